//! `archive trend SERIAL`: each parameter across a unit's calibrations, its drift rate with
//! uncertainty, and the recalibration interval the drift implies against the procedure's
//! acceptance limit at a stated confidence.

mod fit;
mod render;

pub use fit::{Bound, Drift, HORIZON_DAYS, Point, drift, interval_days};

use crate::{Archive, Result, dates};
use serde::Serialize;
use statrs::distribution::{ContinuousCDF, Normal};

/// What to trend.
#[derive(Debug, Clone)]
pub struct TrendOptions {
    /// Parameters by dotted name (every parameter when empty).
    pub params: Vec<String>,
    /// Dry runs too.
    pub include_dry_runs: bool,
    /// Confidence of the recalibration interval (one-sided), e.g. 0.95.
    pub confidence: f64,
}

/// A unit's trend; the JSON keys are a stable interface.
#[derive(Debug, Clone, Serialize)]
pub struct Trend {
    /// IMU serial.
    pub serial: String,
    /// Confidence of the intervals.
    pub confidence: f64,
    /// One-sided coverage factor (normal quantile at `confidence`).
    pub k: f64,
    /// Calibrations of the unit found.
    pub calibrations: usize,
    /// One entry per parameter.
    pub parameters: Vec<ParamTrend>,
}

/// One parameter across calibrations.
#[derive(Debug, Clone, Serialize)]
pub struct ParamTrend {
    /// Dotted name.
    pub name: String,
    /// Unit.
    pub unit: String,
    /// Calibrations, oldest first.
    pub points: Vec<TrendPoint>,
    /// `determined` or `undetermined`.
    pub drift_status: String,
    /// The fitted drift, when determined.
    pub drift: Option<Drift>,
    /// The acceptance limit the interval is computed against.
    pub limit: Option<LimitUse>,
    /// Days after the last calibration until the drift is expected to cross the limit.
    pub recalibration_days: Option<f64>,
    /// That date, `YYYY-MM-DD`.
    pub recalibrate_by: Option<String>,
    /// Why something is missing, in plain words.
    pub notes: Vec<String>,
}

/// One calibration value.
#[derive(Debug, Clone, Serialize)]
pub struct TrendPoint {
    /// Archive id of the run.
    pub run: String,
    /// Start of the run.
    pub started: String,
    /// Value.
    pub value: f64,
    /// Standard uncertainty.
    pub u: f64,
}

/// An acceptance limit applied to a parameter.
#[derive(Debug, Clone, Serialize)]
pub struct LimitUse {
    /// As the procedure wrote it (`abs(accel.bias.x) <= 0.05 m/s^2`).
    pub text: String,
    /// Which side it bounds.
    pub bound: Bound,
    /// Limit value, in the parameter's unit.
    pub limit: f64,
}

impl Archive {
    /// The trend of every (or the chosen) parameter of `serial`.
    pub async fn trend(&self, serial: &str, opt: &TrendOptions) -> Result<Trend> {
        let dry = if opt.include_dry_runs {
            ""
        } else {
            " AND r.dry_run = 0"
        };
        let sql = format!(
            "SELECT r.id, r.started, p.name, p.value, p.u, p.unit FROM parameters p \
             JOIN runs r ON r.id = p.run_id WHERE r.serial = $1{dry} ORDER BY r.started, r.id"
        );
        let rows: Vec<(String, String, String, f64, f64, String)> =
            sqlx::query_as(sqlx::AssertSqlSafe(sql))
                .bind(serial)
                .fetch_all(&self.pool)
                .await?;
        let runs_sql = format!(
            "SELECT r.id FROM runs r WHERE r.serial = $1{dry} ORDER BY r.started DESC, r.id"
        );
        let runs: Vec<(String,)> = sqlx::query_as(sqlx::AssertSqlSafe(runs_sql))
            .bind(serial)
            .fetch_all(&self.pool)
            .await?;
        let limits: Vec<(String, String, f64, String)> = match runs.first() {
            Some((latest,)) => {
                sqlx::query_as(
                    "SELECT quantity, op, limit_value, unit FROM limits WHERE run_id = $1",
                )
                .bind(latest)
                .fetch_all(&self.pool)
                .await?
            }
            None => Vec::new(),
        };
        let k = Normal::standard().inverse_cdf(opt.confidence.clamp(0.5, 0.999_999));
        let mut names: Vec<String> = if opt.params.is_empty() {
            let mut n: Vec<String> = rows.iter().map(|r| r.2.clone()).collect();
            n.sort();
            n.dedup();
            n
        } else {
            opt.params.clone()
        };
        names.dedup();
        let parameters = names
            .iter()
            .map(|name| {
                let mine: Vec<_> = rows.iter().filter(|r| &r.2 == name).collect();
                param_trend(name, &mine, &limits, k)
            })
            .collect();
        Ok(Trend {
            serial: serial.to_string(),
            confidence: opt.confidence,
            k,
            calibrations: runs.len(),
            parameters,
        })
    }
}

type Row = (String, String, String, f64, f64, String);

fn param_trend(
    name: &str,
    rows: &[&Row],
    limits: &[(String, String, f64, String)],
    k: f64,
) -> ParamTrend {
    let mut notes = Vec::new();
    let unit = rows.last().map(|r| r.5.clone()).unwrap_or_default();
    let mut points = Vec::new();
    let mut fit_points = Vec::new();
    for r in rows {
        if r.5 != unit {
            notes.push(format!(
                "run {} gives it in {}, not {unit}: left out",
                r.0, r.5
            ));
            continue;
        }
        let Some(t) = dates::days_from_iso(&r.1) else {
            notes.push(format!("run {} has no readable start date: left out", r.0));
            continue;
        };
        points.push(TrendPoint {
            run: r.0.clone(),
            started: r.1.clone(),
            value: r.3,
            u: r.4,
        });
        fit_points.push(Point {
            t_days: t,
            value: r.3,
            u: r.4,
        });
    }
    if rows.is_empty() {
        notes.push("no calibration of this unit holds this parameter".into());
    }
    let d = drift(&fit_points);
    if d.is_none() {
        notes.push("drift undetermined: fewer than two calibrations at different dates".into());
    }
    let limit = find_limit(name, &unit, limits, &mut notes);
    let (mut days, mut by) = (None, None);
    if let (Some(d), Some(l)) = (&d, &limit) {
        match interval_days(d, l.bound, l.limit, k) {
            Some(tau) => {
                days = Some(tau);
                let last = fit_points.iter().map(|p| p.t_days).fold(f64::MIN, f64::max);
                by = Some(dates::iso_date(last + tau));
            }
            None => notes.push("the limit is not reached within 100 years".into()),
        }
    }
    ParamTrend {
        name: name.to_string(),
        unit,
        points,
        drift_status: if d.is_some() {
            "determined"
        } else {
            "undetermined"
        }
        .into(),
        drift: d,
        limit,
        recalibration_days: days,
        recalibrate_by: by,
        notes,
    }
}

impl Trend {
    /// The recommended recalibration (ISO/IEC 17025, 7.8.4.3: only when agreed with the
    /// customer): the earliest date a parameter's predicted value plus its expanded
    /// uncertainty reaches its acceptance limit, and the sentence that says so; `None` when
    /// the history allows none (no drift determined against a limit).
    pub fn recommended_interval(&self) -> Option<(String, String)> {
        let p = self
            .parameters
            .iter()
            .filter(|p| p.recalibration_days.is_some() && p.recalibrate_by.is_some())
            .min_by(|a, b| {
                let days = |p: &ParamTrend| p.recalibration_days.unwrap_or(f64::INFINITY);
                days(a).total_cmp(&days(b))
            })?;
        let by = p.recalibrate_by.clone()?;
        let limit = p.limit.as_ref().map(|l| l.text.clone()).unwrap_or_default();
        let line = format!(
            "recommended recalibration: {by} (from the drift of {}, {} calibrations: the \
             predicted value plus U (k = {:.2}, {:.0} % one-sided) reaches {limit})",
            p.name,
            p.points.len(),
            self.k,
            self.confidence * 100.0
        );
        Some((by, line))
    }
}

/// The acceptance limit on `name` (`name op L`, `abs(name) op L`, `|name| op L` or
/// `name within +-L`).
fn find_limit(
    name: &str,
    unit: &str,
    limits: &[(String, String, f64, String)],
    notes: &mut Vec<String>,
) -> Option<LimitUse> {
    for (q, op, limit, lunit) in limits {
        let q = q.replace(' ', "");
        let magnitude = q == format!("abs({name})") || q == format!("|{name}|");
        if q != name && !magnitude {
            continue;
        }
        let text = if op == "within" {
            format!("{q} within +-{limit} {lunit}")
        } else {
            format!("{q} {op} {limit} {lunit}")
        };
        // A limit in another unit of the same dimension (`80 mg` on a bias in m/s^2).
        let factor = |u: &str| ratecal_physics::units::parse_quantity(&format!("1 {u}"));
        let limit = match (lunit == unit, factor(lunit), factor(unit)) {
            (true, _, _) => *limit,
            (false, Some((dl, fl)), Some((dp, fp))) if dl == dp && fp != 0.0 => limit * fl / fp,
            _ => {
                notes.push(format!(
                    "limit `{text}` is in {lunit}, the parameter in {unit}: not compared"
                ));
                continue;
            }
        };
        // The analysis judges a check on a calibrated parameter by its magnitude
        // (docs/language.md): `accel.bias.x <= 80 mg` bounds |accel.bias.x|; `within
        // +-L` bounds both sides, so the interval ends when the predicted value plus or
        // minus U reaches either.
        let bound = match op.as_str() {
            "<=" | "<" | "within" => Bound::Magnitude,
            ">=" | ">" if !magnitude => Bound::Lower,
            _ => continue,
        };
        return Some(LimitUse { text, bound, limit });
    }
    if !notes.iter().any(|n| n.starts_with("limit")) {
        notes
            .push("the procedure sets no acceptance limit on it: no recalibration interval".into());
    }
    None
}
