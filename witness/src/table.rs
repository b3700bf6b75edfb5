//! The table's own errors (station side), written from docs/effects.md's words: what the
//! table reports is the plan's motion; what the IMU turns by differs.
//!
//! - Encoder eccentricity: axis k's encoder reads `theta_enc = theta + e sin(theta + phi)`,
//!   `theta` the true angle. The table reports `theta_enc` and servoes on it, so the plan's
//!   (commanded, reported) motion is the encoder's and the IMU turns by the `theta` that
//!   solves that equation.
//! - Wobble (in no registry): the outer bearing tilts the whole gimbal about the lab axis
//!   `u = unit(a_o x up)` by `delta = w sin(2 th_o + phi)`; the encoders read the angles
//!   exactly.

use crate::rot::{self, V3};
use crate::station::{Instant, Station};

/// One arc second, rad.
pub const ARCSEC: f64 = std::f64::consts::PI / (180.0 * 3600.0);

/// The true (angle deg, rate deg/s, acceleration deg/s^2) of an axis whose encoder,
/// eccentric by `e_arcsec` at phase `phi_deg`, follows `enc` = (angle, rate, acceleration)
/// of the plan.
pub fn true_axis(e_arcsec: f64, phi_deg: f64, enc: [f64; 3]) -> [f64; 3] {
    if e_arcsec == 0.0 {
        return enc;
    }
    let e = e_arcsec * ARCSEC;
    let phi = phi_deg.to_radians();
    let th_enc = enc[0].to_radians();
    // Newton on F(th) = th + e sin(th + phi) - th_enc, F' = 1 + e cos(th + phi).
    let mut th = th_enc;
    for _ in 0..50 {
        let step = (th + e * (th + phi).sin() - th_enc) / (1.0 + e * (th + phi).cos());
        th -= step;
        if step.abs() <= 1e-17 * th_enc.abs().max(1.0) {
            break;
        }
    }
    // d/dt: rate_enc = rate (1 + e cos); accel_enc = accel (1 + e cos) - rate^2 e sin.
    let k = 1.0 + e * (th + phi).cos();
    let rate = enc[1].to_radians() / k;
    let accel = (enc[2].to_radians() + rate * rate * e * (th + phi).sin()) / k;
    [th, rate, accel].map(f64::to_degrees)
}

/// The lab axis the outer bearing's wobble tilts about: `a_o x up`, normalised.
fn wobble_axis(st: &Station) -> V3 {
    let u = rot::cross(st.outer_axis, [0.0, 0.0, 1.0]);
    rot::scale(u, 1.0 / rot::dot(u, u).sqrt())
}

/// The instant of a gimbal tilted by the wobble `delta = w sin(2 th_o + phi)` about the lab
/// axis `u`: `C_LB' = R(u, delta) C_LB`, so the body sees `u` turning in by `delta'`.
pub fn wobble(
    st: &Station,
    inst: &Instant,
    w_arcsec: f64,
    phi_deg: f64,
    outer: [f64; 3],
) -> Instant {
    let w = w_arcsec * ARCSEC;
    let [th, dth, ddth] = outer.map(f64::to_radians);
    let arg = 2.0 * th + phi_deg.to_radians();
    let delta = w * arg.sin();
    let d1 = 2.0 * w * dth * arg.cos();
    let d2 = 2.0 * w * ddth * arg.cos() - 4.0 * w * dth * dth * arg.sin();
    let u = wobble_axis(st);
    let c_lb = rot::mul(&rot::rodrigues(u, delta), &inst.c_lb);
    // u in body axes (of the tilted gimbal: R(u, delta) leaves u where it is).
    let u_b = rot::mul_tv(&c_lb, u);
    let w_b = rot::add(inst.w_b_rps, rot::scale(u_b, d1));
    // d/dt (d1 u_b) = d2 u_b - d1 (w_b x u_b): a lab vector turns in the body by -w_b.
    let du = rot::scale(rot::cross(w_b, u_b), -d1);
    let dw_b = rot::add(inst.dw_b_rps2, rot::add(rot::scale(u_b, d2), du));
    let f_b = rot::mul_tv(&c_lb, [0.0, 0.0, st.gravity_mps2]);
    let earth_b = rot::mul_tv(&c_lb, st.earth_rate_lab());
    Instant {
        c_lb,
        f_b,
        w_ib_dps: rot::add(w_b, earth_b).map(f64::to_degrees),
        w_b_rps: w_b,
        dw_b_rps2: dw_b,
        ..inst.clone()
    }
}
