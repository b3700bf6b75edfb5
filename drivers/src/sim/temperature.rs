//! Lab air and IMU internal temperature as functions of time (noise is added by the
//! streams that report them).

use crate::station::{FaultSpec, Station};

/// One ambient excursion: ramp up by `delta` over `ramp`, hold `hold`, ramp back down.
#[derive(Debug, Clone, Copy)]
struct Excursion {
    at: f64,
    delta: f64,
    ramp: f64,
    hold: f64,
}

impl Excursion {
    fn value(&self, t: f64) -> f64 {
        let s = t - self.at;
        let ramp = self.ramp.max(1e-9);
        if s <= 0.0 {
            0.0
        } else if s < ramp {
            self.delta * s / ramp
        } else if s < ramp + self.hold {
            self.delta
        } else if s < 2.0 * ramp + self.hold {
            self.delta * (2.0 * ramp + self.hold - s) / ramp
        } else {
            0.0
        }
    }
}

/// The station's temperature behaviour.
#[derive(Debug, Clone)]
pub struct Temperatures {
    mean: f64,
    drift_per_s: f64,
    warmup_offset: f64,
    warmup_tau: f64,
    excursions: Vec<Excursion>,
}

impl Temperatures {
    /// From the station's `temperature` section and its temperature-excursion faults.
    pub fn new(station: &Station) -> Self {
        let t = &station.temperature;
        let excursions = station
            .faults
            .iter()
            .filter_map(|f| match f {
                FaultSpec::TemperatureExcursion {
                    at,
                    delta,
                    ramp,
                    duration,
                } => Some(Excursion {
                    at: at.0,
                    delta: delta.0,
                    ramp: ramp.0,
                    hold: duration.0,
                }),
                _ => None,
            })
            .collect();
        Temperatures {
            mean: t.ambient.mean.0,
            drift_per_s: t.ambient.drift.0 / 3600.0,
            warmup_offset: t.imu.warmup_offset.0,
            warmup_tau: t.imu.warmup_time_constant.0.max(1e-9),
            excursions,
        }
    }

    /// True lab air temperature at `t`, degC.
    pub fn ambient(&self, t: f64) -> f64 {
        let mut v = self.mean + self.drift_per_s * t;
        for e in &self.excursions {
            v += e.value(t);
        }
        v
    }

    /// True IMU internal temperature at `t`, degC: ambient plus the warm-up offset.
    pub fn imu(&self, t: f64) -> f64 {
        let warm = if self.warmup_offset == 0.0 {
            0.0
        } else {
            self.warmup_offset * (1.0 - (-t.max(0.0) / self.warmup_tau).exp())
        };
        self.ambient(t) + warm
    }
}
