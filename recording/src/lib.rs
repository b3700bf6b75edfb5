//! The recording folder of `spec/recording-format.md`, the contract between measuring and
//! analysing: `manifest.yaml` (the [`Manifest`]), `imu.csv` and `table.csv`. One crate
//! reads it ([`read`]), writes it ([`RecordingWriter`]) and says why a folder is refused
//! ([`RecordingError`], located at file:line:column), for the run, the replay driver, the
//! analysis and whoever comes next.
//!
//! ```
//! use ratecal_recording::{Columns, ImuSample, Manifest, RecordingWriter, TableSample};
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let dir = tempfile::tempdir()?;
//! let manifest: Manifest = ratecal_recording::parse_manifest(
//!     "manifest.yaml",
//!     "format: ratecal-recording/1
//! station:
//!   site: { latitude_deg: 55.7, gravity_mps2: 9.8156 }
//!   table: { outer_axis: [0, -1, 0], inner_axis: [1, 0, 0] }
//! segments:
//!   - { id: rest, kind: static, t_start: 0.1, t_end: 0.3 }
//! ",
//! )?;
//! let mut w = RecordingWriter::create(dir.path(), manifest, Columns::default())?;
//! for i in 0..5 {
//!     let t = 0.1 * i as f64;
//!     w.write_imu(&[ImuSample {
//!         t, accel: [0.0, 0.0, 9.8], gyro: [0.0; 3], temp_c: None, t_host: None,
//!     }])?;
//!     w.write_table(&[TableSample {
//!         t, outer_deg: 0.0, inner_deg: 0.0, outer_rate_dps: 0.0, inner_rate_dps: 0.0,
//!         ambient_c: None, t_host: None,
//!     }])?;
//! }
//! w.finish()?;
//! w.close();
//! let rec = ratecal_recording::read(dir.path())?;
//! assert_eq!(rec.imu.t, [0.0, 0.1, 0.2, 0.3, 0.4]);
//! assert_eq!(rec.manifest.segments[0].id, "rest");
//! # Ok(())
//! # }
//! ```

pub mod cadence;
pub mod chain;
pub mod commit;
mod data;
mod error;
mod excerpt;
mod files;
mod manifest;
mod read;
mod write;

pub use cadence::{Cadence, CadenceReport};
pub use data::{ImuSample, ImuStream, Recording, TableSample, TableStream};
pub use error::{RecordingError, yaml_offset};
pub use excerpt::Excerpt;
pub use files::{FileState, WrittenFile, hash_folder, hash_folder_known, regular, sha256_file};
pub use manifest::{
    AbortRecord, Attitude, EnvironmentRecord, FORMAT, LinkRecord, Manifest, ManifestStation, Mount,
    ProcedureRef, ResumeRecord, RunInfo, Segment, SegmentKind, SyncRecord, TableAxes, WriteFailure,
};
pub use read::{OpenRecording, SpanRows, parse_manifest, read, read_imu, read_table};
pub use write::{
    Columns, RecordingWriter, civil_from_days, manifest_yaml, push_fixed, rfc3339, sha256_hex,
};
