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

/// The ideal outputs of a table state: `f_B(0)` (m/s^2) and `w_ib` (deg/s).
fn ideal(state: &TableState) -> (Vec3, Vec3) {
    let snap = state.snapshot(&geo(), &SITE);
    (snap.f_b(&Vec3::zeros()), snap.w_ib() / DEG)
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
            "gyro_scale_nonlinearity",
            "accel_second_order",
            "accel_scale_asymmetry",
            "gyro_scale_asymmetry",
            "accel_scale_thermal",
            "gyro_scale_thermal",
            "clock_rate",
            "table_encoder_eccentricity"
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
        if ["time_offset", "clock_rate", "table_encoder_eccentricity"].contains(&e.id()) {
            continue; // applied to the motion, not the outputs: tested above
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

#[test]
fn second_order_is_k2_ug_per_g_squared() {
    let mut s = signals(0.4);
    s.f_b = Vec3::new(s.g, -0.5 * s.g, 0.0);
    let out = effect("accel_second_order")
        .unwrap()
        .forward(&[150.0, 40.0, 7.0], &s)
        .accel;
    // One g along X: 150 ug; half a g along Y: 40 / 4 ug.
    let want = Vec3::new(150e-6, 10e-6, 0.0) * s.g;
    assert!((out - want).norm() < 1e-15, "{out} vs {want}");
}

#[test]
fn asymmetry_changes_the_scale_with_the_sign_of_the_input() {
    for (id, sensor) in [
        ("accel_scale_asymmetry", Sensor::Accel),
        ("gyro_scale_asymmetry", Sensor::Gyro),
    ] {
        let e = effect(id).unwrap();
        let mut s = signals(0.2);
        s.earth_b = Vec3::zeros();
        for sign in [1.0, -1.0] {
            s.f_b = Vec3::new(2.0, 0.0, 0.0) * sign;
            s.w_b = Vec3::new(2.0, 0.0, 0.0) * sign * DEG;
            let out = *e.forward(&[300.0, 0.0, 0.0], &s).of(sensor);
            // The output at +x and -x: scale 1 + 300 ppm at +2, 1 - 300 ppm at -2 (the
            // output moves by +600 ppm of 2 either way).
            assert!((out.x - 600e-6).abs() < 1e-15, "{id} {sign}: {out}");
            let scale = (2.0 * sign + out.x) / (2.0 * sign) - 1.0;
            assert!((scale - sign * 300e-6).abs() < 1e-15);
        }
    }
}

#[test]
fn scale_thermal_scales_the_input_by_the_temperature() {
    let mut s = signals(0.9);
    s.dtemp_c = 5.0;
    let a = effect("accel_scale_thermal")
        .unwrap()
        .forward(&[100.0, -50.0, 20.0], &s)
        .accel;
    let g = effect("gyro_scale_thermal")
        .unwrap()
        .forward(&[100.0, -50.0, 20.0], &s)
        .gyro;
    let k = Vec3::new(100.0, -50.0, 20.0) * 5.0 * 1e-6;
    assert!((a - k.component_mul(&s.f_b)).norm() < 1e-15);
    assert!((g - k.component_mul(&s.w_ib_dps())).norm() < 1e-15);
    assert!(effect("accel_scale_thermal").unwrap().uses_temperature());
    assert!(effect("gyro_scale_thermal").unwrap().uses_temperature());
}

#[test]
fn clock_rate_regressor_is_the_derivative_of_re_timing() {
    let e = effect("clock_rate").unwrap();
    // Stamped 2.5 s: the first-order lag is t eps, the exact one t eps / (1 + eps).
    let t = 2.5;
    let y = |ppm: f64| ideal(&moving(super::clock_rate::ClockRate::table_time_s(ppm, t)));
    let h = 1.0;
    let ((fp, wp), (fm, wm)) = (y(h), y(-h));
    let mut out = [Partials::default()];
    e.regressors(&signals(t).at(t), &mut out);
    let (fa, fg) = ((fp - fm) / (2.0 * h), (wp - wm) / (2.0 * h));
    assert!(
        (out[0].accel - fa).norm() < 1e-9,
        "{} vs {fa}",
        out[0].accel
    );
    assert!((out[0].gyro - fg).norm() < 1e-9, "{} vs {fg}", out[0].gyro);
    // The simulator's delay: exact re-timing, composed with the time offset.
    let mut m = ImuModel::default();
    m.push("clock_rate", vec![60.0]);
    m.push("time_offset", vec![2.0]);
    let t = 1800.0;
    let te = t - m.delay_at_s(t);
    assert!((te - (t / (1.0 + 60e-6) - 2e-3)).abs() < 1e-9, "{te}");
    assert!(
        (t - te - 0.110).abs() < 1e-3,
        "60 ppm is about 0.1 s after half an hour"
    );
}

#[test]
fn encoder_true_motion_reads_back_as_the_encoder() {
    let err = EncoderError::from_values(&[40.0, -25.0, 15.0, 60.0]);
    let enc = |t: f64| moving(t);
    let truth = |t: f64| err.true_motion(&enc(t));
    let (t, h) = (0.8, 1e-4);
    let arcsec = DEG / 3600.0;
    for (k, (tr, en)) in [
        (truth(t).outer, enc(t).outer),
        (truth(t).inner, enc(t).inner),
    ]
    .into_iter()
    .enumerate()
    {
        let [s, c] = if k == 0 { err.outer } else { err.inner };
        let back = tr.angle + s * tr.angle.sin() + c * tr.angle.cos();
        assert!((back - en.angle).abs() < 1e-15, "axis {k}");
        // Tens of arc seconds apart.
        assert!((tr.angle - en.angle).abs() > 5.0 * arcsec);
    }
    // The true rate and acceleration are the derivatives of the true angle.
    let d = |f: &dyn Fn(&TableState) -> f64| (f(&truth(t + h)) - f(&truth(t - h))) / (2.0 * h);
    let now = truth(t);
    assert!((d(&|s| s.outer.angle) - now.outer.rate).abs() < 1e-8);
    assert!((d(&|s| s.inner.angle) - now.inner.rate).abs() < 1e-8);
    assert!((d(&|s| s.outer.rate) - now.outer.accel).abs() < 1e-7);
    assert!((d(&|s| s.inner.rate) - now.inner.accel).abs() < 1e-7);
}

#[test]
fn eccentricity_regressors_are_the_derivatives_of_the_true_motion() {
    let e = effect("table_encoder_eccentricity").unwrap();
    assert!(e.station_side());
    for t in [0.3, 1.1, 2.9] {
        let reported = moving(t);
        let mut out = [Partials::default(); 4];
        e.regressors(&signals(t), &mut out);
        for k in 0..4 {
            let y = |v: f64| {
                let mut values = [0.0; 4];
                values[k] = v;
                ideal(&EncoderError::from_values(&values).true_motion(&reported))
            };
            let h = 1.0;
            let ((fp, wp), (fm, wm)) = (y(h), y(-h));
            let (fa, fg) = ((fp - fm) / (2.0 * h), (wp - wm) / (2.0 * h));
            assert!(fa.norm() + fg.norm() > 1e-6, "{t} {k}: excited");
            assert!(
                (out[k].accel - fa).norm() < 1e-10,
                "{t} {k}: {} vs {fa}",
                out[k].accel
            );
            assert!(
                (out[k].gyro - fg).norm() < 1e-10,
                "{t} {k}: {} vs {fg}",
                out[k].gyro
            );
        }
    }
}

#[test]
fn eccentricity_amplitude_and_phase_round_trip() {
    let (s, c) = Eccentricity::components(20.0, 30.0);
    // e sin(theta + phi) = s sin(theta) + c cos(theta) at any theta.
    for th in [0.0, 0.7, 2.0, -1.3] {
        let want = 20.0 * (th + 30.0 * DEG).sin();
        assert!((s * th.sin() + c * th.cos() - want).abs() < 1e-12);
    }
    let ((e, ue), (phi, uphi)) = Eccentricity::amplitude_phase(s, c, [[1.0, 0.0], [0.0, 1.0]]);
    assert!((e - 20.0).abs() < 1e-12 && (phi - 30.0).abs() < 1e-12);
    // Isotropic 1 arcsec: 1 arcsec on the amplitude, 1/20 rad on the phase.
    assert!((ue - 1.0).abs() < 1e-12);
    assert!((uphi - 1.0 / 20.0 / DEG).abs() < 1e-9);
}

#[test]
fn every_parameter_has_a_plausible_range() {
    for e in REGISTRY {
        for p in e.params() {
            assert!(
                p.max_abs.is_finite() && p.max_abs > 0.0,
                "{}.{}",
                e.id(),
                p.name
            );
            assert!(p.plausible(p.max_abs) && !p.plausible(-1.01 * p.max_abs));
        }
    }
    let max = |id: &str| effect(id).unwrap().params()[0].max_abs;
    assert_eq!(max("accel_misalignment"), 50.0);
    assert_eq!(max("gyro_misalignment"), 50.0);
    assert_eq!(max("g_sensitivity"), 1.0);
    assert_eq!(max("lever_arm"), 300.0);
    assert_eq!(max("time_offset"), 1000.0);
    assert!((max("earth_rate") - 15.041).abs() < 1e-3);
    let station: Vec<&str> = REGISTRY
        .iter()
        .filter(|e| e.station_side())
        .map(|e| e.id())
        .collect();
    assert_eq!(station, ["table_encoder_eccentricity"]);
}

#[test]
fn a_term_that_says_it_is_constant_at_rest_ignores_time_and_temperature() {
    // The analysis evaluates such a term once for a stretch at rest: its regressors must
    // not read the time stamp or the temperature, at rest or moving.
    let mut constant = 0;
    for e in catalogue() {
        for base in [signals(0.0), signals(0.9)] {
            let n = e.params().len();
            let (mut a, mut b) = (vec![Partials::default(); n], vec![Partials::default(); n]);
            let mut later = base.at(base.t_s + 1234.5);
            later.dtemp_c = base.dtemp_c + 17.0;
            e.regressors(&base, &mut a);
            e.regressors(&later, &mut b);
            let same = a.iter().zip(&b).all(|(x, y)| x == y);
            if !e.varies_at_rest() {
                assert!(same, "{} reads the time or the temperature", e.id());
            }
        }
        constant += usize::from(!e.varies_at_rest());
    }
    // The terms that do read them say so.
    for id in ["clock_rate", "accel_thermal_drift", "gyro_scale_thermal"] {
        assert!(effect(id).unwrap().varies_at_rest(), "{id}");
    }
    assert!(constant >= 10, "{constant}");
}
