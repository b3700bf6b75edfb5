//! `ratecal analyze --with <effect>` on simulated recordings of the standard plan (a
//! ten-minute gyro block) with that effect present in the IMU, one catalogue effect at a
//! time: declared, its parameters land within their uncertainty of the truth, the residuals
//! come down to the IMU's noise, and the parameters the motion cannot excite say what would
//! determine them. Not declared, the residuals of the affected segments show it.

use crate::common;
use common::plans::standard;
use common::sim::{record, station};
use ratecal_analysis::fit::{self, Options};
use ratecal_analysis::results::{Parameter, Results};
use ratecal_physics::effects::EarthRate;
use ratecal_recording as recording;

/// The configured white noise of the default station at 100 Hz: accel m/s^2, gyro deg/s.
const NOISE: (f64, f64) = (2e-6 * 9.80665 * 10.0, 0.003);

/// Simulates the station with `effects` and analyses it by kind, with `with` declared.
fn analyse(effects: &str, seed: u64, with: &[&str]) -> Results {
    let dir = tempfile::tempdir().unwrap();
    record(&station(effects, &[]), &standard(600.0), seed, dir.path());
    let rec = recording::read(dir.path()).unwrap();
    let opts = Options {
        with: with.iter().map(|s| s.to_string()).collect(),
        ..Options::default()
    };
    fit::analyze_with(&rec, None, &opts)
}

/// Each `(key, truth)` is estimated within 3u (plus a thousandth of the truth: the
/// second-order product of a scale error and the effect is outside the linear model), and
/// every other parameter of the effect is either consistent with zero or says what motion
/// it needs.
fn within(res: &Results, effect: &str, truth: &[(&str, f64)]) {
    for (key, p) in res
        .parameters
        .iter()
        .filter(|(k, _)| k.starts_with(&format!("{effect}.")))
    {
        let param = &key[effect.len() + 1..];
        let want = truth.iter().find(|t| t.0 == param).map(|t| t.1);
        match p {
            Parameter::Estimate { value, u, .. } => {
                let w = want.unwrap_or(0.0);
                assert!(
                    (value - w).abs() <= 3.0 * u + 1e-3 * w.abs(),
                    "{key} = {value} ± {u}, truth {w}"
                );
            }
            Parameter::Unobservable { needs, .. } => {
                assert!(needs.is_some(), "{key}: unobservable without saying why");
                assert!(
                    want.is_none(),
                    "{key}: the truth {want:?} was not determined"
                );
            }
            Parameter::UpperBound { .. } => panic!("{key}: an effect's parameter as a bound"),
        }
    }
    for (param, _) in truth {
        assert!(
            res.parameters.contains_key(&format!("{effect}.{param}")),
            "{effect}.{param} missing"
        );
    }
}

/// The RMS of one sensor's residuals over every segment.
fn rms(res: &Results, sensor: &str) -> f64 {
    let (mut ss, mut n) = (0.0, 0.0);
    for r in res.residuals.iter().filter(|r| r.sensor == sensor) {
        let k = r.n as f64;
        ss += k * (r.mean * r.mean + r.std * r.std);
        n += k;
    }
    (ss / n).sqrt()
}

fn at_noise(res: &Results) {
    assert!(
        rms(res, "accel") < 1.2 * NOISE.0,
        "accel {}",
        rms(res, "accel")
    );
    assert!(
        rms(res, "gyro") < 1.2 * NOISE.1,
        "gyro {}",
        rms(res, "gyro")
    );
}

/// Station effects, effect id, truth.
type Case<'a> = (&'a str, &'a str, &'a [(&'a str, f64)]);

/// Each catalogue effect, declared.
#[test]
fn each_declared_effect_is_recovered() {
    let lat = 55.7;
    let [north, up] = EarthRate::values(lat);
    let cases: &[Case] = &[
        (
            "{}",
            "earth_rate",
            &[("north_dph", north), ("up_dph", up), ("latitude_deg", lat)],
        ),
        (
            "{ lever_arm: { rxx_mm: -4, ryy_mm: 14, rzz_mm: 25 } }",
            "lever_arm",
            &[("rxx_mm", -4.0), ("ryy_mm", 14.0), ("rzz_mm", 25.0)],
        ),
        (
            "{ time_offset: { tau_ms: 3 } }",
            "time_offset",
            &[("tau_ms", 3.0)],
        ),
        (
            "{ accel_misalignment: { xy_mrad: 0.4, yz_mrad: 0.5, zx_mrad: -0.6 } }",
            "accel_misalignment",
            &[("xy_mrad", 0.4), ("yz_mrad", 0.5), ("zx_mrad", -0.6)],
        ),
        (
            "{ gyro_misalignment: { xy_mrad: -0.5, yx_mrad: 0.6, zx_mrad: 0.4 } }",
            "gyro_misalignment",
            &[("xy_mrad", -0.5), ("yx_mrad", 0.6), ("zx_mrad", 0.4)],
        ),
        (
            "{ g_sensitivity: { xx_dps_per_g: 0.002, yy_dps_per_g: -0.0015, xz_dps_per_g: 0.0008 } }",
            "g_sensitivity",
            &[
                ("xx_dps_per_g", 0.002),
                ("yy_dps_per_g", -0.0015),
                ("xz_dps_per_g", 0.0008),
            ],
        ),
        (
            "{ accel_thermal_drift: { x: 0.0004, y: -0.0003, z: 0.0005 } }",
            "accel_thermal_drift",
            &[("x", 0.0004), ("y", -0.0003), ("z", 0.0005)],
        ),
        (
            "{ gyro_scale_nonlinearity: { x: 2, y: -1.5 } }",
            "gyro_scale_nonlinearity",
            &[("x", 2.0), ("y", -1.5)],
        ),
    ];
    for (i, (effects, id, truth)) in cases.iter().enumerate() {
        let res = analyse(effects, 20 + i as u64, &[id]);
        within(&res, id, truth);
        at_noise(&res);
        // The joint fit's correlations name the effect's parameters.
        let joint: Vec<&String> = res.fits.values().flat_map(|f| &f.parameters).collect();
        assert!(
            joint.iter().any(|k| k.starts_with(&format!("{id}."))),
            "{id}: not in the fits' parameter lists"
        );
    }
}

/// The gyro thermal drift, against the wandering bias (physics.md): a drift of 0.002
/// deg/s per degC through the IMU's 4 degC warm-up is found, and the nominal model,
/// without it, shows a gyro residual trend on the static block.
#[test]
fn gyro_thermal_drift_is_recovered() {
    let effects = "{ gyro_thermal_drift: { x: 0.002, y: -0.0015, z: 0.001 } }";
    let res = analyse(effects, 31, &["gyro_thermal_drift"]);
    within(
        &res,
        "gyro_thermal_drift",
        &[("x", 0.002), ("y", -0.0015), ("z", 0.001)],
    );
    let (x, u) = res.value("gyro_thermal_drift.x").unwrap();
    assert!(x > 3.0 * u, "{x} ± {u} cannot be told from zero");
}

/// A z-axis scale nonlinearity and a lever arm's coordinates the standard never excites
/// (nothing rotates about Z) are not determined, and say so.
#[test]
fn what_the_motion_cannot_excite_says_what_would() {
    let res = analyse("{}", 5, &["lever_arm", "gyro_scale_nonlinearity"]);
    let needs = |k: &str| match &res.parameters[k] {
        Parameter::Unobservable { needs, .. } => needs.clone().unwrap_or_default(),
        p => panic!("{k} determined: {p:?}"),
    };
    assert!(needs("gyro_scale_nonlinearity.z").contains("about Z"));
    assert!(needs("lever_arm.rxy_mm").contains("about Z"));
}

/// Not declared, a lever arm shows in the accelerometer residuals of the rate segments the
/// seed model does not fit (the centripetal term at 100 deg/s), with a warning.
#[test]
fn an_undeclared_lever_arm_shows_in_the_rate_segment_residuals() {
    let res = analyse(
        "{ lever_arm: { rxx_mm: -4, ryy_mm: 14, rzz_mm: 25 } }",
        7,
        &[],
    );
    let worst = res
        .residuals
        .iter()
        .filter(|r| r.sensor == "accel" && r.segment.starts_with("gyro_scale/"))
        .map(|r| r.mean.abs())
        .fold(0.0, f64::max);
    // 25 mm at 100 deg/s: w^2 r = 3.05^2 * 0.025 = 0.23 m/s^2 (half of it about the
    // inner axis, where rzz feels it along z).
    assert!(worst > 0.05, "{worst}");
    assert!(
        res.warnings
            .iter()
            .any(|w| w.contains("accel") && w.contains("gyro_scale/")),
        "{:?}",
        res.warnings
    );
    let declared = analyse(
        "{ lever_arm: { rxx_mm: -4, ryy_mm: 14, rzz_mm: 25 } }",
        7,
        &["lever_arm"],
    );
    assert!(declared.warnings.iter().all(|w| !w.contains("gyro_scale/")));
}
