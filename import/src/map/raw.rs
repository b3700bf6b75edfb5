//! The import map as written (YAML keys, with the location of every value a later check may
//! refuse); `resolve.rs` turns it into an [`crate::ImportMap`].

use serde::Deserialize;
use serde::de::{self, Deserializer, MapAccess, SeqAccess, Visitor};
use serde_saphyr::Spanned;
use std::collections::BTreeMap;
use std::fmt;

/// The whole map file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawMap {
    pub source: RawSource,
    pub imu: RawImu,
    #[serde(default)]
    pub segments: Option<Spanned<RawSegments>>,
    #[serde(default)]
    pub table: Option<Spanned<RawTable>>,
    pub site: RawSite,
    /// Free-form IMU description copied to the manifest's `imu:` (model, serial, grade).
    #[serde(default)]
    pub device: BTreeMap<String, String>,
}

/// `source:`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawSource {
    pub format: Spanned<String>,
    #[serde(default)]
    pub encoding: Option<Spanned<String>>,
    #[serde(default)]
    pub skip_lines: Option<usize>,
    #[serde(default)]
    pub header: Option<Spanned<String>>,
    #[serde(default)]
    pub delimiter: Option<Spanned<String>>,
    #[serde(default)]
    pub variable: Option<Spanned<String>>,
}

/// `imu:`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawImu {
    pub time: Spanned<RawTime>,
    pub columns: RawColumns,
    pub units: RawUnits,
    #[serde(default)]
    pub zero: Option<RawZero>,
    #[serde(default)]
    pub axes: Option<Spanned<Vec<Spanned<String>>>>,
}

/// `imu.time:`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawTime {
    #[serde(default)]
    pub rate_hz: Option<Spanned<f64>>,
    #[serde(default)]
    pub column: Option<Spanned<RawCol>>,
    #[serde(default)]
    pub unit: Option<Spanned<String>>,
}

/// A column: a header name or a 0-based index.
#[derive(Debug, Clone, Deserialize)]
#[serde(untagged)]
pub enum RawCol {
    Index(u64),
    Name(String),
}

/// `imu.columns:`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawColumns {
    pub ax: Spanned<RawCol>,
    pub ay: Spanned<RawCol>,
    pub az: Spanned<RawCol>,
    pub gx: Spanned<RawCol>,
    pub gy: Spanned<RawCol>,
    pub gz: Spanned<RawCol>,
}

/// `imu.units:`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawUnits {
    pub accel: Spanned<String>,
    pub gyro: Spanned<String>,
}

/// `imu.zero:`: one count for all three axes, or one per axis.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawZero {
    #[serde(default)]
    pub accel: Option<Spanned<RawTriple>>,
    #[serde(default)]
    pub gyro: Option<Spanned<RawTriple>>,
}

/// A number, or three.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(untagged)]
pub enum RawTriple {
    One(f64),
    Three([f64; 3]),
}

/// `site:`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawSite {
    pub latitude_deg: Spanned<f64>,
    pub gravity_mps2: Spanned<f64>,
}

/// `segments:`: a list, or `{ detect: {...} }`.
#[derive(Debug)]
pub enum RawSegments {
    List(Vec<Spanned<RawSegment>>),
    Detect(Box<RawDetect>),
}

/// One declared segment.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawSegment {
    pub id: Spanned<String>,
    pub kind: Spanned<String>,
    #[serde(default)]
    pub samples: Option<Spanned<[u64; 2]>>,
    #[serde(default)]
    pub time: Option<Spanned<[f64; 2]>>,
    #[serde(default)]
    pub up: Option<Spanned<String>>,
    #[serde(default)]
    pub axis: Option<Spanned<String>>,
    #[serde(default)]
    pub rate_dps: Option<Spanned<f64>>,
    /// Nominal angle of a turn, deg.
    #[serde(default)]
    pub angle_deg: Option<Spanned<f64>>,
    /// `feedback`, `nominal` or `unknown` (a static segment).
    #[serde(default)]
    pub attitude: Option<Spanned<String>>,
    /// Tolerance of a nominal attitude, deg.
    #[serde(default)]
    pub tolerance_deg: Option<Spanned<f64>>,
}

/// `segments: { detect: {...} }`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawDetectWrap {
    pub detect: RawDetect,
}

/// The detection's settings.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawDetect {
    /// Shortest static interval kept (`"2 s"`).
    pub static_min: Spanned<String>,
    /// Moving-variance threshold as a multiple of the quietest variance (default 6).
    #[serde(default)]
    pub threshold: Option<Spanned<f64>>,
    /// Window of the moving variance (`"0.5 s"`, default 0.5 s).
    #[serde(default)]
    pub window: Option<Spanned<String>>,
    /// The detected poses' attitude: `unknown` (default without feedback) or `nominal`.
    #[serde(default)]
    pub attitude: Option<Spanned<String>>,
    /// Tolerance of a nominal attitude, deg.
    #[serde(default)]
    pub tolerance_deg: Option<Spanned<f64>>,
}

impl<'de> Deserialize<'de> for RawSegments {
    // By hand rather than `untagged`: an untagged enum buffers its content and loses the
    // location of an error inside one segment.
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = RawSegments;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a list of segments or `{ detect: { static_min: 2 s } }`")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
                let mut v = Vec::new();
                while let Some(s) = seq.next_element()? {
                    v.push(s);
                }
                Ok(RawSegments::List(v))
            }
            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<Self::Value, A::Error> {
                let w = RawDetectWrap::deserialize(de::value::MapAccessDeserializer::new(map))?;
                Ok(RawSegments::Detect(Box::new(w.detect)))
            }
        }
        d.deserialize_any(V)
    }
}

/// `table:`: `none`, or the feedback file with its own map.
#[derive(Debug)]
pub enum RawTable {
    None,
    Feed(Box<RawFeed>),
}

/// `table: { file, source, time, offset_s, columns, units, outer_axis, inner_axis }`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawFeed {
    /// Relative to the first source's folder.
    pub file: Spanned<String>,
    #[serde(default)]
    pub source: Option<RawSource>,
    pub time: Spanned<RawTime>,
    /// Added to the feedback's time to put it on the IMU's time base, s.
    #[serde(default)]
    pub offset_s: Option<Spanned<f64>>,
    pub columns: RawFeedColumns,
    pub units: RawFeedUnits,
    #[serde(default)]
    pub outer_axis: Option<Spanned<[f64; 3]>>,
    #[serde(default)]
    pub inner_axis: Option<Spanned<[f64; 3]>>,
}

/// `table.columns:`, named as `table.csv`'s.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawFeedColumns {
    pub outer: Spanned<RawCol>,
    pub inner: Spanned<RawCol>,
    pub outer_rate: Spanned<RawCol>,
    pub inner_rate: Spanned<RawCol>,
}

/// `table.units:`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawFeedUnits {
    pub angle: Spanned<String>,
    pub rate: Spanned<String>,
}

impl<'de> Deserialize<'de> for RawTable {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = RawTable;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str(
                    "`none` or `{ file: feedback.csv, time: ..., columns: ..., units: ... }`",
                )
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<Self::Value, E> {
                if v == "none" {
                    Ok(RawTable::None)
                } else {
                    Err(E::invalid_value(de::Unexpected::Str(v), &self))
                }
            }
            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<Self::Value, A::Error> {
                let f = RawFeed::deserialize(de::value::MapAccessDeserializer::new(map))?;
                Ok(RawTable::Feed(Box::new(f)))
            }
        }
        d.deserialize_any(V)
    }
}
