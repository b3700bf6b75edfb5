//! The sanity checks of a manual recording: the clock and sampling checks of any recording;
//! gravity's magnitude on the calibrated poses (a consumer part's raw offsets reach
//! hundreds of mg, so the raw poses prove nothing); gravity's direction against each nominal
//! face (a pose on the wrong face); the gyros at rest. No table: `gyro_follows_table` is
//! not evaluated (the turns' misses are in `manual.turns`).

use super::Triad;
use super::accel::calibrated;
use super::data::Data;
use crate::fit::Source;
use crate::fit::sanity::{self, ATTITUDE_MAX_DEG, GYRO_BIAS_MAX};
use crate::recording::{Attitude, CadenceReport, Manifest};
use crate::results::{ResidualStats, SanityCheck, SanityStatus};
use nalgebra::Vector3;

/// A calibrated pose may read gravity this far off (relative): ten times what a calibration
/// leaves on a consumer part, a fraction of any units or axis mistake.
pub(crate) const CALIBRATED_GRAVITY_REL: f64 = 0.02;

/// Every sanity check of a manual recording, in results.json order (less `fitted_values_plausible`).
pub(crate) fn checks<S: Source>(
    m: &Manifest,
    src: &S,
    d: &Data,
    accel: Option<&Triad>,
    g: f64,
    warnings: &mut Vec<String>,
) -> Vec<SanityCheck> {
    let imu = src.imu_cadence();
    let tab = CadenceReport::of(&src.table().t);
    vec![
        sanity::time_increasing(&imu, &tab),
        sanity::clocks_overlap(src.imu_extent(), src.table()),
        sanity::sampling(&imu, &tab, warnings),
        magnitude(d, accel, g),
        direction(d, accel),
        at_rest(d),
        SanityCheck::new(
            "gyro_follows_table",
            SanityStatus::NotEvaluated,
            format!(
                "no table in {}: the turns are checked by the gyro fit (manual.turns)",
                m.station.table.model.as_deref().unwrap_or("this recording")
            ),
        ),
    ]
}

fn magnitude(d: &Data, accel: Option<&Triad>, g: f64) -> SanityCheck {
    let name = "gravity_magnitude_at_rest";
    let Some(a) = accel else {
        return SanityCheck::new(
            name,
            SanityStatus::NotEvaluated,
            "no accelerometer calibration to check the poses through",
        );
    };
    let tol = CALIBRATED_GRAVITY_REL * g;
    let worst = d
        .poses
        .iter()
        .map(|p| {
            let got = calibrated(a, p).norm();
            (
                (got - g).abs() - tol,
                format!("segment {}: calibrated |specific force| {got:.4} m/s^2 where the site's gravity is {g:.4} m/s^2 (tolerance {tol:.3} m/s^2)", p.id),
            )
        })
        .max_by(|x, y| x.0.total_cmp(&y.0));
    sanity::verdict(
        name,
        worst,
        "no static pose",
        " (a pose that was not at rest, or poses too few or too alike for the calibration)",
    )
}

fn direction(d: &Data, accel: Option<&Triad>) -> SanityCheck {
    let name = "gravity_direction_at_rest";
    let faces: Vec<_> = d
        .poses
        .iter()
        .filter(|p| p.attitude == Attitude::Nominal)
        .filter_map(|p| p.face.map(|f| (p, f)))
        .collect();
    let (Some(a), false) = (accel, faces.is_empty()) else {
        return SanityCheck::new(
            name,
            SanityStatus::NotEvaluated,
            "attitudes unknown: only gravity's magnitude is known at the poses",
        );
    };
    let worst = faces
        .iter()
        .map(|(p, (j, s))| {
            let c = calibrated(a, p);
            let face = Vector3::ith(*j, *s);
            let deg = c.cross(&face).norm().atan2(c.dot(&face)).to_degrees();
            let tol = ATTITUDE_MAX_DEG + p.tol_rad.to_degrees();
            (deg - tol, format!("segment {}: the calibrated specific force is {deg:.2} deg from its face (tolerance {tol:.1} deg)", p.id))
        })
        .max_by(|x, y| x.0.total_cmp(&y.0));
    sanity::verdict(
        name,
        worst,
        "no nominal face",
        " (a pose on another face than the one declared?)",
    )
}

fn at_rest(d: &Data) -> SanityCheck {
    let limit = GYRO_BIAS_MAX * 3f64.sqrt();
    let worst = d
        .poses
        .iter()
        .map(|p| {
            let w = Vector3::from(p.w).norm();
            (w - limit, format!("segment {}: |angular rate| {w:.4} deg/s at rest (limit {limit:.3} deg/s: a plausible bias)", p.id))
        })
        .max_by(|x, y| x.0.total_cmp(&y.0));
    sanity::verdict(
        "gyro_at_rest",
        worst,
        "no static pose",
        " (gyros in mdeg/s or raw counts read as deg/s?)",
    )
}

/// Each pose's calibrated specific force less gravity along it (the model at an unknown
/// attitude), per axis, m/s^2.
pub(crate) fn residuals(d: &Data, accel: Option<&Triad>, g: f64) -> Vec<ResidualStats> {
    let Some(a) = accel else { return Vec::new() };
    let mut out = Vec::new();
    for p in &d.poses {
        let c = calibrated(a, p);
        let r = c - c.normalize() * g;
        for k in 0..3 {
            out.push(ResidualStats {
                segment: p.id.clone(),
                sensor: "accel".into(),
                channel: super::AXES[k].into(),
                n: p.n,
                mean: r[k],
                std: p.f_std[k],
                slope_per_s: 0.0,
                unit: "m/s^2".into(),
            });
        }
    }
    out
}
