//! `time_offset`: the IMU and table clocks disagree; the sample stamped `t` measured the
//! motion at `t - tau`.

use super::{Descriptor, Effect, Param, Partials, Sensor, Signals};
use crate::DEG;

/// The `time_offset` effect (`tau_ms`).
#[derive(Debug)]
pub struct TimeOffset;

/// The registry's instance.
pub static TIME_OFFSET: TimeOffset = TimeOffset;

static PARAMS: [Param; 1] = [Param {
    name: "tau_ms",
    unit: "ms",
    channel: None,
    needs: "motion that changes the references: rotation that turns gravity through the accelerometers, or changing rates",
    // A second of clock disagreement is a broken setup, not a calibration result.
    max_abs: 1000.0,
}];

/// What `time_offset` is.
static DESCRIPTOR: Descriptor = Descriptor {
    id: "time_offset",
    explanation: "the IMU and table clocks disagree: the IMU samples lag (or lead) the table's feedback",
    follows: "the rate of change of the reference",
    params: &PARAMS,
    sensors: &[Sensor::Accel, Sensor::Gyro],
    nominal: false,
    sensed: false,
    station_side: false,
    uses_temperature: false,
    varies_at_rest: false,
};

impl Effect for TimeOffset {
    fn descriptor(&self) -> Option<&'static Descriptor> {
        Some(&DESCRIPTOR)
    }

    /// y(t - tau) = y(t) - tau dy/dt to first order.
    fn regressors(&self, s: &Signals, out: &mut [Partials]) {
        out[0] = Partials {
            accel: -s.df_b * 1e-3,
            gyro: -s.dw_ib / DEG * 1e-3,
        };
    }

    /// The simulator delays the motion itself (exact, not the first-order term).
    fn forward(&self, _values: &[f64], _s: &Signals) -> Partials {
        Partials::default()
    }

    fn delay_s(&self, values: &[f64]) -> f64 {
        values[0] * 1e-3
    }
}
