//! The nominal biases: outputs at zero input.

use super::{Effect, Param, Partials, Sensor, Signals, per_axis};

/// A bias of one sensor triad.
#[derive(Debug)]
pub struct Bias {
    sensor: Sensor,
    params: &'static [Param],
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
    params: &per_axis!(Sensor::Accel, "m/s^2", NEEDS, ACCEL_MAX),
};

/// `gyro_bias`: gyro outputs at zero input, deg/s.
pub static GYRO_BIAS: Bias = Bias {
    sensor: Sensor::Gyro,
    params: &per_axis!(Sensor::Gyro, "deg/s", NEEDS, GYRO_MAX),
};

impl Effect for Bias {
    fn varies_at_rest(&self) -> bool {
        false
    }

    fn id(&self) -> &'static str {
        match self.sensor {
            Sensor::Accel => "accel_bias",
            Sensor::Gyro => "gyro_bias",
        }
    }

    fn explanation(&self) -> &'static str {
        match self.sensor {
            Sensor::Accel => "each accelerometer reads a constant offset at zero input",
            Sensor::Gyro => "each gyro reads a constant offset at zero input",
        }
    }

    fn follows(&self) -> &'static str {
        match self.sensor {
            Sensor::Accel => "nothing: a constant",
            Sensor::Gyro => "nothing: a constant",
        }
    }

    fn params(&self) -> &'static [Param] {
        self.params
    }

    fn nominal(&self) -> bool {
        true
    }

    fn sensors(&self) -> &'static [Sensor] {
        self.sensor.only()
    }

    fn regressors(&self, _s: &Signals, out: &mut [Partials]) {
        for (i, p) in out.iter_mut().enumerate() {
            *p = Partials::axis(self.sensor, i, 1.0);
        }
    }
}
