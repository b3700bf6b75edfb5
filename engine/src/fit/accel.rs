//! Residuals of a fitted sensor model `out = K ref + b`, per segment and axis.

use super::prep::SegData;
use super::{Out, residual_stats};
use ratecal_physics::{Mat3, Vec3};

/// Which sensor a fitted model describes.
#[derive(Clone, Copy)]
pub(super) enum Sensor {
    /// Accelerometers: outputs `accel`, references `f_ref`, mask `keep_a`.
    Accel,
    /// Gyros: outputs `gyro`, references `w_ref`, mask `keep_g`.
    Gyro,
}

/// Pushes the residuals of `out = K ref + b` per segment and axis, and returns the worst
/// axis's pooled residual standard deviation with its standard uncertainty.
pub(super) fn model_residuals(
    segs: &[&SegData],
    sensor: Sensor,
    k: &Mat3,
    b: &Vec3,
    out: &mut Out,
) -> (f64, f64) {
    let mut worst = (0.0f64, 0.0f64);
    for ax in 0..3 {
        let (mut ss, mut n) = (0.0, 0usize);
        for s in segs {
            let (y, rf, keep, name, unit) = match sensor {
                Sensor::Accel => (&s.accel, &s.f_ref, &s.keep_a, "accel", "m/s^2"),
                Sensor::Gyro => (&s.gyro, &s.w_ref, &s.keep_g, "gyro", "deg/s"),
            };
            let r: Vec<f64> = (0..s.t.len())
                .map(|i| y[ax][i] - b[ax] - (0..3).map(|j| k[(ax, j)] * rf[j][i]).sum::<f64>())
                .collect();
            out.residuals
                .push(residual_stats(s, name, ax, &r, keep, unit));
            for i in 0..r.len() {
                if keep[i] {
                    ss += r[i] * r[i];
                    n += 1;
                }
            }
        }
        if n > 1 {
            let sd = (ss / (n - 1) as f64).sqrt();
            if sd > worst.0 {
                worst = (sd, sd / (2.0 * (n - 1) as f64).sqrt());
            }
        }
    }
    worst
}
