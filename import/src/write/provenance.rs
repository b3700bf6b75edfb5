//! The manifest's `provenance:` block: where an imported recording came from and how its
//! samples were converted (the recording format ignores unknown keys, so any reader of
//! the format still reads the manifest).

use crate::map::{AXES, ImportMap, TimeSpec};
use serde::Serialize;

/// `provenance:`.
#[derive(Debug, Serialize)]
pub struct Provenance {
    /// `ratecal import <version>`.
    pub tool: String,
    /// When (RFC 3339, UTC).
    pub imported: String,
    /// The map file and its SHA-256.
    pub map: FileHash,
    /// Each source and its SHA-256.
    pub sources: Vec<FileHash>,
    /// How the samples were converted.
    pub conversion: Conversion,
    /// `synthesized`: the table stream was made from the segments' declared attitudes;
    /// `feedback`: read from the lab's feedback file.
    pub table: String,
    /// The feedback file and its SHA-256.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub table_file: Option<FileHash>,
    /// How the feedback was converted.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub table_conversion: Option<String>,
    /// `declared` (map) or `detected` (from the signal) or `none`.
    pub segments: String,
}

/// A file and its hash.
#[derive(Debug, Serialize)]
pub struct FileHash {
    /// As given on the command line.
    pub file: String,
    /// Lowercase hex SHA-256 of its bytes.
    pub sha256: String,
}

/// The conversion, written out.
#[derive(Debug, Serialize)]
pub struct Conversion {
    /// How `t` was made.
    pub time: String,
    /// `ax ay az` from the columns.
    pub accel: String,
    /// `gx gy gz` from the columns.
    pub gyro: String,
    /// Body axes from sensor axes.
    pub axes: String,
    /// Samples imported.
    pub samples: u64,
}

impl Conversion {
    /// The conversion a map applies.
    pub fn of(map: &ImportMap, samples: u64) -> Self {
        let time = match &map.time {
            TimeSpec::Rate(hz) => format!("t = i / {hz} Hz (i: 0-based sample after the header)"),
            TimeSpec::Column { col, to_s } => format!("t = column {:?} x {to_s} s", col.col),
        };
        let axes = map
            .axes
            .iter()
            .enumerate()
            .map(|(b, (i, s))| {
                format!(
                    "{} = {}{}",
                    AXES[b],
                    if *s < 0.0 { "-" } else { "" },
                    AXES[*i]
                )
            })
            .collect::<Vec<_>>()
            .join(", ");
        let triad = |s: &crate::map::Scale, unit: &str| {
            format!(
                "(column - {:?}) x {} {unit} (units `{}`), then body axes",
                s.zero, s.factor, s.unit
            )
        };
        Conversion {
            time,
            accel: triad(&map.accel, "m/s^2"),
            gyro: triad(&map.gyro, "deg/s"),
            axes: format!("body {axes} (sensor axes)"),
            samples,
        }
    }
}

/// The feedback's conversion, written out.
pub fn table_conversion(f: &crate::map::TableFeed) -> String {
    let time = match &f.time {
        TimeSpec::Rate(hz) => format!("t = i / {hz} Hz"),
        TimeSpec::Column { col, to_s } => format!("t = column {:?} x {to_s} s", col.col),
    };
    format!(
        "{time} + offset {} s; angles x {} deg (`{}`), rates x {} deg/s (`{}`)",
        f.offset_s, f.angle.factor, f.angle.unit, f.rate.factor, f.rate.unit
    )
}

/// `provenance:` as YAML, to follow the manifest.
pub fn yaml(p: &Provenance) -> Result<String, String> {
    #[derive(Serialize)]
    struct Block<'a> {
        provenance: &'a Provenance,
    }
    serde_saphyr::to_string(&Block { provenance: p }).map_err(|e| e.to_string())
}
