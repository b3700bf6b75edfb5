//! The nominal scale-factor errors: `K - 1` on the diagonal of the sensitivity matrices.

use super::{Effect, Param, Partials, Sensor, Signals, per_axis};

/// A scale-factor error of one sensor triad, ppm.
#[derive(Debug)]
pub struct Scale {
    sensor: Sensor,
    params: &'static [Param],
}

/// Largest plausible scale-factor error, ppm: consumer MEMS sensitivities are specified to
/// +-3 % (5 % allows for the worst parts).
const MAX_PPM: f64 = 50_000.0;

/// `accel_scale`: accelerometer scale-factor errors, ppm.
pub static ACCEL_SCALE: Scale = Scale {
    sensor: Sensor::Accel,
    params: &per_axis!(
        Sensor::Accel,
        "ppm",
        [
            "attitudes with gravity along +X and -X",
            "attitudes with gravity along +Y and -Y",
            "attitudes with gravity along +Z and -Z"
        ],
        MAX_PPM
    ),
};

/// `gyro_scale`: gyro scale-factor errors, ppm.
pub static GYRO_SCALE: Scale = Scale {
    sensor: Sensor::Gyro,
    params: &per_axis!(
        Sensor::Gyro,
        "ppm",
        ["rotate about X", "rotate about Y", "rotate about Z"],
        MAX_PPM
    ),
};

impl Effect for Scale {
    fn varies_at_rest(&self) -> bool {
        false
    }

    fn id(&self) -> &'static str {
        match self.sensor {
            Sensor::Accel => "accel_scale",
            Sensor::Gyro => "gyro_scale",
        }
    }

    fn explanation(&self) -> &'static str {
        match self.sensor {
            Sensor::Accel => "each accelerometer's sensitivity differs from nominal",
            Sensor::Gyro => "each gyro's sensitivity differs from nominal",
        }
    }

    fn follows(&self) -> &'static str {
        match self.sensor {
            Sensor::Accel => "the specific force along the axis",
            Sensor::Gyro => "the rate about the axis",
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

    fn regressors(&self, s: &Signals, out: &mut [Partials]) {
        let input = match self.sensor {
            Sensor::Accel => s.f_b,
            Sensor::Gyro => s.w_ib_dps(),
        };
        for (i, p) in out.iter_mut().enumerate() {
            *p = Partials::axis(self.sensor, i, input[i] * 1e-6);
        }
    }
}
