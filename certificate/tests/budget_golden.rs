//! One parameter's budget computed by hand with the GUM's formulas, against the crate.

use ratecal_certificate::budget::TermStatus;
use ratecal_certificate::terms::{Stated, TemperatureCoefficients, budget};

#[test]
fn gyro_scale_budget_by_hand() {
    // A gyro scale factor of -653 ppm whose fit gives u_A = 2 ppm on 5 degrees of freedom,
    // on a table whose rate accuracy is stated as 2 sqrt(3) ppm (rectangular).
    let a_ppm = 2.0 * 3f64.sqrt();
    let stated = Stated {
        rate_accuracy: Some(a_ppm * 1e-6),
        gravity_mps2: 9.8156,
        ..Stated::default()
    };
    let b = budget("gyro.scale.x", -653.0, 2.0, "ppm", 5.0, &stated);

    // By hand: u_B = a / sqrt(3) = 2 ppm; u_c = sqrt(2^2 + 2^2) = 2 sqrt(2) ppm;
    // nu_eff = u_c^4 / (u_A^4 / 5 + u_B^4 / inf) = 64 / (16 / 5) = 20;
    // k = t_0.975(20) = 2.086 (GUM table G.2); U = k u_c = 5.900 ppm.
    // (clock and temperature are not stated here: shown, left out of u_c)
    assert_eq!(b.terms.len(), 4);
    assert_eq!(b.terms[1].status, TermStatus::Stated);
    assert!((b.terms[1].u.unwrap() - 2.0).abs() < 1e-12);
    assert!((b.u_c - 2.0 * 2f64.sqrt()).abs() < 1e-12);
    assert!((b.nu_eff.unwrap() - 20.0).abs() < 1e-9);
    assert!((b.k - 2.086).abs() < 5e-4, "k {}", b.k);
    assert!((b.expanded - 2.086 * 2.0 * 2f64.sqrt()).abs() < 2e-3);
    assert!(!b.complete);
}

#[test]
fn gyro_scale_with_timing_and_temperature_by_hand() {
    // The same gyro scale factor (u_A = 2 ppm, 5 degrees of freedom) with every Type B
    // term stated: rate accuracy 2 sqrt(3) ppm, DAQ clock accuracy sqrt(3) ppm, a gyro scale
    // temperature coefficient of -3 ppm/degC and a lab stable to 2/3 sqrt(3) degC.
    let s3 = 3f64.sqrt();
    let stated = Stated {
        rate_accuracy: Some(2.0 * s3 * 1e-6),
        clock_accuracy: Some(s3 * 1e-6),
        temperature_stability_c: Some(2.0 / 3.0 * s3),
        temperature_coefficients: TemperatureCoefficients {
            gyro_scale: Some(-3.0),
            ..Default::default()
        },
        gravity_mps2: 9.8156,
        ..Stated::default()
    };
    let b = budget("gyro.scale.x", -653.0, 2.0, "ppm", 5.0, &stated);
    // By hand, each rectangular bound a gives a / sqrt(3):
    //   rate: 2 sqrt(3) / sqrt(3) = 2 ppm; clock: sqrt(3) / sqrt(3) = 1 ppm;
    //   temperature: |c| dT / sqrt(3) = 3 * (2/3) sqrt(3) / sqrt(3) = 2 ppm.
    // u_c = sqrt(4 + 4 + 1 + 4) = sqrt(13) ppm;
    // nu_eff = u_c^4 / (u_A^4 / 5) = 169 / (16 / 5) = 52.8125 (Type B: infinite dof);
    // k = t_0.975(52.8) = 2.0058 (t_0.975(50) = 2.0086, t_0.975(60) = 2.0003);
    // U = k u_c = 7.232 ppm.
    let by_source = |s: &str| {
        b.terms
            .iter()
            .find(|t| t.source == s)
            .unwrap_or_else(|| panic!("{s}: {:?}", b.terms))
    };
    assert_eq!(b.terms.len(), 4);
    assert!((by_source("table rate accuracy").u.unwrap() - 2.0).abs() < 1e-12);
    assert!((by_source("DAQ clock accuracy").u.unwrap() - 1.0).abs() < 1e-12);
    let temp = by_source("temperature sensitivity");
    assert_eq!(temp.distribution, "rectangular");
    assert!((temp.u.unwrap() - 2.0).abs() < 1e-12);
    assert!(
        temp.sensitivity.starts_with("-3 ppm per degC"),
        "{}",
        temp.sensitivity
    );
    assert!((b.u_c - 13f64.sqrt()).abs() < 1e-12);
    assert!((b.nu_eff.unwrap() - 52.8125).abs() < 1e-9);
    assert!((b.k - 2.0058).abs() < 5e-4, "k {}", b.k);
    assert!((b.expanded - 2.0058 * 13f64.sqrt()).abs() < 2e-3);
    assert!(b.complete);
}

#[test]
fn accel_bias_through_the_gravity_projection_by_hand() {
    // 5 arcsec position accuracy on g = 9.8156 m/s^2: u = g * 5 arcsec / sqrt(3).
    let arcsec = std::f64::consts::PI / 180.0 / 3600.0;
    let stated = Stated {
        position_accuracy_rad: Some(5.0 * arcsec),
        gravity_mps2: 9.8156,
        ..Stated::default()
    };
    let b = budget("accel.bias.x", 0.01, 1e-5, "m/s^2", 12.0, &stated);
    let u_pos = 9.8156 * 5.0 * arcsec / 3f64.sqrt();
    assert!((b.terms[1].u.unwrap() - u_pos).abs() < 1e-15);
    // Orthogonality and temperature not stated: shown, never 0, and the budget says it is
    // incomplete.
    assert_eq!(b.terms.len(), 4);
    assert_eq!(b.terms[2].status, TermStatus::NotStated);
    assert!(b.terms[2].u.is_none() && !b.complete);
    assert_eq!(b.terms[3].source, "temperature sensitivity");
    assert_eq!(b.terms[3].status, TermStatus::NotStated);
    let u_c: f64 = (1e-10 + u_pos * u_pos).sqrt();
    assert!((b.u_c - u_c).abs() < 1e-15);
    let nu = u_c.powi(4) / (1e-20 / 12.0);
    assert!((b.nu_eff.unwrap() - nu).abs() < 1e-9 * nu);
}
