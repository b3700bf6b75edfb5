//! Gyro noise from the long static block: the spread of its residuals about the fitted
//! model, per axis (`gyro.noise.<axis>`, and the worst as `gyro.bias.std`,
//! `gyro.noise.std`).

use super::prep::SegData;
use super::stats::std;
use super::{AXES, Out};
use crate::results::Parameter;
use ratecal_physics::{Mat3, Vec3};

/// Noise of the block's residuals about `out = K w_ref + b`, per axis.
pub(crate) fn block_noise(block: &SegData, k: &Mat3, b: &Vec3, out: &mut Out) {
    let mut worst = (0.0f64, 0.0f64);
    let keep = &block.keep_g;
    let n = keep.iter().filter(|k| **k).count() as f64;
    if n < 2.0 {
        return;
    }
    for ax in 0..3 {
        let r: Vec<f64> = (0..block.t.len())
            .map(|i| {
                block.gyro[ax][i]
                    - b[ax]
                    - (0..3).map(|j| k[(ax, j)] * block.w_ref[j][i]).sum::<f64>()
            })
            .collect();
        let sd = std(&r, keep);
        let u_sd = sd / (2.0 * (n - 1.0)).sqrt();
        out.params.insert(
            format!("gyro.noise.{}", AXES[ax]),
            Parameter::estimate(sd, u_sd, "deg/s"),
        );
        if sd > worst.0 {
            worst = (sd, u_sd);
        }
    }
    for q in ["gyro.bias.std", "gyro.noise", "gyro.noise.std"] {
        out.quantities.insert(q.into(), worst);
    }
}
