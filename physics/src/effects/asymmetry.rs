//! `accel_scale_asymmetry` and `gyro_scale_asymmetry`: the scale factor differs for
//! positive and negative inputs; output i gains `k_i |x_i|` (ppm), so the scale is
//! `s_i + k_i` for positive inputs and `s_i - k_i` for negative ones.

use super::{Effect, Param, Partials, Sensor, Signals, per_axis};

/// The scale asymmetry of one sensor triad, ppm.
#[derive(Debug)]
pub struct Asymmetry {
    sensor: Sensor,
    params: &'static [Param],
}

/// Largest plausible asymmetry, ppm: navigation-grade parts stay below 100 ppm, consumer
/// MEMS parts below about 0.5 %.
const MAX_PPM: f64 = 10_000.0;

/// `accel_scale_asymmetry`, ppm.
pub static ACCEL_SCALE_ASYMMETRY: Asymmetry = Asymmetry {
    sensor: Sensor::Accel,
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
};

/// `gyro_scale_asymmetry`, ppm.
pub static GYRO_SCALE_ASYMMETRY: Asymmetry = Asymmetry {
    sensor: Sensor::Gyro,
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
    fn varies_at_rest(&self) -> bool {
        false
    }

    fn id(&self) -> &'static str {
        match self.sensor {
            Sensor::Accel => "accel_scale_asymmetry",
            Sensor::Gyro => "gyro_scale_asymmetry",
        }
    }

    fn explanation(&self) -> &'static str {
        match self.sensor {
            Sensor::Accel => {
                "each accelerometer's scale factor differs for positive and negative specific force"
            }
            Sensor::Gyro => "each gyro's scale factor differs for positive and negative rates",
        }
    }

    fn follows(&self) -> &'static str {
        match self.sensor {
            Sensor::Accel => "the magnitude of the specific force along the axis",
            Sensor::Gyro => "the magnitude of the rate about the axis",
        }
    }

    fn params(&self) -> &'static [Param] {
        self.params
    }

    fn sensors(&self) -> &'static [Sensor] {
        self.sensor.only()
    }

    fn regressors(&self, s: &Signals, out: &mut [Partials]) {
        let x = self.input(s);
        for (i, p) in out.iter_mut().enumerate() {
            *p = Partials::axis(self.sensor, i, x[i].abs() * 1e-6);
        }
    }
}
