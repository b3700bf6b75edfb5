//! `accel_scale_asymmetry` and `gyro_scale_asymmetry`: the scale factor differs for
//! positive and negative inputs; output i gains `k_i |x_i|` (ppm), so the scale is
//! `s_i + k_i` for positive inputs and `s_i - k_i` for negative ones.

use super::{Descriptor, Effect, Partials, Sensor, Signals, per_axis};

/// The scale asymmetry of one sensor triad, ppm.
#[derive(Debug)]
pub struct Asymmetry {
    sensor: Sensor,
    descriptor: &'static Descriptor,
}

/// Largest plausible asymmetry, ppm: navigation-grade parts stay below 100 ppm, consumer
/// MEMS parts below about 0.5 %.
const MAX_PPM: f64 = 10_000.0;

/// `accel_scale_asymmetry`, ppm.
pub static ACCEL_SCALE_ASYMMETRY: Asymmetry = Asymmetry {
    sensor: Sensor::Accel,
    descriptor: &Descriptor {
        id: "accel_scale_asymmetry",
        explanation: "each accelerometer's scale factor differs for positive and negative specific force",
        follows: "the magnitude of the specific force along the axis",
        params: &per_axis!(
            Sensor::Accel,
            "ppm",
            [
                "attitudes with gravity along +X and -X, and with X level",
                "attitudes with gravity along +Y and -Y, and with Y level",
                "attitudes with gravity along +Z and -Z, and with Z level"
            ],
            MAX_PPM
        ),
        sensors: Sensor::Accel.only(),
        nominal: false,
        sensed: false,
        station_side: false,
        uses_temperature: false,
        varies_at_rest: false,
    },
};

/// `gyro_scale_asymmetry`, ppm.
pub static GYRO_SCALE_ASYMMETRY: Asymmetry = Asymmetry {
    sensor: Sensor::Gyro,
    descriptor: &Descriptor {
        id: "gyro_scale_asymmetry",
        explanation: "each gyro's scale factor differs for positive and negative rates",
        follows: "the magnitude of the rate about the axis",
        params: &per_axis!(
            Sensor::Gyro,
            "ppm",
            [
                "rotation about X in both directions, and static data",
                "rotation about Y in both directions, and static data",
                "rotation about Z in both directions, and static data"
            ],
            MAX_PPM
        ),
        sensors: Sensor::Gyro.only(),
        nominal: false,
        sensed: false,
        station_side: false,
        uses_temperature: false,
        varies_at_rest: false,
    },
};

impl Asymmetry {
    fn input(&self, s: &Signals) -> crate::Vec3 {
        match self.sensor {
            Sensor::Accel => s.f_b,
            Sensor::Gyro => s.w_ib_dps(),
        }
    }
}

impl Effect for Asymmetry {
    fn descriptor(&self) -> Option<&'static Descriptor> {
        Some(self.descriptor)
    }

    fn regressors(&self, s: &Signals, out: &mut [Partials]) {
        let x = self.input(s);
        for (i, p) in out.iter_mut().enumerate() {
            *p = Partials::axis(self.sensor, i, x[i].abs() * 1e-6);
        }
    }
}
