//! Explain on harder simulated recordings of the standard plan: pairs and triples of
//! effects at once (the correlated ones among them), a navigation-grade IMU whose largest
//! unmodelled signal is the Earth's rotation, and effects far below the per-sample noise
//! (the Earth's rate in a 30-minute tactical recording with 0.005 deg/s of noise; a thermal
//! drift worth two thirds of the noise). Each on several seeds: explain names exactly the effects
//! present (and the Earth's rate, which every recording holds), recovers their parameters
//! within their uncertainty, and reaches the noise floor.

use crate::common;
use common::explain::{found, within};
use common::plans::standard;
use common::sim::{record, station};
use ratecal_analysis::explain::{self, Explanation, NominalModel, Options, Parameter};
use ratecal_drivers::Station;
use ratecal_recording as recording;

fn explain_run(st: &Station, block_s: f64, seed: u64) -> Explanation {
    let dir = tempfile::tempdir().unwrap();
    record(st, &standard(block_s), seed, dir.path());
    let rec = recording::read(dir.path()).unwrap();
    explain::explain(&rec, &NominalModel::seed(), &Options::default())
}

/// The final residual RMS at most `f` times the noise floor explain states.
fn at_floor(x: &Explanation, f: f64) {
    let (r, n) = (x.final_.rms, x.final_.noise_floor);
    assert!(r.accel_mps2 < f * n.accel_mps2, "accel {r:?} vs {n:?}");
    assert!(r.gyro_dps < f * n.gyro_dps, "gyro {r:?} vs {n:?}");
}

/// The Earth's rate as explain reports it: the latitude is the manifest's (held, u 0); the
/// heading of the table's axes is fitted. Returns the heading and its u.
fn heading(x: &Explanation) -> (f64, f64) {
    let f = x
        .findings
        .iter()
        .find(|f| f.effect == "earth_rate")
        .unwrap();
    match &f.parameters["latitude_deg"] {
        Parameter::Estimate { value, u, .. } => assert_eq!((*value, *u), (55.7, 0.0)),
        p => panic!("latitude not reported: {p:?}"),
    }
    match &f.parameters["heading_deg"] {
        Parameter::Estimate { value, u, .. } => (*value, *u),
        p => panic!("heading not determined: {p:?}"),
    }
}

const LEVER: &str = "lever_arm: { rxx_mm: -4, ryy_mm: 14, rzz_mm: 25 }";
const LEVER_TRUTH: &[(&str, f64)] = &[("rxx_mm", -4.0), ("ryy_mm", 14.0), ("rzz_mm", 25.0)];

/// A lever arm and a time offset both show during rotation (centripetal vs the rotating
/// gravity vector's lag): told apart, each measured.
#[test]
fn lever_arm_and_time_offset_together() {
    let st = station(&format!("{{ {LEVER}, time_offset: {{ tau_ms: 3 }} }}"), &[]);
    for seed in [8, 9] {
        let x = explain_run(&st, 600.0, seed);
        // The simulator re-times exactly; the registry's time offset is first order, and
        // what it leaves (`-tau^2 |w|^2 f / 2`) may be discovered as that form, nothing else.
        for f in x.findings.iter().filter(|f| f.discovered) {
            assert!(
                f.terms
                    .iter()
                    .all(|t| t.expression.contains("w_b.x * f_b.x + w_b.y * f_b.y")),
                "seed {seed}: {} discovered",
                f.effect
            );
        }
        let named: Vec<&str> = found(&x)
            .into_iter()
            .filter(|f| !f.starts_with("discovered_"))
            .collect();
        assert_eq!(
            named,
            ["earth_rate", "lever_arm", "time_offset"],
            "seed {seed}: rejected {:?}",
            x.rejected
        );
        within(&x, "lever_arm", LEVER_TRUTH, 3.0);
        within(&x, "time_offset", &[("tau_ms", 3.0)], 3.0);
        at_floor(&x, 1.15);
    }
}

/// g-sensitivity and the Earth's rate both vary with the attitude; with a gyro
/// misalignment as a third, all three are named and measured, the latitude included.
#[test]
fn g_sensitivity_earth_rate_and_gyro_misalignment_together() {
    let st = station(
        "{ g_sensitivity: { xx_dps_per_g: 0.002, yy_dps_per_g: -0.0015, zz_dps_per_g: 0.001 }, \
           gyro_misalignment: { xy_mrad: -0.5, yx_mrad: 0.6, zx_mrad: 0.4 } }",
        &[],
    );
    for seed in [10, 11] {
        let x = explain_run(&st, 600.0, seed);
        assert_eq!(
            found(&x),
            ["earth_rate", "g_sensitivity", "gyro_misalignment"],
            "seed {seed}: rejected {:?}",
            x.rejected
        );
        within(
            &x,
            "g_sensitivity",
            &[
                ("xx_dps_per_g", 0.002),
                ("yy_dps_per_g", -0.0015),
                ("zz_dps_per_g", 0.001),
            ],
            3.0,
        );
        within(
            &x,
            "gyro_misalignment",
            &[("xy_mrad", -0.5), ("yx_mrad", 0.6), ("zx_mrad", 0.4)],
            3.0,
        );
        let (h, u) = heading(&x);
        assert!(h.abs() < 3.0 * u, "seed {seed}: heading {h} ± {u}");
        at_floor(&x, 1.15);
    }
}

/// Three effects of both sensors: a lever arm, an accelerometer misalignment and a gyro
/// scale nonlinearity.
#[test]
fn three_effects_of_both_sensors() {
    let st = station(
        &format!(
            "{{ {LEVER}, accel_misalignment: {{ xy_mrad: 0.4, yz_mrad: 0.5, zx_mrad: -0.6 }}, \
               gyro_scale_nonlinearity: {{ x: 2, y: -1.5 }} }}"
        ),
        &[],
    );
    for seed in [12, 13] {
        let x = explain_run(&st, 600.0, seed);
        assert_eq!(
            found(&x),
            [
                "accel_misalignment",
                "earth_rate",
                "gyro_scale_nonlinearity",
                "lever_arm"
            ],
            "seed {seed}: rejected {:?}",
            x.rejected
        );
        within(&x, "lever_arm", LEVER_TRUTH, 3.0);
        within(
            &x,
            "accel_misalignment",
            &[("xy_mrad", 0.4), ("yz_mrad", 0.5), ("zx_mrad", -0.6)],
            3.0,
        );
        within(
            &x,
            "gyro_scale_nonlinearity",
            &[("x", 2.0), ("y", -1.5)],
            3.0,
        );
        at_floor(&x, 1.15);
    }
}

/// A navigation-grade IMU (0.00003 deg/s/rtHz, 0.01 deg/h bias instability, a bias random
/// walk of 1e-8 deg/s/rts, 0.2 ug/rtHz):
/// the Earth's rate, which the standard's seed model leaves out, is by far its largest
/// error signal; explain finds it alone and puts the station within a fraction of a degree
/// of its latitude.
#[test]
fn navigation_grade_imu_shows_the_earth_rate() {
    let st = station(
        "{}",
        &[
            (
                "gyro_noise_density: 0.0003 deg/s/rtHz",
                "gyro_noise_density: 0.00003 deg/s/rtHz",
            ),
            (
                "gyro_bias_markov_sigma: 2 deg/h",
                "gyro_bias_markov_sigma: 0.01 deg/h",
            ),
            (
                "gyro_bias_random_walk: 1e-6 deg/s/rts",
                "gyro_bias_random_walk: 1e-8 deg/s/rts",
            ),
            (
                "accel_noise_density: 2 ug/rtHz",
                "accel_noise_density: 0.2 ug/rtHz",
            ),
        ],
    );
    for seed in [14, 15] {
        let x = explain_run(&st, 600.0, seed);
        assert_eq!(found(&x), ["earth_rate"], "seed {seed}: {:?}", x.rejected);
        // The simulated table is aligned with north: heading zero within 3u.
        let (h, u) = heading(&x);
        assert!(h.abs() < 3.0 * u, "seed {seed}: heading {h} ± {u}");
        assert!(u < 2.0, "seed {seed}: heading ± {u} deg");
        at_floor(&x, 1.15);
    }
}

/// The Earth's rate (about 0.004 deg/s) in a 30-minute tactical-grade recording with
/// 0.005 deg/s of noise per sample (0.0005 deg/s/rtHz at 100 Hz).
#[test]
fn earth_rate_below_the_noise_in_thirty_minutes() {
    let st = station(
        "{}",
        &[(
            "gyro_noise_density: 0.0003 deg/s/rtHz",
            "gyro_noise_density: 0.0005 deg/s/rtHz",
        )],
    );
    for seed in [16, 17] {
        let x = explain_run(&st, 1500.0, seed);
        assert_eq!(found(&x), ["earth_rate"], "seed {seed}: {:?}", x.rejected);
        let (h, u) = heading(&x);
        assert!(h.abs() < 3.0 * u, "seed {seed}: heading {h} ± {u}");
    }
}

/// A gyro thermal drift worth two thirds of the per-sample noise through the warm-up
/// (0.0005 deg/s per degC over the 4 degC warm-up: 0.002 deg/s against 0.003 deg/s of
/// noise) is found, judged against the wandering bias (its estimate plus one standard
/// error: half the noise was found before the wander's own uncertainty was counted), and
/// measured.
#[test]
fn thermal_drift_at_two_thirds_of_the_noise() {
    let st = station(
        "{ gyro_thermal_drift: { x: 0.0005 } }",
        &[(
            "gyro_bias_markov_sigma: 2 deg/h",
            "gyro_bias_markov_sigma: 0.3 deg/h",
        )],
    );
    for seed in [18, 19] {
        let x = explain_run(&st, 600.0, seed);
        assert_eq!(
            found(&x),
            ["earth_rate", "gyro_thermal_drift"],
            "seed {seed}: {:?}",
            x.rejected
        );
        within(&x, "gyro_thermal_drift", &[("x", 0.0005)], 3.0);
    }
}
