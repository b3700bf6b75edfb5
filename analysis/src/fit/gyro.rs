//! Gyro noise from the long static block: the spread of its residuals about the joint
//! fit's model, per axis (`gyro.noise.<axis>`, and the worst as `gyro.bias.std`,
//! `gyro.noise.std`).

use super::{AXES, Out};
use crate::results::{Parameter, ResidualStats};

/// Noise of the block `id` from the fit's residual statistics of its gyro channels.
pub(crate) fn block_noise<'a>(
    id: &str,
    residuals: impl Iterator<Item = &'a ResidualStats> + Clone,
    out: &mut Out,
) {
    let mut worst = (0.0f64, 0.0f64);
    for ax in AXES {
        let Some(r) = residuals
            .clone()
            .find(|r| r.sensor == "gyro" && r.segment == id && r.channel == ax)
        else {
            return;
        };
        if r.n < 2 {
            return;
        }
        let sd = r.std;
        let u_sd = sd / (2.0 * (r.n as f64 - 1.0)).sqrt();
        out.params.insert(
            format!("gyro.noise.{ax}"),
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
