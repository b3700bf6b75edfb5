//! The change model of a semantic diff: one `Change` per difference in meaning, with a
//! path an auditor can read (`step accel_static / settle / fluctuation`) and the old and
//! new values as display strings.

use ratecal_physics::STANDARD_GRAVITY;
use ratecal_plan::{Dim, Quantity, Signal};
use serde::{Deserialize, Serialize};

/// What happened to one element of the procedure.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ChangeKind {
    /// Present only in the new version.
    Added,
    /// Present only in the old version.
    Removed,
    /// Changed, with no direction of strictness.
    Changed,
    /// Same content, different position.
    Moved,
    /// A limit or rule made stricter.
    Tightened,
    /// A limit or rule made more permissive.
    Loosened,
}

impl ChangeKind {
    /// The lowercase name used in JSON and text (`loosened`).
    pub fn as_str(self) -> &'static str {
        match self {
            ChangeKind::Added => "added",
            ChangeKind::Removed => "removed",
            ChangeKind::Changed => "changed",
            ChangeKind::Moved => "moved",
            ChangeKind::Tightened => "tightened",
            ChangeKind::Loosened => "loosened",
        }
    }
}

/// One semantic difference between two plans.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Change {
    /// Where (`step gyro_scale / accept gyro.residual.std`).
    pub path: String,
    /// What happened.
    pub kind: ChangeKind,
    /// Old value as displayed, `None` when added.
    pub old: Option<String>,
    /// New value as displayed, `None` when removed.
    pub new: Option<String>,
    /// Whether an auditor must not miss it: a loosened limit, a weakened or removed abort
    /// rule, a removed acceptance limit. Not part of the JSON (derivable from kind and path).
    #[serde(skip)]
    pub alert: bool,
}

impl Change {
    /// A change with both sides.
    pub fn new(
        path: impl Into<String>,
        kind: ChangeKind,
        old: Option<String>,
        new: Option<String>,
    ) -> Self {
        let alert = kind == ChangeKind::Loosened;
        Change {
            path: path.into(),
            kind,
            old,
            new,
            alert,
        }
    }

    /// An element only in the new version.
    pub fn added(path: impl Into<String>, new: impl Into<String>) -> Self {
        Change::new(path, ChangeKind::Added, None, Some(new.into()))
    }

    /// An element only in the old version.
    pub fn removed(path: impl Into<String>, old: impl Into<String>) -> Self {
        Change::new(path, ChangeKind::Removed, Some(old.into()), None)
    }

    /// A value that changed (`kind` says in which direction).
    pub fn value(
        path: impl Into<String>,
        kind: ChangeKind,
        old: impl Into<String>,
        new: impl Into<String>,
    ) -> Self {
        Change::new(path, kind, Some(old.into()), Some(new.into()))
    }

    /// Marks the change as one an auditor must not miss.
    pub fn alerting(mut self) -> Self {
        self.alert = true;
        self
    }
}

/// Identifies one side of a diff.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Side {
    /// Procedure name.
    pub name: String,
    /// Version.
    pub version: String,
    /// Lowercase hex SHA-256 of the canonical text.
    pub sha256: String,
}

/// A whole diff: both sides and the changes in procedure order.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DiffReport {
    /// The old version.
    pub old: Side,
    /// The new version.
    pub new: Side,
    /// Every semantic change.
    pub changes: Vec<Change>,
}

/// Relative tolerance under which two internal values are the same (unit round trips).
const REL_TOL: f64 = 1e-9;

/// Whether two internal values are equal up to unit-conversion rounding.
pub fn same(a: f64, b: f64) -> bool {
    a == b || (a - b).abs() <= REL_TOL * a.abs().max(b.abs())
}

/// Shortest decimal for a value, rounded to 12 significant digits (`0.001`, not
/// `0.0010000000000000002`).
pub fn fmt_num(v: f64) -> String {
    if !v.is_finite() {
        return v.to_string();
    }
    let rounded: f64 = format!("{v:.11e}").parse().unwrap_or(v);
    let s = format!("{rounded}");
    if s == "-0" { "0".into() } else { s }
}

/// A quantity as the procedure wrote it (`0.002 g`).
pub fn fmt_q(q: &Quantity) -> String {
    if q.unit.is_empty() {
        fmt_num(q.written)
    } else {
        format!("{} {}", fmt_num(q.written), q.unit)
    }
}

/// An internal value of a dimension in the unit a procedure most likely used: angles
/// below one degree in arcsec, accelerations in g, others in the internal unit.
pub fn fmt_internal(dim: Dim, v: f64) -> String {
    match dim {
        Dim::Angle if v != 0.0 && v.abs() < 1.0 => format!("{} arcsec", fmt_num(v * 3600.0)),
        Dim::Accel => format!("{} g", fmt_num(v / STANDARD_GRAVITY)),
        Dim::Time if v >= 60.0 && (v / 60.0).fract() == 0.0 => format!("{} min", fmt_num(v / 60.0)),
        Dim::Ratio => format!("{} %", fmt_num(v * 100.0)),
        Dim::Number => fmt_num(v),
        _ => format!("{} {}", fmt_num(v), dim.internal_unit()),
    }
}

/// Seconds (`10 s`, `60 min`).
pub fn fmt_s(v: f64) -> String {
    fmt_internal(Dim::Time, v)
}

/// The dimension of a live signal's internal unit.
pub fn signal_dim(s: Signal) -> Dim {
    match s {
        Signal::Accel => Dim::Accel,
        Signal::Gyro | Signal::RateError => Dim::Rate,
        Signal::AttitudeError => Dim::Angle,
        Signal::AmbientTemperature | Signal::ImuTemperature => Dim::Temperature,
        Signal::AmbientDrift => Dim::TemperatureRate,
    }
}

/// The name a procedure gives a live signal (`table.attitude_error`).
pub fn signal_name(s: Signal) -> &'static str {
    match s {
        Signal::Accel => "imu.accel",
        Signal::Gyro => "imu.gyro",
        Signal::AttitudeError => "table.attitude_error",
        Signal::RateError => "table.rate_error",
        Signal::AmbientTemperature => "ambient.temperature",
        Signal::AmbientDrift => "ambient.drift",
        Signal::ImuTemperature => "imu.temperature",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_round_trip_units() {
        assert_eq!(fmt_num(0.001 * 9.80665 / 9.80665), "0.001");
        assert_eq!(
            fmt_internal(Dim::Accel, 0.001 * STANDARD_GRAVITY),
            "0.001 g"
        );
        assert_eq!(fmt_internal(Dim::Angle, 5.0 / 3600.0), "5 arcsec");
        assert_eq!(fmt_internal(Dim::Angle, 90.0), "90 deg");
        assert_eq!(fmt_s(3600.0), "60 min");
        assert_eq!(fmt_s(10.0), "10 s");
        assert_eq!(fmt_num(-0.0), "0");
        assert!(same(0.002 * 9.80665, 2.0 * 9.80665e-3));
        assert!(!same(0.002, 0.0021));
    }
}
