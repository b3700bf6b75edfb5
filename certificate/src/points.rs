//! The measurement points (ISO/IEC 17025, 7.8.4: the results with their conditions): for
//! each attitude and rate point of the recording, the reference the table applied on the
//! IMU's principal channel, the IMU's mean raw reading there, the error, its U and whether
//! the calibrated model explains the reading within that U.
//!
//! The reference is nominal: at an attitude, local gravity on the axis the manifest names
//! `up` (`+z up`: +g on z), else on the axis that reads it; at a rate point, the table's
//! rate on the gyro axis that reads it, with that axis's sign (the Earth's rate is left in
//! the error, as the bias is). Its standard uncertainty is the station's: gravity's `u`,
//! the rate accuracy's bound over sqrt(3).

use crate::model::MeasurementPoint;
use ratecal_analysis::budget::terms::Stated;
use ratecal_analysis::results::Results;
use ratecal_recording::{Manifest, Recording, SegmentKind};
use std::path::Path;

/// The coverage factor of a point's U.
const K: f64 = 2.0;

/// The points of the recording in `dir` (empty when it cannot be read: not stated).
pub fn points(
    dir: &Path,
    manifest: &Manifest,
    results: &Results,
    stated: &Stated,
) -> Vec<MeasurementPoint> {
    let Ok(rec) = Recording::open(dir) else {
        return Vec::new();
    };
    let g = manifest.station.site.gravity_mps2;
    let mut out = Vec::new();
    for seg in &manifest.segments {
        let rate = match (seg.kind, seg.rate_dps) {
            (SegmentKind::Static, _) => None,
            (SegmentKind::Rate, Some(r)) => Some(r),
            _ => continue,
        };
        let Ok(imu) = rec.read_imu_span(seg.t_start, seg.t_end) else {
            continue;
        };
        let streams = if rate.is_some() {
            &imu.gyro
        } else {
            &imu.accel
        };
        let n = streams[0].len();
        if n < 2 {
            continue;
        }
        let stats: Vec<(f64, f64)> = streams.iter().map(|v| mean_std(v)).collect();
        let dominant = (0..3)
            .max_by(|&a, &b| stats[a].0.abs().total_cmp(&stats[b].0.abs()))
            .unwrap_or(2);
        let named = seg.up.as_deref().and_then(signed_axis);
        let (axis, sign) = match (rate, named) {
            (None, Some(up)) => up,
            _ => (dominant, stats[dominant].0.signum()),
        };
        let (mean, std) = stats[axis];
        let (sensor, reference, u_ref, unit, condition) = match rate {
            None => (
                "accel",
                sign * g,
                stated.gravity_u_mps2.unwrap_or(0.0),
                "m/s^2",
                match &seg.up {
                    Some(up) => format!("attitude, {up} up"),
                    None => format!("attitude, {}{} up", sign_text(sign), AXES[axis]),
                },
            ),
            Some(r) => (
                "gyro",
                sign * r.abs(),
                r.abs() * stated.rate_accuracy.unwrap_or(0.0) / 3f64.sqrt(),
                "deg/s",
                format!(
                    "rate point, {} axis at {} deg/s",
                    seg.axis.as_deref().unwrap_or("table"),
                    crate::render::doc::num(r)
                ),
            ),
        };
        let u = ((std * std) / n as f64 + u_ref * u_ref).sqrt();
        let expanded = K * u;
        let residual = results
            .residuals
            .iter()
            .find(|s| s.segment == seg.id && s.sensor == sensor && s.channel == AXES[axis]);
        let verdict = match residual {
            Some(r) if r.mean.abs() <= expanded => "consistent",
            Some(_) => "inconsistent",
            None => "not_judged",
        };
        out.push(MeasurementPoint {
            segment: seg.id.clone(),
            kind: if rate.is_some() { "rate" } else { "static" }.into(),
            channel: format!("{sensor}.{}", AXES[axis]),
            condition,
            reference,
            reading: mean,
            error: mean - reference,
            expanded,
            k: K,
            unit: unit.into(),
            verdict: verdict.into(),
        });
    }
    out
}

const AXES: [&str; 3] = ["x", "y", "z"];

fn sign_text(s: f64) -> &'static str {
    if s < 0.0 { "-" } else { "+" }
}

/// `+z` -> (2, +1), `-x` -> (0, -1).
fn signed_axis(up: &str) -> Option<(usize, f64)> {
    let (sign, axis) = match up.as_bytes() {
        [b'+', a] => (1.0, *a),
        [b'-', a] => (-1.0, *a),
        [a] => (1.0, *a),
        _ => return None,
    };
    let i = AXES.iter().position(|x| x.as_bytes()[0] == axis)?;
    Some((i, sign))
}

fn mean_std(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
    (mean, var.sqrt())
}

#[cfg(test)]
mod tests {
    use super::signed_axis;

    #[test]
    fn up_names_an_axis_and_its_sign() {
        assert_eq!(signed_axis("+z"), Some((2, 1.0)));
        assert_eq!(signed_axis("-x"), Some((0, -1.0)));
        assert_eq!(signed_axis("up"), None);
    }
}
