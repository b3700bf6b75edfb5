//! Temperature compensation: bias against the IMU temperature across blocks of the static
//! data. The fit is judged against the scatter of block means, which holds the wandering
//! bias too (a slow random walk can mimic a temperature slope).

use super::lsq::Normal;
use super::prep::SegData;
use super::{AXES, Out};
use crate::results::Parameter;
use ratecal_physics::{Mat3, Vec3};

/// Smallest temperature span that determines a slope, degC.
const MIN_SPAN_C: f64 = 1.0;
/// Block length, s.
const BLOCK_S: f64 = 10.0;

/// Fits `bias(T) = b0 + k (T - T_mean)` for both sensors over blocks of the static segments,
/// using the residuals of the sensors' models. Returns false when the temperature did not
/// vary enough (or there is no temp column).
pub(crate) fn fit(
    segs: &[&SegData],
    accel: &(Mat3, Vec3),
    gyro: &(Mat3, Vec3),
    out: &mut Out,
) -> bool {
    // (temp, accel residual, gyro residual) per block
    let mut blocks: Vec<(f64, Vec3, Vec3)> = Vec::new();
    for s in segs {
        let Some(temp) = &s.temp else { return false };
        let mut i = 0;
        while i < s.t.len() {
            let t0 = s.t[i];
            let mut acc = (0.0, Vec3::zeros(), Vec3::zeros(), 0usize);
            while i < s.t.len() && s.t[i] < t0 + BLOCK_S {
                if s.keep_a[i] && s.keep_g[i] {
                    let f = Vec3::new(s.f_ref[0][i], s.f_ref[1][i], s.f_ref[2][i]);
                    let w = Vec3::new(s.w_ref[0][i], s.w_ref[1][i], s.w_ref[2][i]);
                    let a = Vec3::new(s.accel[0][i], s.accel[1][i], s.accel[2][i]);
                    let g = Vec3::new(s.gyro[0][i], s.gyro[1][i], s.gyro[2][i]);
                    acc.0 += temp[i];
                    acc.1 += a - accel.0 * f - accel.1;
                    acc.2 += g - gyro.0 * w - gyro.1;
                    acc.3 += 1;
                }
                i += 1;
            }
            if acc.3 > 10 {
                let n = acc.3 as f64;
                blocks.push((acc.0 / n, acc.1 / n, acc.2 / n));
            }
        }
    }
    let (lo, hi) = blocks
        .iter()
        .fold((f64::MAX, f64::MIN), |(l, h), b| (l.min(b.0), h.max(b.0)));
    if blocks.len() < 4 || hi - lo < MIN_SPAN_C {
        return false;
    }
    let tm = blocks.iter().map(|b| b.0).sum::<f64>() / blocks.len() as f64;
    for (sensor, unit) in [("accel", "m/s^2/degC"), ("gyro", "deg/s/degC")] {
        for ax in 0..3 {
            let mut ne = Normal::new(2);
            for b in &blocks {
                let y = if sensor == "accel" { b.1[ax] } else { b.2[ax] };
                ne.add(&[b.0 - tm, 1.0], y);
            }
            let name = format!("{sensor}.thermal_drift.{}", AXES[ax]);
            match ne.solve(&[0, 1]) {
                Some(sol) => {
                    out.params
                        .insert(name, Parameter::estimate(sol.x[0], sol.u(0, 1.0), unit));
                }
                None => out.unobservable(
                    &name,
                    "the temperature did not vary independently of the blocks' offsets",
                ),
            }
        }
    }
    true
}
