//! The nominal scale-factor errors: `K - 1` on the diagonal of the sensitivity matrices.

use super::{Descriptor, Effect, Partials, Sensor, Signals, per_axis};

/// A scale-factor error of one sensor triad, ppm.
#[derive(Debug)]
pub struct Scale {
    sensor: Sensor,
    descriptor: &'static Descriptor,
}

/// Largest plausible scale-factor error, ppm: consumer MEMS sensitivities are specified to
/// +-3 % (5 % allows for the worst parts).
const MAX_PPM: f64 = 50_000.0;

/// `accel_scale`: accelerometer scale-factor errors, ppm.
pub static ACCEL_SCALE: Scale = Scale {
    sensor: Sensor::Accel,
    descriptor: &Descriptor {
        id: "accel_scale",
        explanation: "each accelerometer's sensitivity differs from nominal",
        follows: "the specific force along the axis",
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
        sensors: Sensor::Accel.only(),
        nominal: true,
        sensed: false,
        station_side: false,
        uses_temperature: false,
        varies_at_rest: false,
    },
};

/// `gyro_scale`: gyro scale-factor errors, ppm.
pub static GYRO_SCALE: Scale = Scale {
    sensor: Sensor::Gyro,
    descriptor: &Descriptor {
        id: "gyro_scale",
        explanation: "each gyro's sensitivity differs from nominal",
        follows: "the rate about the axis",
        params: &per_axis!(
            Sensor::Gyro,
            "ppm",
            ["rotate about X", "rotate about Y", "rotate about Z"],
            MAX_PPM
        ),
        sensors: Sensor::Gyro.only(),
        nominal: true,
        sensed: false,
        station_side: false,
        uses_temperature: false,
        varies_at_rest: false,
    },
};

impl Effect for Scale {
    fn descriptor(&self) -> Option<&'static Descriptor> {
        Some(self.descriptor)
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
