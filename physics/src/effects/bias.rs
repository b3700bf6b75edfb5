//! The nominal biases: outputs at zero input.

use super::{Descriptor, Effect, Partials, Sensor, Signals, per_axis};

/// A bias of one sensor triad.
#[derive(Debug)]
pub struct Bias {
    sensor: Sensor,
    descriptor: &'static Descriptor,
}

const NEEDS: [&str; 3] = ["any data of the sensor"; 3];

// Consumer MEMS parts: zero-g offsets up to about 150 mg after soldering, zero-rate
// outputs up to about 25 deg/s.
/// Largest plausible accelerometer bias, m/s^2 (about 200 mg).
const ACCEL_MAX: f64 = 2.0;
/// Largest plausible gyro bias, deg/s.
const GYRO_MAX: f64 = 30.0;

/// `accel_bias`: accelerometer outputs at zero input, m/s^2.
pub static ACCEL_BIAS: Bias = Bias {
    sensor: Sensor::Accel,
    descriptor: &Descriptor {
        id: "accel_bias",
        explanation: "each accelerometer reads a constant offset at zero input",
        follows: "nothing: a constant",
        params: &per_axis!(Sensor::Accel, "m/s^2", NEEDS, ACCEL_MAX),
        sensors: Sensor::Accel.only(),
        nominal: true,
        sensed: false,
        station_side: false,
        uses_temperature: false,
        varies_at_rest: false,
    },
};

/// `gyro_bias`: gyro outputs at zero input, deg/s.
pub static GYRO_BIAS: Bias = Bias {
    sensor: Sensor::Gyro,
    descriptor: &Descriptor {
        id: "gyro_bias",
        explanation: "each gyro reads a constant offset at zero input",
        follows: "nothing: a constant",
        params: &per_axis!(Sensor::Gyro, "deg/s", NEEDS, GYRO_MAX),
        sensors: Sensor::Gyro.only(),
        nominal: true,
        sensed: false,
        station_side: false,
        uses_temperature: false,
        varies_at_rest: false,
    },
};

impl Effect for Bias {
    fn descriptor(&self) -> Option<&'static Descriptor> {
        Some(self.descriptor)
    }

    fn regressors(&self, _s: &Signals, out: &mut [Partials]) {
        for (i, p) in out.iter_mut().enumerate() {
            *p = Partials::axis(self.sensor, i, 1.0);
        }
    }
}
