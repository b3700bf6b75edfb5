//! The paper's claims in simulation: all six coordinates from a navigation-grade IMU with
//! instrumental errors, the two-period differencing against a single period, the closed
//! forms of physics.md as a check of the regressors, and the control experiment.

mod size_effect_support;

use ratecal_engine::fit::size_effect::{COORDS, SizeEffect, estimate};
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
        // Worse, and far outside its own uncertainty (the instrumental part is systematic).
        let sigmas = (0..6)
            .map(|m| errors_mm(&one)[m].abs() / (one.coords_m[m].unwrap().1 * 1e3))
            .fold(0.0, f64::max);
        eprintln!(
            "seed {seed}: worst two periods {worst_two:.3} mm, one period {worst_one:.3} mm ({sigmas:.0} u)"
        );
        assert!(
            worst_one > worst_two && worst_one > 0.3 && sigmas > 20.0,
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
