//! Sanity checks: what physics guarantees of any recording, checked before its numbers
//! become a verdict. A recording whose accelerometers are in g, whose gyros are in rad/s,
//! whose axis is flipped or whose mount is not the manifest's still fits (to nonsense);
//! these checks say so. Each gives one results.json `sanity` entry (names in
//! docs/results.md); a failed one makes the verdict `incomplete` (not fit for judgment).
//! Time going backwards and clocks without overlap are refused by the reader before an
//! analysis starts (`sanity::time_increasing`, `sanity::clocks_overlap`); here they are
//! checked again for a recording built in memory.
//!
//! Tolerances are those of a plausible IMU of any grade, consumer MEMS included: scale
//! errors within [`SCALE_MAX`], biases within [`ACCEL_BIAS_MAX`] and [`GYRO_BIAS_MAX`]
//! per axis. Every units mistake is a factor of 3 or more (g, mg, ft/s^2, rad/s, counts).

use super::segment::{RawSums, Summary};
use crate::recording::{CadenceReport, Manifest, SegmentKind, TableStream, cadence};
use crate::results::{Parameter, SanityCheck, SanityStatus};
use std::collections::BTreeMap;

/// Largest plausible scale-factor error |K - 1| (10 %: consumer MEMS reach a few %).
pub const SCALE_MAX: f64 = 0.10;
/// Largest plausible accelerometer bias per axis, m/s^2 (consumer MEMS reach 0.5).
pub const ACCEL_BIAS_MAX: f64 = 1.0;
/// Largest plausible gyro bias per axis, deg/s (consumer MEMS reach a few).
pub const GYRO_BIAS_MAX: f64 = 10.0;
/// Largest plausible misalignment (cross-coupling), mrad (about 6 deg).
pub const MISALIGNMENT_MAX: f64 = 100.0;
/// Largest plausible size-effect coordinate (an accelerometer's sensing point from the
/// IMU's reference centre), mm: inside the case of any IMU.
pub const SIZE_EFFECT_MAX_MM: f64 = 300.0;
/// Largest plausible lever arm (a sensing point from the table's axes), mm: on the platform.
pub const LEVER_ARM_MAX_MM: f64 = 1000.0;
/// Largest plausible tilt of a static attitude from the one the table reports, deg (a
/// hand on a bench does better).
pub const ATTITUDE_MAX_DEG: f64 = 10.0;
/// A moving segment is judged by `gyro_follows_table` when its reference rate (RMS of
/// the vector) is at least this, deg/s.
pub const RATE_MIN_DPS: f64 = 5.0;
/// Slack of `gyro_follows_table` for noise and bias wander, deg/s RMS.
pub const RATE_SLACK_DPS: f64 = 2.0;

const CH: [&str; 6] = ["ax", "ay", "az", "gx", "gy", "gz"];

/// The checks on the recording itself (everything but the fitted values), in their
/// results.json order; warnings (dropped samples, jitter) go to `warnings`.
pub(crate) fn recording_checks(
    m: &Manifest,
    sums: &[Summary],
    imu: &CadenceReport,
    imu_extent: (f64, f64),
    table: &TableStream,
    warnings: &mut Vec<String>,
) -> Vec<SanityCheck> {
    let tab = CadenceReport::of(&table.t);
    let with_rows: Vec<(&Summary, SegmentKind, &str)> = sums
        .iter()
        .filter(|s| s.raw.n > 0)
        .map(|s| {
            let seg = &m.segments[s.seg];
            (s, seg.kind, seg.id.as_str())
        })
        .collect();
    let rest: Vec<(&RawSums, &str)> = with_rows
        .iter()
        .filter(|s| s.1 == SegmentKind::Static)
        .map(|s| (&s.0.raw, s.2))
        .collect();
    let moving: Vec<(&RawSums, &str)> = with_rows
        .iter()
        .filter(|s| s.1 != SegmentKind::Static)
        .map(|s| (&s.0.raw, s.2))
        .collect();
    let max_rate = m
        .segments
        .iter()
        .filter_map(|s| s.rate_dps)
        .fold(0.0f64, |a, r| a.max(r.abs()));
    vec![
        time_increasing(imu, &tab),
        clocks_overlap(imu_extent, table),
        sampling(imu, &tab, warnings),
        gravity_magnitude(&rest),
        gravity_direction(&rest),
        gyro_at_rest(&rest, max_rate),
        gyro_follows_table(&moving, &rest),
    ]
}

pub(crate) fn time_increasing(imu: &CadenceReport, table: &CadenceReport) -> SanityCheck {
    let name = "time_increasing";
    for (file, c) in [("imu.csv", imu), ("table.csv", table)] {
        if let Some((prev, t)) = c.backwards {
            return SanityCheck::new(
                name,
                SanityStatus::Fail,
                format!("{file}: time goes backwards or repeats ({t} s after {prev} s)"),
            );
        }
    }
    SanityCheck::new(
        name,
        SanityStatus::Pass,
        "the time stamps of imu.csv and table.csv strictly increase",
    )
}

pub(crate) fn clocks_overlap(imu: (f64, f64), table: &TableStream) -> SanityCheck {
    let name = "clocks_overlap";
    let (Some(&t0), Some(&t1)) = (table.t.first(), table.t.last()) else {
        return SanityCheck::new(name, SanityStatus::Fail, "table.csv holds no samples");
    };
    let common = imu.1.min(t1) - imu.0.max(t0);
    let what = format!(
        "the IMU stream spans {:.3} s .. {:.3} s, the table feedback {t0:.3} s .. {t1:.3} s",
        imu.0, imu.1
    );
    if common > 0.0 {
        SanityCheck::new(
            name,
            SanityStatus::Pass,
            format!("{what}: {common:.3} s in common"),
        )
    } else {
        SanityCheck::new(
            name,
            SanityStatus::Fail,
            format!("{what}: no time in common"),
        )
    }
}

/// Gaps and jitter are counted and located in a warning; they never refuse a recording.
pub(crate) fn sampling(
    imu: &CadenceReport,
    table: &CadenceReport,
    warnings: &mut Vec<String>,
) -> SanityCheck {
    let mut parts = Vec::new();
    for (file, c) in [("imu.csv", imu), ("table.csv", table)] {
        let hz = 1.0 / c.nominal_step_s;
        let mut found = Vec::new();
        if let Some((at, len)) = c.longest_gap {
            found.push(format!(
                "{} gap{} in the time stamps (about {} sample{} dropped), the longest {len:.3} s from t = {at:.3} s",
                c.gaps,
                if c.gaps == 1 { "" } else { "s" },
                c.dropped,
                if c.dropped == 1 { "" } else { "s" },
            ));
        }
        if let Some((at, step)) = c.worst_jitter {
            found.push(format!(
                "{} step{} off the nominal by more than {:.0} %, the worst {step:.4} s at t = {at:.3} s",
                c.jittered,
                if c.jittered == 1 { "" } else { "s" },
                cadence::JITTER_FRACTION * 100.0,
            ));
        }
        let head = format!("{file} nominal {hz:.4} Hz");
        if found.is_empty() {
            parts.push(format!("{head}, no gaps, no jitter"));
        } else {
            let text = found.join("; ");
            warnings.push(format!(
                "{file} (nominal {hz:.4} Hz): {text}; the analysis uses the samples as stamped"
            ));
            parts.push(format!("{head}: {text}"));
        }
    }
    SanityCheck::new("sampling", SanityStatus::Pass, parts.join("; "))
}

/// The mean output of a sensor (0 accel, 3 gyro) and its mean reference over a segment.
fn means(s: &RawSums, first: usize) -> ([f64; 3], [f64; 3]) {
    (
        std::array::from_fn(|k| s.mean_out(first + k)),
        std::array::from_fn(|k| s.mean_ref(first + k)),
    )
}

fn norm(v: [f64; 3]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|k| a[k] - b[k])
}

/// The worst segment of a check: `(excess over its tolerance, detail)`.
fn worst<'a>(
    rest: &[(&'a RawSums, &'a str)],
    f: impl Fn(&RawSums, &str) -> (f64, String),
) -> Option<(f64, String)> {
    rest.iter()
        .map(|(s, id)| f(s, id))
        .max_by(|a, b| a.0.total_cmp(&b.0))
}

/// Bias (vector) and scale allowance of an accelerometer reading `g_ref`, m/s^2.
fn accel_tolerance(g_ref: f64) -> f64 {
    SCALE_MAX * g_ref + ACCEL_BIAS_MAX * 3f64.sqrt()
}

fn gravity_magnitude(rest: &[(&RawSums, &str)]) -> SanityCheck {
    let name = "gravity_magnitude_at_rest";
    let judged = worst(rest, |s, id| {
        let (o, r) = means(s, 0);
        let (got, want) = (norm(o), norm(r));
        let tol = accel_tolerance(want);
        (
            (got - want).abs() - tol,
            format!(
                "segment {id}: |specific force| {got:.4} m/s^2 where the site's gravity gives {want:.4} m/s^2 (tolerance {tol:.2} m/s^2)"
            ),
        )
    });
    verdict(
        name,
        judged,
        "no static segment",
        " (accelerometers in g, mg or raw counts read as m/s^2?)",
    )
}

fn gravity_direction(rest: &[(&RawSums, &str)]) -> SanityCheck {
    let name = "gravity_direction_at_rest";
    let judged = worst(rest, |s, id| {
        let (o, r) = means(s, 0);
        let g = norm(r);
        let tol = accel_tolerance(g) + g * ATTITUDE_MAX_DEG.to_radians().sin();
        let d = norm(sub(o, r));
        (
            d - tol,
            format!(
                "segment {id}: mean specific force [{:.3}, {:.3}, {:.3}] m/s^2 where the table's attitude and the mount give [{:.3}, {:.3}, {:.3}]: {d:.3} m/s^2 apart (tolerance {tol:.2})",
                o[0], o[1], o[2], r[0], r[1], r[2]
            ),
        )
    });
    verdict(
        name,
        judged,
        "no static segment",
        " (a swapped or sign-flipped accelerometer axis, or a mount that is not the manifest's?)",
    )
}

fn gyro_at_rest(rest: &[(&RawSums, &str)], max_rate: f64) -> SanityCheck {
    let name = "gyro_at_rest";
    let mut limit = GYRO_BIAS_MAX * 3f64.sqrt();
    if max_rate > 0.0 {
        limit = limit.min(0.5 * max_rate);
    }
    let against = if max_rate > 0.0 {
        format!(", half the largest table rate {max_rate} deg/s at most")
    } else {
        String::new()
    };
    let judged = worst(rest, |s, id| {
        let (o, _) = means(s, 3);
        let w = norm(o);
        (
            w - limit,
            format!(
                "segment {id}: |angular rate| {w:.4} deg/s at rest (limit {limit:.3} deg/s: a plausible bias{against})"
            ),
        )
    });
    verdict(
        name,
        judged,
        "no static segment",
        " (gyros in mdeg/s or raw counts read as deg/s?)",
    )
}

/// The gyro bias estimated at rest: mean output minus reference over the static segments.
fn rest_bias(rest: &[(&RawSums, &str)]) -> [f64; 3] {
    let n: usize = rest.iter().map(|s| s.0.n).sum();
    if n == 0 {
        return [0.0; 3];
    }
    std::array::from_fn(|k| {
        let c = 3 + k;
        rest.iter().map(|s| s.0.so[c] - s.0.sr[c]).sum::<f64>() / n as f64
    })
}

fn gyro_follows_table(moving: &[(&RawSums, &str)], rest: &[(&RawSums, &str)]) -> SanityCheck {
    let name = "gyro_follows_table";
    let b = rest_bias(rest);
    let judged: Vec<(&RawSums, &str)> = moving
        .iter()
        .copied()
        .filter(|(s, _)| (3..6).map(|c| s.ref_ms(c)).sum::<f64>().sqrt() >= RATE_MIN_DPS)
        .collect();
    let found = worst(&judged, |s, id| {
        let rate = (3..6).map(|c| s.ref_ms(c)).sum::<f64>().sqrt();
        let off = (0..3)
            .map(|k| s.mismatch_ms(3 + k, b[k]))
            .sum::<f64>()
            .sqrt();
        let tol = SCALE_MAX * rate + RATE_SLACK_DPS;
        // The axes that carry the motion, with their gain on the reference.
        let gains: Vec<String> = (0..3)
            .filter(|&k| s.ref_ms(3 + k).sqrt() >= 0.3 * rate)
            .map(|k| format!("{} {:.3}", CH[3 + k], s.gain(3 + k, b[k])))
            .collect();
        (
            off - tol,
            format!(
                "segment {id}: the gyros depart from the table's rate ({rate:.3} deg/s RMS) by {off:.3} deg/s RMS (tolerance {tol:.3}); gain on the reference: {}",
                gains.join(", ")
            ),
        )
    });
    verdict(
        name,
        found,
        &format!("no rate or oscillation segment turns at {RATE_MIN_DPS} deg/s or more"),
        " (gyros in rad/s, a swapped or sign-flipped axis, or a mount that is not the manifest's?)",
    )
}

/// The entry of a check judged segment by segment: `fail` when the worst segment exceeds
/// its tolerance (with `hint`), `pass` with the worst one's figures, or `not_evaluated`.
pub(crate) fn verdict(
    name: &str,
    worst: Option<(f64, String)>,
    none: &str,
    hint: &str,
) -> SanityCheck {
    match worst {
        None => SanityCheck::new(name, SanityStatus::NotEvaluated, none),
        Some((excess, detail)) if excess > 0.0 || excess.is_nan() => {
            SanityCheck::new(name, SanityStatus::Fail, format!("{detail}{hint}"))
        }
        Some((_, detail)) => SanityCheck::new(name, SanityStatus::Pass, format!("worst {detail}")),
    }
}

/// `fitted_values_plausible`: the fitted biases, scale factors, misalignments, lever arms
/// and size-effect coordinates inside the ranges an IMU of any grade and a table have (a scale factor of -90 % is a units error, not a
/// calibration).
pub(crate) fn plausible(params: &BTreeMap<String, Parameter>) -> SanityCheck {
    plausible_with(params, ACCEL_BIAS_MAX)
}

/// Largest plausible accelerometer offset of a part calibrated without a table, m/s^2:
/// consumer parts' raw offsets reach hundreds of mg (the MPU-6050 session: 115 mg), and
/// a manual calibration is the first one they get.
pub const ACCEL_OFFSET_MAX_MANUAL: f64 = 5.0;

/// [`plausible`] with the accelerometer bias allowed up to `accel_bias_max`, m/s^2.
pub(crate) fn plausible_with(
    params: &BTreeMap<String, Parameter>,
    accel_bias_max: f64,
) -> SanityCheck {
    let name = "fitted_values_plausible";
    let rule = |n: &str, unit: &str| -> Option<f64> {
        let kind = n.split('.').nth(1)?;
        match (n.split('.').next()?, kind, unit) {
            ("accel" | "gyro", "scale", "ppm") => Some(SCALE_MAX * 1e6),
            ("accel", "bias", "m/s^2") => Some(accel_bias_max),
            ("gyro", "bias", "deg/s") => Some(GYRO_BIAS_MAX),
            ("accel" | "gyro", "misalignment", "mrad") => Some(MISALIGNMENT_MAX),
            ("size_effect", _, "mm") => Some(SIZE_EFFECT_MAX_MM),
            ("lever_arm", _, "mm") => Some(LEVER_ARM_MAX_MM),
            _ => None,
        }
    };
    let mut checked = 0;
    let mut out = Vec::new();
    for (n, p) in params {
        let Parameter::Estimate { value, unit, .. } = p else {
            continue;
        };
        let Some(limit) = rule(n, unit) else {
            continue;
        };
        checked += 1;
        if value.is_nan() || value.abs() > limit {
            out.push(format!(
                "{n} = {value:.6} {unit} (plausible within +-{limit} {unit})"
            ));
        }
    }
    if checked == 0 {
        return SanityCheck::new(
            name,
            SanityStatus::NotEvaluated,
            "no bias, scale factor, misalignment, lever arm or size effect was fitted",
        );
    }
    if out.is_empty() {
        SanityCheck::new(
            name,
            SanityStatus::Pass,
            format!(
                "{checked} fitted values within +-{:.0} % scale, +-{accel_bias_max} m/s^2 and +-{GYRO_BIAS_MAX} deg/s bias, +-{MISALIGNMENT_MAX} mrad misalignment, +-{LEVER_ARM_MAX_MM} mm lever arm, +-{SIZE_EFFECT_MAX_MM} mm size effect",
                SCALE_MAX * 100.0
            ),
        )
    } else {
        SanityCheck::new(
            name,
            SanityStatus::Fail,
            format!(
                "{} (a units or axis error, not a calibration)",
                out.join("; ")
            ),
        )
    }
}

/// The checks of several runs analysed together, one entry per check: `fail` when any run
/// failed it, else `pass` when any passed it; each run's detail kept, named `run k`.
pub(crate) fn merge(runs: &[&[SanityCheck]]) -> Vec<SanityCheck> {
    let Some(first) = runs.first() else {
        return Vec::new();
    };
    first
        .iter()
        .map(|c| {
            let of: Vec<(usize, &SanityCheck)> = runs
                .iter()
                .enumerate()
                .filter_map(|(k, r)| Some((k, r.iter().find(|x| x.check == c.check)?)))
                .collect();
            let has = |s: SanityStatus| of.iter().any(|(_, x)| x.status == s);
            let status = if has(SanityStatus::Fail) {
                SanityStatus::Fail
            } else if has(SanityStatus::Pass) {
                SanityStatus::Pass
            } else {
                SanityStatus::NotEvaluated
            };
            let detail = of
                .iter()
                .map(|(k, x)| format!("run {}: {}", k + 1, x.detail))
                .collect::<Vec<_>>()
                .join("; ");
            SanityCheck::new(&c.check, status, detail)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_units_error_is_not_a_plausible_calibration() {
        let mut p = BTreeMap::new();
        p.insert(
            "accel.scale.x".to_string(),
            Parameter::estimate(-650.0, 5.0, "ppm"),
        );
        p.insert("gyro.scale.z".to_string(), Parameter::unobservable());
        assert_eq!(plausible(&p).status, SanityStatus::Pass);
        // Accelerometers in g: K = 1 / 9.81.
        p.insert(
            "accel.scale.y".to_string(),
            Parameter::estimate(-898_000.0, 5.0, "ppm"),
        );
        let c = plausible(&p);
        assert_eq!(c.status, SanityStatus::Fail);
        assert!(c.detail.contains("accel.scale.y") && !c.detail.contains("accel.scale.x"));
        assert_eq!(
            plausible(&BTreeMap::new()).status,
            SanityStatus::NotEvaluated
        );
    }

    #[test]
    fn several_runs_fail_a_check_when_one_does() {
        let ok = [SanityCheck::new("gyro_at_rest", SanityStatus::Pass, "a")];
        let bad = [SanityCheck::new("gyro_at_rest", SanityStatus::Fail, "b")];
        let m = merge(&[&ok, &bad]);
        assert_eq!(m.len(), 1);
        assert_eq!(m[0].status, SanityStatus::Fail);
        assert_eq!(m[0].detail, "run 1: a; run 2: b");
    }
}
