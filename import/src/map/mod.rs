//! The import map (YAML, read with serde-saphyr): where the IMU's columns are, in which
//! units and axes, which segments the data hold, and the site. Every refusal is located in
//! the map file.

mod attitude;
mod raw;
mod resolve;
mod segments;
mod table;
mod units;

pub use resolve::{MAX_RATE_HZ, MIN_RATE_HZ, load_map};
pub use table::TableFeed;
pub use units::{scale_of, seconds_per};

use ratecal_physics::Site;
use ratecal_recording::SegmentKind;
use std::collections::BTreeMap;
use std::ops::Range;

/// A loaded, checked import map.
#[derive(Debug, Clone)]
pub struct ImportMap {
    /// The map's file name (as given).
    pub file: String,
    /// Its text.
    pub text: String,
    /// Lowercase hex SHA-256 of its bytes.
    pub sha256: String,
    /// How to read the sources.
    pub source: SourceSpec,
    /// Where the time comes from.
    pub time: TimeSpec,
    /// `ax ay az gx gy gz`, in that order.
    pub columns: [Col; 6],
    /// Accelerometer scale (to m/s^2) and zero.
    pub accel: Scale,
    /// Gyro scale (to deg/s) and zero.
    pub gyro: Scale,
    /// Body axis `i` is `sign * sensor[index]`.
    pub axes: [(usize, f64); 3],
    /// The segments: declared, detected, or none.
    pub segments: Segments,
    /// The site.
    pub site: Site,
    /// The table's feedback file (`None`: `table: none`, the stream is synthesized).
    pub table: Option<TableFeed>,
    /// Free-form IMU description for the manifest.
    pub device: BTreeMap<String, String>,
}

/// The source format.
#[derive(Debug, Clone, PartialEq)]
pub enum Format {
    /// Delimited or whitespace-separated text.
    Csv,
    /// A MATLAB file; `variable` is the matrix to read.
    Mat {
        /// The variable's name.
        variable: String,
    },
}

/// How the cells of a line are separated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Delimiter {
    /// Found from the header or first line: `,` `;` tab, else whitespace.
    Auto,
    /// One byte.
    Byte(u8),
    /// Runs of spaces and tabs (leading ones ignored).
    Whitespace,
}

/// `source:`.
#[derive(Debug, Clone)]
pub struct SourceSpec {
    /// csv or mat.
    pub format: Format,
    /// Encoding of the text (header names).
    pub encoding: &'static encoding_rs::Encoding,
    /// Lines skipped before the header (or the data, without one).
    pub skip_lines: usize,
    /// Whether the first line after the skipped ones is a header.
    pub header: bool,
    /// Cell separator.
    pub delimiter: Delimiter,
}

/// A column reference and where the map wrote it.
#[derive(Debug, Clone, PartialEq)]
pub struct Col {
    /// Name or index.
    pub col: ColRef,
    /// Bytes of the map text.
    pub at: Range<usize>,
}

/// A header name or a 0-based index (over the sources side by side).
#[derive(Debug, Clone, PartialEq)]
pub enum ColRef {
    /// 0-based.
    Index(usize),
    /// Header name.
    Name(String),
}

/// Time of the samples.
#[derive(Debug, Clone, PartialEq)]
pub enum TimeSpec {
    /// Sample `i` at `i / rate_hz`.
    Rate(f64),
    /// A column, in seconds times `to_s`.
    Column {
        /// The column.
        col: Col,
        /// Seconds per unit.
        to_s: f64,
    },
}

/// A sensor triad's conversion: `(raw - zero) * factor`.
#[derive(Debug, Clone, PartialEq)]
pub struct Scale {
    /// To the internal unit.
    pub factor: f64,
    /// The count (or value) that means zero, per sensor axis.
    pub zero: [f64; 3],
    /// The unit as written.
    pub unit: String,
    /// Where the unit is in the map.
    pub at: Range<usize>,
}

/// The segments of the map.
#[derive(Debug, Clone, PartialEq)]
pub enum Segments {
    /// None declared: the recording has no segments.
    None,
    /// Declared by sample or time range.
    List(Vec<DeclSegment>),
    /// Found from the signal.
    Detect(Detect),
}

/// `segments: { detect: ... }`.
#[derive(Debug, Clone, PartialEq)]
pub struct Detect {
    /// Shortest static interval kept, s.
    pub static_min_s: f64,
    /// Variance threshold, multiple of the quietest windows' variance.
    pub threshold: f64,
    /// Window of the moving variance, s.
    pub window_s: f64,
    /// The detected poses' attitude (`None`: `unknown`, the default of a hand-held session).
    pub attitude: Option<Attitude>,
    /// Where `segments:` is in the map.
    pub at: Range<usize>,
}

/// A declared segment.
#[derive(Debug, Clone, PartialEq)]
pub struct DeclSegment {
    /// Id.
    pub id: String,
    /// static or rate.
    pub kind: SegmentKind,
    /// Its samples.
    pub range: SegRange,
    /// Which body axis points up (static).
    pub up: Option<Up>,
    /// Rotation axis and rate, deg/s (rate).
    pub rate: Option<(RateAxis, f64)>,
    /// A turn's signed body axis and nominal angle, deg, when the map gives them.
    pub turn: Option<Turn>,
    /// The declared attitude of a static segment, when the map gives one.
    pub attitude: Option<Attitude>,
    /// Where the segment is in the map.
    pub at: Range<usize>,
    /// Where its range is.
    pub range_at: Range<usize>,
    /// Where its `up` is.
    pub up_at: Range<usize>,
}

/// Samples `[from, to)` or times `[t0, t1)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SegRange {
    /// 0-based sample indices.
    Samples(u64, u64),
    /// Seconds.
    Time(f64, f64),
}

/// The up axis of a static segment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Up {
    /// Body axis index and sign (`+x` is `(0, 1.0)`).
    Axis(usize, f64),
    /// No body axis within 10 deg of vertical.
    Oblique,
}

/// How well a static segment's attitude is known, as the map declares it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Attitude {
    /// The table's feedback holds it (needs a feedback file).
    Feedback,
    /// The nominal face within `tolerance_deg`.
    Nominal(f64),
    /// Only gravity's magnitude is known.
    Unknown,
}

/// A turn's body axis (index, sign) and nominal angle, deg; each optional.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Turn {
    /// Signed body axis.
    pub axis: Option<(usize, f64)>,
    /// Nominal angle, deg.
    pub angle_deg: Option<f64>,
}

/// The axis a rate segment turns about.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RateAxis {
    /// A body axis (index, sign).
    Body(usize, f64),
    /// The table's outer axis.
    Outer,
    /// The table's inner axis.
    Inner,
}

impl Up {
    /// `+x`, `-z`, `oblique`.
    pub fn name(self) -> String {
        match self {
            Up::Axis(i, s) => format!("{}{}", if s > 0.0 { '+' } else { '-' }, AXES[i]),
            Up::Oblique => "oblique".into(),
        }
    }
}

impl RateAxis {
    /// `x`, `-y`, `outer`, `inner`.
    pub fn name(self) -> String {
        match self {
            RateAxis::Body(i, s) => format!("{}{}", if s < 0.0 { "-" } else { "" }, AXES[i]),
            RateAxis::Outer => "outer".into(),
            RateAxis::Inner => "inner".into(),
        }
    }
}

/// Body axis names.
pub const AXES: [char; 3] = ['x', 'y', 'z'];

/// `+x`, `x`, `-y` to (index, sign).
pub fn signed_axis(text: &str) -> Option<(usize, f64)> {
    let t = text.trim();
    let (sign, name) = match t.strip_prefix('-') {
        Some(n) => (-1.0, n),
        None => (1.0, t.strip_prefix('+').unwrap_or(t)),
    };
    let i = AXES
        .iter()
        .position(|c| name.len() == 1 && name.starts_with(*c))?;
    Some((i, sign))
}
