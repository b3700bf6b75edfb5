//! The registry against independent forms: the kinematics' own specific force at a point,
//! finite differences along a trajectory, and the Earth's rate.

use super::*;
use crate::{AxisMotion, DEG, Geometry, ImuErrors, Mat3, Site, TableState};

const SITE: Site = Site {
    latitude_deg: 40.0,
    gravity_mps2: 9.80,
};

fn moving(t: f64) -> TableState {
    TableState {
        outer: AxisMotion {
            angle: 0.3 + 0.5 * t + 0.1 * t * t,
            rate: 0.5 + 0.2 * t,
            accel: 0.2,
        },
        inner: AxisMotion {
            angle: -0.2 + 1.1 * t - 0.3 * t * t,
            rate: 1.1 - 0.6 * t,
            accel: -0.6,
        },
    }
}

fn geo() -> Geometry {
    // A mount that is not the identity, so body and platform axes differ.
    Geometry::seed().with_mount(crate::rotation(&Vec3::new(0.0, 0.0, 1.0), 0.4))
}

fn signals(t: f64) -> Signals {
    Signals::new(&moving(t).snapshot(&geo(), &SITE), &SITE, 0.0)
}

#[test]
fn ids_are_unique_and_the_catalogue_is_physics_md() {
    let ids: Vec<&str> = catalogue().map(|e| e.id()).collect();
    assert_eq!(
        ids,
        [
            "earth_rate",
            "lever_arm",
            "time_offset",
            "accel_misalignment",
            "gyro_misalignment",
            "g_sensitivity",
            "gyro_thermal_drift",
            "accel_thermal_drift",
            "gyro_scale_nonlinearity"
        ]
    );
    for e in REGISTRY {
        assert!(effect(e.id()).is_some());
        assert!(e.params().len() <= 16, "forward's buffer");
        assert!(!e.explanation().is_empty());
    }
}

#[test]
fn lever_arm_matches_the_specific_force_at_the_point() {
    let r_i = Vec3::new(0.031, -0.012, 0.047);
    let s = signals(0.7);
    let values: Vec<f64> = (0..9).map(|k| r_i[k % 3] * 1e3).collect();
    let got = effect("lever_arm").unwrap().forward(&values, &s).accel;
    let snap = moving(0.7).snapshot(&geo(), &SITE);
    let want = snap.f_b(&(geo().c_pb * r_i)) - snap.f_b(&Vec3::zeros());
    assert!((got - want).norm() < 1e-12, "{got} vs {want}");
}

#[test]
fn time_offset_regressor_is_the_reference_derivative() {
    let (t, h) = (0.7, 1e-5);
    let d = |t: f64| {
        let s = signals(t);
        (s.f_b, s.w_ib_dps())
    };
    let (fp, wp) = d(t + h);
    let (fm, wm) = d(t - h);
    let mut out = [Partials::default()];
    effect("time_offset")
        .unwrap()
        .regressors(&signals(t), &mut out);
    // d y / d tau_ms = -1e-3 dy/dt
    let fa = -(fp - fm) / (2.0 * h) * 1e-3;
    let fg = -(wp - wm) / (2.0 * h) * 1e-3;
    assert!(
        (out[0].accel - fa).norm() < 1e-8,
        "{} vs {fa}",
        out[0].accel
    );
    assert!((out[0].gyro - fg).norm() < 1e-8, "{} vs {fg}", out[0].gyro);
}

#[test]
fn earth_rate_is_fifteen_degrees_an_hour_and_gives_back_its_latitude() {
    let [n, u] = EarthRate::values(40.0);
    assert!(((n * n + u * u).sqrt() - 15.041).abs() < 1e-3);
    let (lat, ulat) = EarthRate::latitude_deg(n, u, [[0.01, 0.0], [0.0, 0.01]]);
    assert!((lat - 40.0).abs() < 1e-9);
    // 0.1 deg/h on a 15 deg/h vector: about 0.38 deg.
    let r = (n * n + u * u).sqrt();
    assert!((ulat - 0.1 / r / DEG).abs() < 1e-9);
    let s = signals(0.3);
    let g = effect("earth_rate").unwrap().forward(&[n, u], &s).gyro;
    assert!((g - s.earth_b / DEG).norm() < 1e-12);
}

#[test]
fn errors_give_the_spec_model_to_first_order() {
    let mut e = ImuErrors {
        b_a: Vec3::new(0.01, -0.02, 0.03),
        b_g: Vec3::new(0.001, 0.002, -0.003),
        g_sens: Mat3::from_fn(|i, j| 1e-4 * (i as f64 + 2.0 * j as f64)),
        gyro_thermal: Vec3::new(1e-4, 0.0, -2e-4),
        gyro_nonlinearity: Vec3::new(3.0, -2.0, 1.0),
        ..Default::default()
    };
    e.k_a = Mat3::identity() + Mat3::from_fn(|i, j| 1e-4 * (1.0 + i as f64 - j as f64));
    e.k_g = Mat3::identity() + Mat3::from_fn(|i, j| 2e-4 * (1.0 + j as f64 - i as f64));
    let state = moving(0.7);
    let snap = state.snapshot(&geo(), &SITE);
    let (a, g) = e.measure(&state, &geo(), &SITE, 25.0);
    // physics.md: a = K_a s + b_a; w = K_g w_ib + b_g + G f_B(0) (+ thermal, nonlinearity).
    let f0 = snap.f_b(&Vec3::zeros());
    let w = snap.w_ib() / DEG;
    let want_a = e.k_a * f0 + e.b_a;
    let nl = Vec3::from_fn(|i, _| e.gyro_nonlinearity[i] * 1e-6 * w[i] * w[i].abs());
    let want_g = e.k_g * w + e.b_g + e.g_sens * f0 + e.gyro_thermal * 5.0 + nl;
    assert!((a - want_a).norm() < 1e-12, "{a} vs {want_a}");
    assert!((g - want_g).norm() < 1e-12, "{g} vs {want_g}");
}

#[test]
fn regressors_are_the_derivatives_of_forward() {
    let s = signals(1.1);
    for e in REGISTRY {
        let n = e.params().len();
        let mut parts = vec![Partials::default(); n];
        e.regressors(&s, &mut parts);
        if e.id() == "time_offset" {
            continue; // applied by delaying the motion: tested above
        }
        for k in 0..n {
            let mut v = vec![0.0; n];
            v[k] = 1.0;
            let f = e.forward(&v, &s);
            assert!((f.accel - parts[k].accel).norm() < 1e-12, "{} {k}", e.id());
            assert!((f.gyro - parts[k].gyro).norm() < 1e-12, "{} {k}", e.id());
        }
    }
}
