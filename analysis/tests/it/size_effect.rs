//! The paper's claims in simulation: all six coordinates from a navigation-grade IMU with
//! instrumental errors, the two-period differencing against a single period, the closed
//! forms of physics.md as a check of the regressors, and the control experiment.

use crate::size_effect_support;
use ratecal_analysis::fit::size_effect::{COORDS, SizeEffect, estimate};
use ratecal_physics::ImuErrors;
use ratecal_physics::nav::sway_coefficient;
use size_effect_support::{Experiment, TRUTH_MM, lever, nav_grade, record, sways};
use std::f64::consts::PI;

fn errors_mm(est: &SizeEffect) -> [f64; 6] {
    std::array::from_fn(|m| {
        let (v, _) = est.coords_m[m].expect("observable");
        v * 1e3 - TRUTH_MM[m]
    })
}

fn show(label: &str, est: &SizeEffect) -> f64 {
    let e = errors_mm(est);
    for (m, (_, _, name)) in COORDS.iter().enumerate() {
        let (v, u) = est.coords_m[m].unwrap();
        eprintln!(
            "{label} {name}: {:.4} mm (truth {:.4}, error {:+.4}, u {:.4})",
            v * 1e3,
            TRUTH_MM[m],
            e[m],
            u * 1e3
        );
    }
    e.iter().fold(0.0, |a, b| a.max(b.abs()))
}

fn experiment(seed: u64) -> Experiment {
    Experiment {
        periods_s: vec![5.0, 10.0],
        sway_s: 300.0,
        hz: 100.0,
        seed,
        noise: true,
    }
}

#[test]
fn two_periods_recover_all_six_coordinates_through_instrumental_errors() {
    for seed in [1, 2] {
        let rec = record(&experiment(seed), &nav_grade(&TRUTH_MM));
        let two = estimate(&rec, &sways(&rec, &[5.0, 10.0]));
        assert!(two.warnings.is_empty(), "{:?}", two.warnings);
        let worst_two = show(&format!("seed {seed}, two periods"), &two);
        assert!(worst_two < 0.5, "seed {seed}: worst error {worst_two} mm");
        // One period per cycle: the instrumental errors stay in the estimate.
        let one = estimate(&rec, &sways(&rec, &[5.0]));
        let worst_one = show(&format!("seed {seed}, 5 s only"), &one);
        // Worse, and far outside its own uncertainty (the instrumental part is systematic;
        // u comes from the per-period accelerations' scatter, honest for the random walk of
        // velocity that white accelerometer noise makes).
        let sigmas = (0..6)
            .map(|m| errors_mm(&one)[m].abs() / (one.coords_m[m].unwrap().1 * 1e3))
            .fold(0.0, f64::max);
        eprintln!(
            "seed {seed}: worst two periods {worst_two:.3} mm, one period {worst_one:.3} mm ({sigmas:.0} u)"
        );
        assert!(
            worst_one > worst_two && worst_one > 0.3 && sigmas > 5.0,
            "seed {seed}: single period {worst_one} mm ({sigmas} u) vs two periods {worst_two} mm"
        );
    }
}

#[test]
fn regressors_match_the_closed_forms_on_the_vertical_cycles() {
    // physics.md, Z up, th0 = 0: <da_E> = r_yx / c, <da_N> = r_xy / c; an ideal IMU.
    let x = Experiment {
        noise: false,
        ..experiment(1)
    };
    let imu = ImuErrors {
        lever_m: lever(&TRUTH_MM),
        ..Default::default()
    };
    let rec = record(&x, &imu);
    let est = estimate(&rec, &sways(&rec, &[5.0, 10.0]));
    for d in est.drifts.iter().filter(|d| d.id.starts_with("sway/z/")) {
        let c = sway_coefficient(PI / 2.0, d.period_s);
        assert!(
            (d.h[0][2] * c - 1.0).abs() < 2e-3,
            "{}: {}",
            d.id,
            d.h[0][2] * c
        );
        assert!(
            (d.h[1][0] * c - 1.0).abs() < 2e-3,
            "{}: {}",
            d.id,
            d.h[1][0] * c
        );
        for m in [1, 3, 4, 5] {
            assert!(d.h[0][m].abs() * c < 1e-3 && d.h[1][m].abs() * c < 1e-3);
        }
    }
    let worst = show("ideal IMU", &est);
    assert!(worst < 0.05, "worst error {worst} mm");
}

/// Final velocity error (m/s) after five fast back-and-forth 180 deg turns about the
/// vertical with body axis `up` up, navigating on outputs compensated with `r_mm`.
fn control_run(up: usize, r_mm: &[f64; 6]) -> f64 {
    use ratecal_physics::nav::{align, angular_accel, compensate, navigate};
    use ratecal_physics::{AxisMotion, DEG, Geometry, Mat3, TableState, Vec3};
    use size_effect_support::{SITE, mount_up};
    let geo = Geometry::vertical_outer().with_mount(mount_up(up));
    let imu = nav_grade(&TRUTH_MM);
    let tilt = if up == 0 { 5.0 * DEG } else { 0.0 };
    let hz = 100.0;
    // 10 s at rest, then 0 -> 180 -> 0 deg in 2 s, five times, then 10 s at rest.
    let turn = |s: f64| {
        let w = PI;
        if (0.0..10.0).contains(&s) {
            AxisMotion {
                angle: PI / 2.0 * (1.0 - (w * s).cos()),
                rate: PI / 2.0 * w * (w * s).sin(),
                accel: PI / 2.0 * w * w * (w * s).cos(),
            }
        } else {
            AxisMotion::default()
        }
    };
    let (mut t, mut w, mut f) = (Vec::new(), Vec::new(), Vec::new());
    for k in 0..(30.0 * hz) as usize {
        let tk = k as f64 / hz;
        let state = TableState {
            outer: turn(tk - 10.0),
            inner: AxisMotion {
                angle: tilt,
                ..Default::default()
            },
        };
        let (a, g) = imu.measure(&state, &geo, &SITE, 20.0);
        t.push(tk);
        w.push(g * DEG);
        f.push(a);
    }
    let r = Mat3::new(
        0.0, r_mm[0], r_mm[1], r_mm[2], 0.0, r_mm[3], r_mm[4], r_mm[5], 0.0,
    ) * 1e-3;
    let dw = angular_accel(&t, &w);
    let fc: Vec<Vec3> = (0..t.len())
        .map(|k| compensate(&f[k], &w[k], &dw[k], &r))
        .collect();
    let n0 = (10.0 * hz) as usize - 10;
    let mean = |v: &[Vec3]| v[..n0].iter().sum::<Vec3>() / n0 as f64;
    let c0 = align(&mean(&fc), &mean(&w), SITE.gravity_mps2).expect("at rest");
    let nav = navigate(&t[n0..], &w[n0..], &fc[n0..], &c0, &SITE, false);
    let v = nav.v_l.last().unwrap();
    v.x.hypot(v.y)
}

#[test]
fn control_experiment_calibrated_coordinates_cut_the_velocity_error() {
    // The paper's control: fast back-and-forth 180 deg turns about each axis, compensated
    // with the calibrated coordinates, and with coordinates 5 mm off (the design document).
    let rec = record(&experiment(3), &nav_grade(&TRUTH_MM));
    let est = estimate(&rec, &sways(&rec, &[5.0, 10.0]));
    let cal: [f64; 6] = std::array::from_fn(|m| est.coords_m[m].unwrap().0 * 1e3);
    let design: [f64; 6] =
        std::array::from_fn(|m| TRUTH_MM[m] + if m % 2 == 0 { 5.0 } else { -5.0 });
    for up in [2, 0, 1] {
        let (v_cal, v_design) = (control_run(up, &cal), control_run(up, &design));
        eprintln!(
            "control, {} up: {v_cal:.5} m/s calibrated, {v_design:.5} m/s 5 mm off, ratio {:.1}",
            ["X", "Y", "Z"][up],
            v_design / v_cal
        );
        assert!(v_design > 5.0 * v_cal, "{up}: {v_cal} vs {v_design}");
    }
}
