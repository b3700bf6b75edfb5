//! `gyro_thermal_drift` and `accel_thermal_drift`: biases that follow the IMU's internal
//! temperature, `b(T) = b0 + k (T - T_ref)`.

use super::{Descriptor, Effect, Partials, Sensor, Signals, per_axis};

/// The thermal drift of one sensor triad's biases.
#[derive(Debug)]
pub struct ThermalDrift {
    sensor: Sensor,
    descriptor: &'static Descriptor,
}

const NEEDS: [&str; 3] = ["a change of the IMU's temperature during the data"; 3];

// Consumer MEMS parts: zero-rate drift up to about 0.15 deg/s per degC, zero-g drift up to
// about 1.5 mg per degC.
/// Largest plausible gyro bias drift, deg/s per degC.
const GYRO_MAX: f64 = 0.2;
/// Largest plausible accelerometer bias drift, m/s^2 per degC (about 2 mg per degC).
const ACCEL_MAX: f64 = 0.02;

/// `gyro_thermal_drift`, deg/s per degC.
pub static GYRO_THERMAL_DRIFT: ThermalDrift = ThermalDrift {
    sensor: Sensor::Gyro,
    descriptor: &Descriptor {
        id: "gyro_thermal_drift",
        explanation: "the gyro biases follow the IMU's internal temperature",
        follows: "the IMU temperature",
        params: &per_axis!(Sensor::Gyro, "deg/s per degC", NEEDS, GYRO_MAX),
        sensors: Sensor::Gyro.only(),
        nominal: false,
        sensed: false,
        station_side: false,
        uses_temperature: true,
        varies_at_rest: true,
    },
};

/// `accel_thermal_drift`, m/s^2 per degC.
pub static ACCEL_THERMAL_DRIFT: ThermalDrift = ThermalDrift {
    sensor: Sensor::Accel,
    descriptor: &Descriptor {
        id: "accel_thermal_drift",
        explanation: "the accelerometer biases follow the IMU's internal temperature",
        follows: "the IMU temperature",
        params: &per_axis!(Sensor::Accel, "m/s^2 per degC", NEEDS, ACCEL_MAX),
        sensors: Sensor::Accel.only(),
        nominal: false,
        sensed: false,
        station_side: false,
        uses_temperature: true,
        varies_at_rest: true,
    },
};

impl Effect for ThermalDrift {
    fn descriptor(&self) -> Option<&'static Descriptor> {
        Some(self.descriptor)
    }

    fn regressors(&self, s: &Signals, out: &mut [Partials]) {
        for (i, p) in out.iter_mut().enumerate() {
            *p = Partials::axis(self.sensor, i, s.dtemp_c);
        }
    }
}
