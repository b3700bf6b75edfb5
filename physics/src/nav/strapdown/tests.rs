use super::*;
use crate::nav::sway_coefficient;
use crate::{AxisMotion, DEG, Geometry, ImuErrors, TableState};
use std::f64::consts::PI;

const SITE: Site = Site {
    latitude_deg: 55.7,
    gravity_mps2: 9.8156,
};

fn sine(th0: f64, a: f64, w: f64, t: f64) -> AxisMotion {
    AxisMotion {
        angle: th0 + a * (w * t).sin(),
        rate: a * w * (w * t).cos(),
        accel: -a * w * w * (w * t).sin(),
    }
}

/// Ideal samples of a table motion at `hz`, sensing points `lever` (rows, body axes, m).
fn samples(
    geo: &Geometry,
    lever: &Mat3,
    hz: f64,
    dur: f64,
    motion: impl Fn(f64) -> TableState,
) -> (Vec<f64>, Vec<Vec3>, Vec<Vec3>) {
    let n = (dur * hz).round() as usize + 1;
    let (mut t, mut w, mut f) = (Vec::new(), Vec::new(), Vec::new());
    for k in 0..n {
        let tk = k as f64 / hz;
        // An error-free IMU with these sensing points: what ideal sensors read.
        let imu = ImuErrors {
            lever_m: *lever,
            ..Default::default()
        };
        let (s, w_dps) = imu.measure(&motion(tk), geo, &SITE, imu.t_ref_c);
        t.push(tk);
        w.push(w_dps * DEG);
        f.push(s);
    }
    (t, w, f)
}

#[test]
fn two_axis_motion_keeps_attitude_and_a_centred_point_at_rest() {
    // Both axes swaying at unrelated frequencies: the rotations do not commute, so the
    // coning term matters; the table centre does not move, so the velocity stays zero.
    let geo = Geometry::seed();
    let motion = |t: f64| TableState {
        outer: sine(0.2, 0.5, 1.3, t),
        inner: sine(-0.1, 0.8, 2.1, t),
    };
    let (t, w, f) = samples(&geo, &Mat3::zeros(), 100.0, 60.0, motion);
    let s0 = motion(0.0);
    let c0 = geo.c_lb(s0.outer.angle, s0.inner.angle);
    let tr = navigate(&t, &w, &f, &c0, &SITE, true);
    let s1 = motion(60.0);
    let c1 = geo.c_lb(s1.outer.angle, s1.inner.angle);
    let err = (tr.c_lb.last().unwrap().transpose() * c1 - Mat3::identity()).norm();
    // Rates are samples, not increments: the trapezoid leaves dt^2/12 (w'(T) - w'(0)),
    // about 3e-5 rad here, bounded (it telescopes instead of drifting).
    assert!(err < 5e-5, "attitude error {err}");
    let v = tr.v_l.last().unwrap().norm();
    // Two non-commuting sways at up to 1.7 rad/s sampled at 100 Hz leave a mean tilt of a
    // few microradians (the two-sample coning term is exact only for linear rates).
    assert!(v < 3e-3, "velocity {v} m/s after 60 s");
}

#[test]
fn swaying_z_up_drifts_at_the_closed_form_rate() {
    // physics.md: Z up, body X = East at th = 0:
    // <da_E> = (-sin th0 r_xy + cos th0 r_yx) / c, <da_N> = (cos th0 r_xy + sin th0 r_yx) / c.
    // The IMU centre p is off the table axis: that point really moves, no drift from it.
    let geo = Geometry::vertical_outer();
    let p = Vec3::new(0.03, -0.02, 0.01);
    let (r_xy, r_yx) = (0.003, -0.002);
    let lever = Mat3::from_rows(&[
        (p + Vec3::new(0.0, r_xy, 0.0)).transpose(),
        (p + Vec3::new(r_yx, 0.0, 0.0)).transpose(),
        p.transpose(),
    ]);
    for (th0_deg, period) in [(30.0, 5.0), (-120.0, 10.0)] {
        let th0: f64 = th0_deg * DEG;
        let (a, w) = (PI / 2.0, 2.0 * PI / period);
        let periods = 8.0;
        // Starting at a turning point, at rest: an initial velocity error would turn into a
        // drift through the Coriolis term.
        let motion = |t: f64| TableState {
            outer: sine(th0, a, w, t + period / 4.0),
            inner: AxisMotion::default(),
        };
        let (t, wv, f) = samples(&geo, &lever, 100.0, periods * period, motion);
        let c0 = geo.c_lb(motion(0.0).outer.angle, 0.0);
        let tr = navigate(&t, &wv, &f, &c0, &SITE, false);
        let span = periods * period;
        let got = (tr.v_l.last().unwrap() - tr.v_l[0]) / span;
        let c = sway_coefficient(a, period);
        let want_e = (-th0.sin() * r_xy + th0.cos() * r_yx) / c;
        let want_n = (th0.cos() * r_xy + th0.sin() * r_yx) / c;
        // 1e-5 m/s^2 is 7 um of coordinate at T = 5 s.
        assert!((got.x - want_e).abs() < 1e-5, "E {} vs {want_e}", got.x);
        assert!((got.y - want_n).abs() < 1e-5, "N {} vs {want_n}", got.y);
    }
}

#[test]
fn at_rest_nothing_moves() {
    let geo = Geometry::vertical_outer();
    let (t, w, f) = samples(&geo, &Mat3::zeros(), 10.0, 600.0, |_| {
        TableState::at_rest_deg(20.0, 3.0)
    });
    let c0 = geo.c_lb(20.0 * DEG, 3.0 * DEG);
    let tr = navigate(&t, &w, &f, &c0, &SITE, true);
    assert!(tr.v_l.last().unwrap().norm() < 1e-7);
}
