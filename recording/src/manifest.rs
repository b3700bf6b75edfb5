//! `manifest.yaml`: what was recorded, where, on what, and when each segment happened.

use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// The format tag this version writes and reads.
pub const FORMAT: &str = "ratecal-recording/1";

/// `manifest.yaml`. Unknown keys are ignored on reading.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// `ratecal-recording/1`.
    pub format: String,
    /// Station geometry and site.
    pub station: ManifestStation,
    /// Free-form IMU description (model, serial, grade...).
    #[serde(default)]
    pub imu: BTreeMap<String, String>,
    /// The procedure that ran (always written by ratecal; optional from other systems).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub procedure: Option<ProcedureRef>,
    /// Acquisition windows in time order.
    #[serde(default)]
    pub segments: Vec<Segment>,
    /// Lab conditions measured once.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub environment: Option<EnvironmentRecord>,
    /// What ratecal adds about the run itself (absent from other systems' recordings).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub run: Option<RunInfo>,
}

/// `station:` block of the manifest.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ManifestStation {
    /// Site.
    pub site: ratecal_physics::Site,
    /// Table axes.
    pub table: TableAxes,
    /// IMU mount (identity if absent).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mount: Option<Mount>,
}

/// Outer and inner axis unit vectors (lab frame, ENU).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TableAxes {
    /// `a_o`.
    pub outer_axis: [f64; 3],
    /// `a_i` at outer angle 0.
    pub inner_axis: [f64; 3],
    /// The table's make and model (free-form; the spec ignores unknown keys).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model: Option<String>,
}

/// `mount: { rotation: [[...],[...],[...]] }`: `C_PB` row-major.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Mount {
    /// `C_PB`, row-major.
    pub rotation: [[f64; 3]; 3],
}

/// `procedure:` block.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ProcedureRef {
    /// Name.
    pub name: String,
    /// Version.
    pub version: String,
    /// Lowercase hex SHA-256 of the canonical text, unabridged.
    pub sha256: String,
}

/// Kind of a segment.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SegmentKind {
    /// Table at rest.
    Static,
    /// One axis at a constant rate.
    Rate,
    /// One axis swaying sinusoidally.
    Oscillation,
    /// A rotation by hand (or anything that holds no constant rate) between two static
    /// segments; `axis` (a signed body axis) and `angle_deg` when the procedure asked for one.
    Turn,
}

/// How well a static segment's attitude is known (spec/recording-format.md).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Attitude {
    /// The table's angle feedback holds it (the default).
    #[default]
    Feedback,
    /// A fixture's face placed by hand: the nominal attitude within `tolerance_deg`.
    Nominal,
    /// A hand-held pose: only gravity's magnitude is known.
    Unknown,
}

impl Attitude {
    /// The manifest's word (`feedback`, `nominal`, `unknown`).
    pub fn as_str(self) -> &'static str {
        match self {
            Attitude::Feedback => "feedback",
            Attitude::Nominal => "nominal",
            Attitude::Unknown => "unknown",
        }
    }
}

/// One acquisition window.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Segment {
    /// Free-form id.
    pub id: String,
    /// Kind.
    pub kind: SegmentKind,
    /// Start, s (stream clock).
    pub t_start: f64,
    /// End, s.
    pub t_end: f64,
    /// `outer` / `inner` for rate and oscillation segments.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis: Option<String>,
    /// Nominal rate of a rate segment, deg/s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rate_dps: Option<f64>,
    /// Oscillation amplitude, deg.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub amplitude_deg: Option<f64>,
    /// Oscillation period, s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub period_s: Option<f64>,
    /// Oscillation centre, deg.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub center_deg: Option<f64>,
    /// Nominal attitude (informative; references come from the feedback).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pitch_deg: Option<f64>,
    /// Nominal attitude (informative).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub roll_deg: Option<f64>,
    /// Remount before this segment; holds until another segment says otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mount: Option<Mount>,
    /// A static segment's up body axis when the recording says it (`+x`, `-z`), or
    /// `oblique` (no body axis near vertical: a multi-position pose, which the six-position
    /// fits skip). Written by `ratecal import`; absent in a station's recordings.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub up: Option<String>,
    /// Nominal angle of a `turn` about its `axis`, deg.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angle_deg: Option<f64>,
    /// How well a static segment's attitude is known (absent: `feedback`, or `unknown`
    /// for an old recording's `up: oblique`; see [`Segment::attitude`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub attitude: Option<Attitude>,
    /// Tolerance of a `nominal` attitude, deg (required with it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tolerance_deg: Option<f64>,
}

impl Segment {
    /// A segment of `kind` over `[t_start, t_end]` with none of the optional keys: callers
    /// set the ones their motion has.
    pub fn new(id: String, kind: SegmentKind, t_start: f64, t_end: f64) -> Self {
        Segment {
            id,
            kind,
            t_start,
            t_end,
            axis: None,
            rate_dps: None,
            amplitude_deg: None,
            period_s: None,
            center_deg: None,
            pitch_deg: None,
            roll_deg: None,
            mount: None,
            up: None,
            angle_deg: None,
            attitude: None,
            tolerance_deg: None,
        }
    }

    /// Whether the segment is a static pose whose attitude is unknown (`attitude: unknown`,
    /// or `up: oblique` of a recording imported before the key existed).
    pub fn is_oblique(&self) -> bool {
        self.kind == SegmentKind::Static && self.attitude() == Attitude::Unknown
    }

    /// How well the attitude is known: the `attitude` key, else `unknown` for an old
    /// recording's `up: oblique`, else `feedback`.
    pub fn attitude(&self) -> Attitude {
        match (self.attitude, self.up.as_deref()) {
            (Some(a), _) => a,
            (None, Some("oblique")) => Attitude::Unknown,
            _ => Attitude::Feedback,
        }
    }
}

/// `environment:` block.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct EnvironmentRecord {
    /// Lab temperature, degC.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub temperature_c: Option<f64>,
    /// Relative humidity, %.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub humidity_pct: Option<f64>,
    /// Pressure, kPa.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pressure_kpa: Option<f64>,
    /// Vibration, g.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vibration_g: Option<f64>,
}

/// What ratecal records about its own run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunInfo {
    /// Run id.
    pub id: String,
    /// ratecal version.
    pub ratecal_version: String,
    /// Whether the station was simulated.
    pub dry_run: bool,
    /// Start, RFC 3339 (wall clock).
    pub started: String,
    /// End, RFC 3339, once ended.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ended: Option<String>,
    /// `running`, `completed`, `aborted`.
    pub status: String,
    /// Why it aborted.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub abort: Option<AbortRecord>,
    /// Operator.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub operator: Option<String>,
    /// Seed of a simulated run.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seed: Option<u64>,
    /// SHA-256 of the station file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub station_sha256: Option<String>,
    /// SHA-256 of each data file once the run ended (`imu.csv`, `table.csv`, ...).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub files_sha256: BTreeMap<String, String>,
    /// Why the run failed (status `failed`: the station could not be reached...).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub failure: Option<String>,
    /// Each interruption and resume, oldest first.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub resumes: Vec<ResumeRecord>,
    /// Set when the procedure ran although its released version was changed after release
    /// (`--allow-changed`): what changed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub changed_after_release: Option<String>,
    /// Set when the procedure ran as a draft (`--draft`: a version its folder's
    /// `versions.lock` does not release): `DRAFT PROCEDURE: <name> <version> ...`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub draft_procedure: Option<String>,
    /// How hardware links delivered their samples, and the table-to-IMU synchronisation.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sync: Option<SyncRecord>,
    /// A write that failed (a full disk, a file-size limit): the run aborted there and the
    /// stream was cut after its last full line.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub write_failure: Option<WriteFailure>,
}

/// A stream write that failed, and what was cut so that the stream reads back.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WriteFailure {
    /// The file (`imu.csv`).
    pub file: String,
    /// The operating system's error, with its number (`File too large (os error 27)`).
    pub error: String,
    /// Bytes of a partial last line cut from the file.
    pub cut_bytes: u64,
    /// The stamp of the file's last row, s: where its data end (the run notices the
    /// failure later, at the next check of its writer).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub data_end_s: Option<f64>,
}

/// Where a run was interrupted and when it resumed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ResumeRecord {
    /// How the interrupted part ended (`aborted`, `failed`, or `running` when the process
    /// stopped without ending it).
    pub interrupted_status: String,
    /// Why, when recorded (abort rule and values, failure).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    /// Stream time of the last sample before the interruption, s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub t: Option<f64>,
    /// Step it was interrupted in, when recorded.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub step: Option<String>,
    /// When the interrupted part ended (RFC 3339), when recorded.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ended: Option<String>,
    /// When the run resumed (RFC 3339).
    pub resumed: String,
    /// Index of the first step the resumed part ran.
    pub from_step: usize,
    /// Bytes cut from each stream's end when it resumed: written after the journal last
    /// recorded its running hash (a crash's tail), never part of a segment.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub cut_tail: BTreeMap<String, u64>,
}

/// `run.sync`: each hardware link's delivery and the table-to-IMU clock skew estimate.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct SyncRecord {
    /// How much later the table's stamps run than the IMU's, s (estimated from the least
    /// arrival delay of each link; both hardware links needed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub table_minus_imu_s: Option<f64>,
    /// The IMU link.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub imu: Option<LinkRecord>,
    /// The table link.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub table: Option<LinkRecord>,
}

/// One hardware link's delivery over the run.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct LinkRecord {
    /// Samples received.
    pub samples: u64,
    /// Frames refused for a wrong CRC (skipped).
    pub corrupted: u64,
    /// Samples missing from the device counter.
    pub lost: u64,
    /// Times the link was rebuilt.
    pub reconnects: u32,
    /// Least delay from the mapped device stamp to host arrival, ms.
    pub latency_min_ms: f64,
    /// Mean delay, ms.
    pub latency_mean_ms: f64,
    /// Largest delay, ms.
    pub latency_max_ms: f64,
    /// Recording time minus device time, s: the device's own stamp of a sample is its `t`
    /// minus this (the map's latest anchor; a device that restarts re-anchors it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub device_offset_s: Option<f64>,
}

/// Why and when a run aborted.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AbortRecord {
    /// Rule text (or `ctrl-c`, `settle timeout in step X`, `driver error: ...`).
    pub rule: String,
    /// Stream time when it fired, s.
    pub t: f64,
    /// Step it fired in.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub step: Option<String>,
    /// The values that fired it.
    pub values: String,
}
