//! `Checked::observability`: which registry effects a procedure's motion lets explain
//! determine, asked of the plan with the analysis's own regressors. Derived by hand: six
//! static faces turn gravity through every axis but never rotate, so nothing that needs a
//! rate (lever arm, timing) is determined, while the standard
//! procedure's rate points determine the lever arm's diagonal (the centripetal terms along
//! each axis) and not its cross terms.

use ratecal_check::{CheckOptions, EffectObservability, NoImports, check_text};

const STANDARD: &str = include_str!("../../../procedures/imu-2d-standard/1.0.0.rcal");

const SIX_FACES: &str = r#"procedure six-faces version 0.1.0 {
  step faces {
    for (n, pitch, roll) in [
      (1, 0 deg, 0 deg),
      (2, 0 deg, 180 deg),
      (3, 90 deg, 0 deg),
      (4, -90 deg, 0 deg),
      (5, 0 deg, 90 deg),
      (6, 0 deg, 270 deg),
    ] {
      move to pitch pitch, roll roll
      settle for 5 s
      acquire accel, gyro for 10 s at 100 Hz as "face/{n}"
    }
    fit accel bias_scale from face/*
  }
}"#;

fn observability(text: &str) -> Vec<EffectObservability> {
    check_text("p", text, &NoImports, &CheckOptions::default())
        .unwrap_or_else(|d| panic!("{d:?}"))
        .observability()
        .to_vec()
}

fn of<'a>(obs: &'a [EffectObservability], id: &str) -> &'a EffectObservability {
    obs.iter().find(|o| o.effect == id).expect(id)
}

#[test]
fn six_static_faces_determine_no_rotation_physics() {
    let obs = observability(SIX_FACES);
    // (The gyro asymmetry is not among them: at rest the gyros see the Earth's rate, whose
    // magnitude on each axis differs from face to face.)
    for id in ["lever_arm", "time_offset", "clock_rate"] {
        let o = of(&obs, id);
        assert!(o.determined.is_empty(), "{id}: {:?}", o.determined);
        assert!(o.not.iter().all(|n| !n.1.is_empty()), "{id}: needs said");
    }
    // Gravity along every axis, both signs: the misalignment is determined in full, and
    // each axis sees three levels (-g, 0, +g), so f_i^2 is separable from a bias and a
    // scale factor (the second order and the asymmetry are, each beside the nominal model;
    // from each other they are not, which is explain's `not_separable_from`).
    for id in [
        "accel_misalignment",
        "accel_second_order",
        "accel_scale_asymmetry",
    ] {
        let o = of(&obs, id);
        assert!(o.not.is_empty(), "{id}: {:?}", o.not);
    }
}

#[test]
fn the_standard_procedure_determines_the_lever_arm_diagonal_only() {
    let obs = observability(STANDARD);
    let lever = of(&obs, "lever_arm");
    let mut det = lever.determined.clone();
    det.sort_unstable();
    assert_eq!(det, ["rxx_mm", "ryy_mm", "rzz_mm"], "{lever:?}");
    for id in ["gyro_thermal_drift", "accel_scale_thermal"] {
        assert!(of(&obs, id).determined.is_empty(), "{id}");
    }
    assert!(
        of(&obs, "time_offset").not.is_empty(),
        "rate points time the IMU"
    );
}
