//! `gyro_scale_nonlinearity`: each gyro output gains `n_i w_i |w_i|` (ppm per deg/s).

use super::{Descriptor, Effect, Param, Partials, Sensor, Signals, per_axis};

/// The `gyro_scale_nonlinearity` effect.
#[derive(Debug)]
pub struct Nonlinearity;

/// The registry's instance.
pub static GYRO_SCALE_NONLINEARITY: Nonlinearity = Nonlinearity;

static PARAMS: [Param; 3] = per_axis!(
    Sensor::Gyro,
    "ppm per deg/s",
    [
        "rate points of several magnitudes about X",
        "rate points of several magnitudes about Y",
        "rate points of several magnitudes about Z"
    ],
    // A consumer gyro's nonlinearity (up to 1 % of a 250 deg/s full scale) as a quadratic
    // term: 0.01 * 250 / 250^2 = 40e-6 per deg/s.
    50.0
);

/// What `gyro_scale_nonlinearity` is.
static DESCRIPTOR: Descriptor = Descriptor {
    id: "gyro_scale_nonlinearity",
    explanation: "the gyro scale factor changes with the rate: the output error grows with the square of the rate",
    follows: "the signed square of the rate",
    params: &PARAMS,
    sensors: &[Sensor::Gyro],
    nominal: false,
    sensed: false,
    station_side: false,
    uses_temperature: false,
    varies_at_rest: false,
};

impl Effect for Nonlinearity {
    fn descriptor(&self) -> Option<&'static Descriptor> {
        Some(&DESCRIPTOR)
    }

    fn regressors(&self, s: &Signals, out: &mut [Partials]) {
        let w = s.w_ib_dps();
        for (i, p) in out.iter_mut().enumerate() {
            *p = Partials::axis(Sensor::Gyro, i, 1e-6 * w[i] * w[i].abs());
        }
    }
}
