//! `accel_scale_thermal` and `gyro_scale_thermal`: scale factors that follow the IMU's
//! internal temperature, `s(T) = s0 + c (T - T_ref)` (ppm per degC).

use super::{Effect, Param, Partials, Sensor, Signals, per_axis};

/// The thermal sensitivity of one sensor triad's scale factors, ppm per degC.
#[derive(Debug)]
pub struct ScaleThermal {
    sensor: Sensor,
    params: &'static [Param],
}

/// Largest plausible scale thermal coefficient, ppm per degC: consumer MEMS parts are
/// specified to about 0.02 to 0.03 % per degC.
const MAX_PPM_PER_C: f64 = 500.0;

/// `accel_scale_thermal`, ppm per degC.
pub static ACCEL_SCALE_THERMAL: ScaleThermal = ScaleThermal {
    sensor: Sensor::Accel,
    params: &per_axis!(
        Sensor::Accel,
        "ppm per degC",
        [
            "attitudes with gravity along X repeated at several IMU temperatures",
            "attitudes with gravity along Y repeated at several IMU temperatures",
            "attitudes with gravity along Z repeated at several IMU temperatures"
        ],
        MAX_PPM_PER_C
    ),
};

/// `gyro_scale_thermal`, ppm per degC.
pub static GYRO_SCALE_THERMAL: ScaleThermal = ScaleThermal {
    sensor: Sensor::Gyro,
    params: &per_axis!(
        Sensor::Gyro,
        "ppm per degC",
        [
            "rotation about X repeated at several IMU temperatures",
            "rotation about Y repeated at several IMU temperatures",
            "rotation about Z repeated at several IMU temperatures"
        ],
        MAX_PPM_PER_C
    ),
};

impl Effect for ScaleThermal {
    fn id(&self) -> &'static str {
        match self.sensor {
            Sensor::Accel => "accel_scale_thermal",
            Sensor::Gyro => "gyro_scale_thermal",
        }
    }

    fn explanation(&self) -> &'static str {
        match self.sensor {
            Sensor::Accel => {
                "the accelerometer scale factors follow the IMU's internal temperature"
            }
            Sensor::Gyro => "the gyro scale factors follow the IMU's internal temperature",
        }
    }

    fn follows(&self) -> &'static str {
        match self.sensor {
            Sensor::Accel => "the specific force along the axis times the IMU temperature",
            Sensor::Gyro => "the rate about the axis times the IMU temperature",
        }
    }

    fn params(&self) -> &'static [Param] {
        self.params
    }

    fn uses_temperature(&self) -> bool {
        true
    }

    fn sensors(&self) -> &'static [Sensor] {
        self.sensor.only()
    }

    fn regressors(&self, s: &Signals, out: &mut [Partials]) {
        let x = match self.sensor {
            Sensor::Accel => s.f_b,
            Sensor::Gyro => s.w_ib_dps(),
        };
        for (i, p) in out.iter_mut().enumerate() {
            *p = Partials::axis(self.sensor, i, x[i] * s.dtemp_c * 1e-6);
        }
    }
}
