//! `clock_rate`: the IMU's sample clock runs at a rate that differs from the table's.
//!
//! Convention: with `eps = ppm * 1e-6`, the IMU clock advances `(1 + eps)` s for each
//! second of the table's clock, both reading 0 at the recording's time origin (a
//! disagreement at the origin is the `time_offset`). The sample the IMU stamps `t` was
//! therefore taken at table time `t / (1 + eps)`: positive ppm (a fast IMU clock) makes
//! the samples lag the table's feedback by `t eps / (1 + eps)`, a delay that grows along
//! the recording (60 ppm is 0.1 s after half an hour). With a time offset as well, the
//! motion seen at stamp `t` is that of table time `t / (1 + eps) - tau`.

use super::{Descriptor, Effect, Param, Partials, Sensor, Signals};
use crate::DEG;

/// The `clock_rate` effect (`ppm`).
#[derive(Debug)]
pub struct ClockRate;

/// The registry's instance.
pub static CLOCK_RATE: ClockRate = ClockRate;

static PARAMS: [Param; 1] = [Param {
    name: "ppm",
    unit: "ppm",
    channel: None,
    needs: "motion that changes the references (rotation turning gravity through the accelerometers, changing rates) early and late in a long recording: the lag grows with time",
    // Crystal oscillators: 10 to 100 ppm; the internal RC oscillators of consumer IMUs:
    // a few percent over temperature.
    max_abs: 30_000.0,
}];

impl ClockRate {
    /// The table time (s) at which the sample stamped `t_s` by the IMU was taken.
    pub fn table_time_s(ppm: f64, t_s: f64) -> f64 {
        t_s / (1.0 + ppm * 1e-6)
    }
}

/// What `clock_rate` is.
static DESCRIPTOR: Descriptor = Descriptor {
    id: "clock_rate",
    explanation: "the IMU's sample clock runs fast or slow against the table's: the samples drift in time against the table's feedback",
    follows: "the rate of change of the reference, times the time since the start",
    params: &PARAMS,
    sensors: &[Sensor::Accel, Sensor::Gyro],
    nominal: false,
    sensed: false,
    station_side: false,
    uses_temperature: false,
    varies_at_rest: true,
};

impl Effect for ClockRate {
    fn descriptor(&self) -> Option<&'static Descriptor> {
        Some(&DESCRIPTOR)
    }

    /// `y(t / (1 + eps)) = y(t) - t eps dy/dt` to first order (`eps = ppm * 1e-6`).
    fn regressors(&self, s: &Signals, out: &mut [Partials]) {
        let k = -s.t_s * 1e-6;
        out[0] = Partials {
            accel: s.df_b * k,
            gyro: s.dw_ib / DEG * k,
        };
    }

    /// The simulator re-times the motion itself (exact, not the first-order term).
    fn forward(&self, _values: &[f64], _s: &Signals) -> Partials {
        Partials::default()
    }

    fn delay_at_s(&self, values: &[f64], t_s: f64) -> f64 {
        t_s - ClockRate::table_time_s(values[0], t_s)
    }
}
