//! `accel_scale_thermal` and `gyro_scale_thermal`: scale factors that follow the IMU's
//! internal temperature, `s(T) = s0 + c (T - T_ref)` (ppm per degC).

use super::{Descriptor, Effect, Partials, Sensor, Signals, per_axis};

/// The thermal sensitivity of one sensor triad's scale factors, ppm per degC.
#[derive(Debug)]
pub struct ScaleThermal {
    sensor: Sensor,
    descriptor: &'static Descriptor,
}

/// Largest plausible scale thermal coefficient, ppm per degC: consumer MEMS parts are
/// specified to about 0.02 to 0.03 % per degC.
const MAX_PPM_PER_C: f64 = 500.0;

/// `accel_scale_thermal`, ppm per degC.
pub static ACCEL_SCALE_THERMAL: ScaleThermal = ScaleThermal {
    sensor: Sensor::Accel,
    descriptor: &Descriptor {
        id: "accel_scale_thermal",
        explanation: "the accelerometer scale factors follow the IMU's internal temperature",
        follows: "the specific force along the axis times the IMU temperature",
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
        sensors: Sensor::Accel.only(),
        nominal: false,
        sensed: false,
        station_side: false,
        uses_temperature: true,
        varies_at_rest: true,
    },
};

/// `gyro_scale_thermal`, ppm per degC.
pub static GYRO_SCALE_THERMAL: ScaleThermal = ScaleThermal {
    sensor: Sensor::Gyro,
    descriptor: &Descriptor {
        id: "gyro_scale_thermal",
        explanation: "the gyro scale factors follow the IMU's internal temperature",
        follows: "the rate about the axis times the IMU temperature",
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
        sensors: Sensor::Gyro.only(),
        nominal: false,
        sensed: false,
        station_side: false,
        uses_temperature: true,
        varies_at_rest: true,
    },
};

impl Effect for ScaleThermal {
    fn descriptor(&self) -> Option<&'static Descriptor> {
        Some(self.descriptor)
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
