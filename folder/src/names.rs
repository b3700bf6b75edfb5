//! The names of a run folder's files (docs/run-folders.md): written here once, so that
//! every command reads and writes the same folder.

/// The recording's manifest (spec/recording-format.md).
pub const MANIFEST: &str = "manifest.yaml";
/// The IMU stream.
pub const IMU: &str = "imu.csv";
/// The table stream.
pub const TABLE: &str = "table.csv";
/// The run's journal: steps, warnings and the streams' running hashes.
pub const JOURNAL: &str = "journal.jsonl";
/// The copy of the procedure that ran.
pub const PROCEDURE: &str = "procedure.rcal";
/// The copy of the station file the run used.
pub const STATION: &str = "station.yaml";
/// The checked plan, beside the results.
pub const PLAN: &str = "plan.json";
/// The analysis (docs/results.md).
pub const RESULTS: &str = "results.json";
/// What `ratecal explain` found, kept beside the run.
pub const EXPLAIN: &str = "explain.json";
/// The seal: the SHA-256 of every file, written last.
pub const SEAL_FILE: &str = "seal.json";
/// The file holding the SHA-256 of `seal.json`.
pub const SEAL_HASH_FILE: &str = "seal.sha256";
/// The lock every writer of the folder holds (never sealed, verified or archived).
pub const LOCK_FILE: &str = ".ratecal.lock";
