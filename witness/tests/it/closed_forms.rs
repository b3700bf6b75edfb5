//! The witness's closed forms against values derived by hand from physics.md: gravity and
//! the Earth's rate at rest, the rate about the right body axis with the right sign, the
//! lever arm, the clock-rate re-timing, the hidden forms; and the timeline's angle, rate and
//! acceleration agree with each other.

use ratecal_witness::{Axis, Hidden, Imu, OMEGA_E, Plan, Scenario, SegmentSpec, Timeline};

const G: f64 = 9.8016;

fn ideal() -> Scenario {
    let mut s = Scenario::standard("ideal", 1).quiet();
    s.imu = Imu::ideal();
    s
}

fn segment<'a>(tl: &'a Timeline, id: &str) -> &'a SegmentSpec {
    tl.segments.iter().find(|s| s.id == id).unwrap()
}

fn mid(seg: &SegmentSpec) -> f64 {
    0.5 * (seg.t_start + seg.t_end)
}

fn close(a: [f64; 3], b: [f64; 3], tol: f64) {
    for i in 0..3 {
        assert!((a[i] - b[i]).abs() <= tol, "{a:?} vs {b:?} (tol {tol})");
    }
}

fn earth_dps(lat_deg: f64) -> (f64, f64) {
    let (s, c) = lat_deg.to_radians().sin_cos();
    ((OMEGA_E * c).to_degrees(), (OMEGA_E * s).to_degrees())
}

/// A Z-up IMU at rest reads `K_a [0, 0, g] + b_a` and the Earth's rate
/// `Omega_E [0, cos lat, sin lat]` through `K_g`, plus `b_g`.
#[test]
fn z_up_at_rest_reads_gravity_and_the_earth_rate() {
    let s = Scenario::standard("z-up", 1).quiet();
    let tl = s.timeline();
    let inst = s.instant(&tl, mid(segment(&tl, "accel_static/1")));
    close(inst.f_b, [0.0, 0.0, G], 1e-12);
    let (north, up) = earth_dps(40.0);
    close(inst.w_ib_dps, [0.0, north, up], 1e-15);
    let (a, w) = s.outputs(&inst);
    let imu = Imu::tactical();
    close(
        a,
        [
            imu.accel_bias_mps2[0],
            imu.accel_bias_mps2[1],
            (1.0 + 410e-6) * G + imu.accel_bias_mps2[2],
        ],
        1e-12,
    );
    close(
        w,
        [
            imu.gyro_bias_dps[0],
            (1.0 + 700e-6) * north + imu.gyro_bias_dps[1],
            (1.0 + 1100e-6) * up + imu.gyro_bias_dps[2],
        ],
        1e-15,
    );
}

/// The six attitudes read `g [sin th, cos th sin phi, cos th cos phi]` (pitch th, roll phi);
/// X up (pitch 90) turns body Z to the West and keeps Y North: the Earth's rate reads
/// `[Omega sin lat, Omega cos lat, 0]`.
#[test]
fn the_six_attitudes_follow_the_seed_formula() {
    let s = ideal();
    let tl = s.timeline();
    for n in 1..=6 {
        let seg = segment(&tl, &format!("accel_static/{n}"));
        let (th, phi) = seg.attitude_deg.unwrap();
        let (th, phi) = (th.to_radians(), phi.to_radians());
        let want = [th.sin(), th.cos() * phi.sin(), th.cos() * phi.cos()].map(|v| v * G);
        close(s.instant(&tl, mid(seg)).f_b, want, 1e-12);
    }
    let (north, up) = earth_dps(40.0);
    let x_up = s.instant(&tl, mid(segment(&tl, "accel_static/3")));
    close(x_up.w_ib_dps, [up, north, 0.0], 1e-15);
}

/// A table heading `h` (azimuth of its nominal North) turns the Earth's horizontal part:
/// at 90 deg the table's +x points South, so a Z-up X gyro reads `-Omega cos lat`.
#[test]
fn a_table_heading_turns_the_earth_rate() {
    let mut s = ideal();
    s.station.heading_deg = 90.0;
    let tl = s.timeline();
    let inst = s.instant(&tl, mid(segment(&tl, "accel_static/1")));
    let (north, up) = earth_dps(40.0);
    close(inst.w_ib_dps, [-north, 0.0, up], 1e-15);
}

/// Rotation about the outer axis (`a_o = -Y`) reads `-rate` on the Y gyro; about the inner
/// axis (`a_i = X`, outer at zero) `+rate` on the X gyro; the scale applies to it.
#[test]
fn rate_segments_read_the_rate_about_the_right_axis_with_the_right_sign() {
    let mut s = ideal();
    s.imu.gyro_scale_ppm = [1000.0, -2000.0, 0.0];
    let tl = s.timeline();
    for (id, axis, sign) in [
        ("gyro_scale/outer/+50", 1, -1.0),
        ("gyro_scale/outer/-100", 1, -1.0),
        ("gyro_scale/inner/+100", 0, 1.0),
        ("gyro_scale/inner/-50", 0, 1.0),
    ] {
        let seg = segment(&tl, id);
        let rate = seg.rate.unwrap().1;
        for t in [seg.t_start, mid(seg), seg.t_end] {
            let inst = s.instant(&tl, t);
            let earth = ideal_earth(&inst);
            let mut want = earth;
            want[axis] += sign * rate;
            close(inst.w_ib_dps, want, 1e-12);
            let (_, w) = s.outputs(&inst);
            let k = 1.0 + s.imu.gyro_scale_ppm[axis] * 1e-6;
            assert!((w[axis] - k * want[axis]).abs() < 1e-12, "{id}: {w:?}");
        }
    }
    // Positive pitch rate tilts +X up: f_x grows through zero at pitch zero.
    let seg = segment(&tl, "gyro_scale/outer/+50");
    let t = mid(seg);
    let pitch = tl.state(t)[0][0].to_radians();
    let f = s.instant(&tl, t).f_b;
    close(f, [G * pitch.sin(), 0.0, G * pitch.cos()], 1e-12);
    assert_eq!(seg.rate.unwrap().0, Axis::Outer);
}

/// The Earth's rate projected on the body axes, `C_LB^T Omega_L`, in deg/s.
fn ideal_earth(inst: &ratecal_witness::Instant) -> [f64; 3] {
    let (north, up) = earth_dps(40.0);
    let c = inst.c_lb;
    std::array::from_fn(|j| c[1][j] * north + c[2][j] * up)
}

/// Angle, rate and acceleration of the timeline are derivatives of each other, and the
/// body rate and its derivative agree with `C_LB`'s change.
#[test]
fn the_timeline_and_the_kinematics_are_consistent() {
    let s = ideal();
    let tl = s.timeline();
    let h = 1e-4;
    let mut t = 0.0;
    while t < tl.duration_s {
        let [o, i] = tl.state(t);
        let [o1, i1] = tl.state(t + h);
        let [o0, i0] = tl.state(t - h);
        for (x, x1, x0) in [(o, o1, o0), (i, i1, i0)] {
            assert!(
                ((x1[0] - x0[0]) / (2.0 * h) - x[1]).abs() < 1e-4,
                "rate at {t}"
            );
            assert!(
                ((x1[1] - x0[1]) / (2.0 * h) - x[2]).abs() < 1e-3,
                "accel at {t}"
            );
        }
        let (a, a1, a0) = (
            s.instant(&tl, t),
            s.instant(&tl, t + h),
            s.instant(&tl, t - h),
        );
        for j in 0..3 {
            let dw = (a1.w_b_rps[j] - a0.w_b_rps[j]) / (2.0 * h);
            assert!((dw - a.dw_b_rps2[j]).abs() < 1e-5, "dw_b at {t}");
        }
        // [w_b]x = C_LB^T dC_LB/dt: w_b.x = (C^T C')[2][1], etc.
        let d = |r: usize, c: usize| -> f64 {
            (0..3)
                .map(|k| a.c_lb[k][r] * (a1.c_lb[k][c] - a0.c_lb[k][c]) / (2.0 * h))
                .sum()
        };
        let w = [d(2, 1), d(0, 2), d(1, 0)];
        close(w, a.w_b_rps, 1e-5);
        t += 0.37;
    }
}

/// At a constant outer rate `w` (about body -Y at roll 0), an accelerometer at `R` sees the
/// centripetal `w x (w x R)`: `-w^2` times R's part across the axis.
#[test]
fn the_lever_arm_adds_the_centripetal_acceleration() {
    let r_mm = [[30.0, 5.0, 0.0], [0.0, 40.0, 0.0], [0.0, 7.0, 50.0]];
    let mut s = ideal().with(Hidden::LeverArm { r_mm });
    s.plan = Plan::new()
        .spin("spin", Axis::Outer, 100.0, 10.0)
        .stop(Axis::Outer);
    let tl = s.timeline();
    let inst = s.instant(&tl, mid(segment(&tl, "spin")));
    let (a, _) = s.outputs(&inst);
    let w2 = 100f64.to_radians().powi(2);
    close(
        a,
        [
            inst.f_b[0] - w2 * 0.030,
            inst.f_b[1],
            inst.f_b[2] - w2 * 0.050,
        ],
        1e-12,
    );
}

/// A sample stamped `t` under a clock `ppm` fast measured the motion at `t / (1 + ppm 1e-6)`;
/// with a time offset as well, at `t / (1 + eps) - tau`.
#[test]
fn a_fast_imu_clock_re_times_the_motion_exactly() {
    let base = ideal();
    let tl = base.timeline();
    let fast = ideal()
        .with(Hidden::ClockRate { ppm: 100.0 })
        .with(Hidden::TimeOffset { tau_ms: 5.0 });
    let seg = segment(&tl, "gyro_scale/inner/+100");
    let t_stamp = seg.t_end;
    let t_table = t_stamp / (1.0 + 100e-6) - 0.005;
    assert_eq!(fast.table_time(t_stamp), t_table);
    let a = fast.instant(&tl, t_stamp);
    let b = base.instant(&tl, t_table);
    assert_eq!((a.t, a.t_stamp), (t_table, t_stamp));
    assert_eq!(a.f_b, b.f_b);
    // 100 deg/s over the re-timing (74 ms + 5 ms here) is a visible angle.
    let lag_deg = (t_stamp - t_table) * 100.0;
    assert!(lag_deg > 7.0, "{lag_deg}");
    let moved = tl.state(t_stamp)[1][0] - a.angles_deg[1];
    assert!((moved - lag_deg).abs() < 1e-9, "{moved} vs {lag_deg}");
}

/// Each hidden form, evaluated by hand at one instant.
#[test]
fn the_hidden_forms() {
    let s = ideal();
    let tl = s.timeline();
    let x_up = s.instant(&tl, mid(segment(&tl, "accel_static/3")));
    // An instant of the inner spin where gravity has parts on both Y and Z.
    let seg = segment(&tl, "gyro_scale/inner/-100");
    let rate = (0..100)
        .map(|k| s.instant(&tl, seg.t_start + 0.1 * f64::from(k)))
        .find(|i| i.f_b[1].abs() > 3.0 && i.f_b[2].abs() > 3.0)
        .unwrap();
    let f = rate.f_b;
    let cases: Vec<(Hidden, &ratecal_witness::Instant, [f64; 3], [f64; 3])> = vec![
        (
            Hidden::AccelSecondOrder {
                k2_ug_per_g2: [100.0, 0.0, 0.0],
            },
            &x_up,
            [100e-6 * G, 0.0, 0.0],
            [0.0; 3],
        ),
        (
            Hidden::AccelCrossCoupling {
                ug_per_g2: [200.0, 0.0, 0.0],
            },
            &rate,
            [200e-6 * f[1] * f[2] / G, 0.0, 0.0],
            [0.0; 3],
        ),
        (
            Hidden::GyroG2 {
                dps_per_g2: [0.006, -0.004, 0.005],
            },
            &x_up,
            [0.0; 3],
            [0.006, 0.0, 0.0],
        ),
        (
            Hidden::GyroScaleAsymmetry {
                ppm: [300.0, 0.0, 0.0],
            },
            &rate,
            [0.0; 3],
            [300e-6 * rate.w_ib_dps[0].abs(), 0.0, 0.0],
        ),
        (
            Hidden::AccelScaleAsymmetry {
                ppm: [500.0, 0.0, 0.0],
            },
            &x_up,
            [500e-6 * G, 0.0, 0.0],
            [0.0; 3],
        ),
        (
            Hidden::GyroWarmUp {
                amplitude_dps: [0.02, 0.0, 0.0],
                tau_s: 100.0,
            },
            &x_up,
            [0.0; 3],
            [0.02 * (-x_up.t / 100.0).exp(), 0.0, 0.0],
        ),
        (
            Hidden::GSensitivity {
                dps_per_g: [[0.01, 0.0, 0.0], [0.0; 3], [0.02, 0.0, 0.0]],
            },
            &x_up,
            [0.0; 3],
            [0.01, 0.0, 0.02],
        ),
        (
            Hidden::AccelBiasStep {
                at_s: rate.t,
                step_mps2: [0.004, -0.003, 0.0],
            },
            &rate,
            [0.004, -0.003, 0.0],
            [0.0; 3],
        ),
        (
            Hidden::custom("temp_bias", serde_json::json!({}), |i| {
                ([0.0; 3], [0.001 * i.temp_c, 0.0, 0.0])
            }),
            &x_up,
            [0.0; 3],
            [0.001 * x_up.temp_c, 0.0, 0.0],
        ),
    ];
    for (h, inst, da, dw) in cases {
        let id = h.id().to_string();
        let (a0, w0) = s.outputs(inst);
        let mut with = ideal();
        with.hidden.push(h);
        let (a1, w1) = with.outputs(inst);
        let got_a = std::array::from_fn(|i| a1[i] - a0[i]);
        let got_w = std::array::from_fn(|i| w1[i] - w0[i]);
        println!("{id}: {got_a:?} {got_w:?}");
        close(got_a, da, 1e-12);
        close(got_w, dw, 1e-12);
    }
}

/// One arc second, rad.
const ARCSEC: f64 = std::f64::consts::PI / 648_000.0;

/// docs/effects.md's encoder: the inner encoder reads `theta + e sin(theta + phi)` and the
/// table servoes on it, so at the plan's roll 90 deg the true roll is `90 deg - e cos(phi)`
/// to first order (`sin(90 deg + phi) = cos(phi)`): gravity reads
/// `g [0, cos(e cos phi), sin(e cos phi)]`; at roll 0 the true roll is `-e sin(phi)`. The
/// second order (`e^2`, 4e-8 rad here) bounds the difference.
#[test]
fn an_eccentric_encoder_turns_the_imu_by_the_true_angle() {
    let (e, phi) = (40.0, 30f64);
    let s = ideal().with(Hidden::TableEncoderEccentricity {
        e_arcsec: [0.0, e],
        phi_deg: [0.0, phi],
    });
    let tl = s.timeline();
    let d = e * ARCSEC * phi.to_radians().cos();
    let at_90 = s.instant(&tl, mid(segment(&tl, "accel_static/5")));
    let second = G * (e * ARCSEC).powi(2);
    close(at_90.f_b, [0.0, G * d.cos(), G * d.sin()], second);
    let d0 = e * ARCSEC * phi.to_radians().sin();
    let at_0 = s.instant(&tl, mid(segment(&tl, "accel_static/1")));
    close(at_0.f_b, [0.0, -G * d0.sin(), G * d0.cos()], second);
    // The encoder reads the plan (roll 90 deg modulo turns): theta + e sin(theta + phi).
    let th = at_90.angles_deg[1].to_radians();
    let enc = th + e * ARCSEC * (th + phi.to_radians()).sin();
    let plan = tl.state(at_90.t)[1][0];
    assert!(
        (enc - plan.to_radians()).abs() < 1e-14,
        "{enc} vs {plan} deg"
    );
    assert_eq!(plan.rem_euclid(360.0), 90.0);
    // The outer axis is exact.
    assert_eq!(at_90.angles_deg[0], tl.state(at_90.t)[0][0]);
}

/// In a rate segment the encoder's rate is the commanded one: the true rate `r` satisfies
/// `r (1 + e cos(theta + phi)) = 100 deg/s` (docs/effects.md's rate feedback), and the X gyro
/// reads it; the angle, rate and acceleration stay derivatives of each other.
#[test]
fn an_eccentric_encoder_makes_the_true_rate_ripple() {
    let (e, phi) = (80.0, -45f64);
    let s = ideal().with(Hidden::TableEncoderEccentricity {
        e_arcsec: [0.0, e],
        phi_deg: [0.0, phi],
    });
    let tl = s.timeline();
    let seg = segment(&tl, "gyro_scale/inner/+100");
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for k in 0..200 {
        let t = seg.t_start + 0.05 * f64::from(k);
        let inst = s.instant(&tl, t);
        let th = inst.angles_deg[1].to_radians() + phi.to_radians();
        let r = inst.rates_dps[1];
        assert!(
            (r * (1.0 + e * ARCSEC * th.cos()) - 100.0).abs() < 1e-10,
            "{r}"
        );
        let earth = ideal_earth(&inst);
        assert!((inst.w_ib_dps[0] - earth[0] - r).abs() < 1e-10);
        lo = lo.min(r);
        hi = hi.max(r);
        let h = 1e-4;
        let (a1, a0) = (s.instant(&tl, t + h), s.instant(&tl, t - h));
        let rate = (a1.angles_deg[1] - a0.angles_deg[1]) / (2.0 * h);
        assert!((rate - r).abs() < 1e-6, "rate {rate} vs {r}");
        let accel = (a1.rates_dps[1] - a0.rates_dps[1]) / (2.0 * h);
        let dw = (a1.w_b_rps[0] - a0.w_b_rps[0]) / (2.0 * h);
        assert!((dw - inst.dw_b_rps2[0]).abs() < 1e-6, "dw {dw} at {t}");
        assert!((accel.to_radians() - inst.dw_b_rps2[0]).abs() < 1e-6);
    }
    // The ripple: 100 deg/s times e, both ways.
    let ripple = 100.0 * e * ARCSEC;
    assert!((hi - 100.0 - ripple).abs() < 0.01 * ripple, "{hi}");
    assert!((100.0 - lo - ripple).abs() < 0.01 * ripple, "{lo}");
}

/// truth.json gives the registry's components: `sin = e cos(phi)`, `cos = e sin(phi)`.
#[test]
fn the_eccentricity_truth_holds_the_registry_components() {
    let h = Hidden::TableEncoderEccentricity {
        e_arcsec: [50.0, 40.0],
        phi_deg: [-60.0, 30.0],
    };
    let t = h.truth();
    assert_eq!(t.id, "table_encoder_eccentricity");
    assert!(t.registry);
    let p = |k: &str| t.parameters[k].as_f64().unwrap();
    assert!((p("outer_sin_arcsec") - 25.0).abs() < 1e-12);
    assert!((p("outer_cos_arcsec") + 25.0 * 3f64.sqrt()).abs() < 1e-12);
    assert!((p("inner_sin_arcsec") - 20.0 * 3f64.sqrt()).abs() < 1e-12);
    assert!((p("inner_cos_arcsec") - 20.0).abs() < 1e-12);
}

/// The outer bearing's wobble tilts the gimbal about `u = a_o x up = -East` by
/// `delta = w sin(2 th_o + phi)`. At rest Z up (`th_o = 0`, phi 90: `delta = w`) gravity
/// reads `R(-x, delta)^T [0, 0, g] = g [0, -sin(delta), cos(delta)]`; at pitch 90 (X up,
/// `delta = -w`) it reads `g [cos(w), sin(w), 0]`.
#[test]
fn the_wobble_tilts_gravity_by_hand() {
    let w = 60.0;
    let s = ideal().with(Hidden::TableWobble {
        w_arcsec: w,
        phi_deg: 90.0,
    });
    let tl = s.timeline();
    let d = w * ARCSEC;
    let z_up = s.instant(&tl, mid(segment(&tl, "accel_static/1")));
    close(z_up.f_b, [0.0, -G * d.sin(), G * d.cos()], 1e-12);
    let x_up = s.instant(&tl, mid(segment(&tl, "accel_static/3")));
    close(x_up.f_b, [G * d.cos(), G * d.sin(), 0.0], 1e-12);
    // The encoders are exact: the angles are the plan's.
    assert_eq!(x_up.angles_deg, tl.state(x_up.t).map(|a| a[0]));
}

/// Under the wobble the body rate and its derivative still agree with `C_LB`'s change, and
/// an outer spin at 100 deg/s adds `2 w 100 deg/s` at most to the rate.
#[test]
fn the_wobble_kinematics_are_consistent() {
    let w = 60.0;
    let s = ideal().with(Hidden::TableWobble {
        w_arcsec: w,
        phi_deg: 20.0,
    });
    let base = ideal();
    let tl = s.timeline();
    let seg = segment(&tl, "gyro_scale/outer/+100");
    let h = 1e-4;
    let mut most: f64 = 0.0;
    for k in 0..100 {
        let t = seg.t_start + 0.1 * f64::from(k);
        let (a, a1, a0) = (
            s.instant(&tl, t),
            s.instant(&tl, t + h),
            s.instant(&tl, t - h),
        );
        let d = |r: usize, c: usize| -> f64 {
            (0..3)
                .map(|k| a.c_lb[k][r] * (a1.c_lb[k][c] - a0.c_lb[k][c]) / (2.0 * h))
                .sum()
        };
        close([d(2, 1), d(0, 2), d(1, 0)], a.w_b_rps, 1e-7);
        for j in 0..3 {
            let dw = (a1.w_b_rps[j] - a0.w_b_rps[j]) / (2.0 * h);
            assert!((dw - a.dw_b_rps2[j]).abs() < 1e-6, "dw_b at {t}");
        }
        let plain = base.instant(&tl, t);
        let extra: f64 = (0..3)
            .map(|j| (a.w_b_rps[j] - plain.w_b_rps[j]).powi(2))
            .sum::<f64>()
            .sqrt();
        most = most.max(extra);
    }
    let peak = 2.0 * w * ARCSEC * 100f64.to_radians();
    assert!(
        most <= peak * (1.0 + 1e-9) && most > 0.9 * peak,
        "{most} vs {peak}"
    );
}
