//! The simulated table: commands re-plan the analytic motion; feedback is the true motion
//! plus encoder noise and rate ripple, sampled at the feedback rate.

use super::{SharedWorld, Temperatures, lock};
use crate::station::Station;
use crate::{
    DriverError, DriverErrorKind, TableAxisId, TableCommand, TableDriver, TableInfo, TableSample,
};
use async_trait::async_trait;
use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};
use rand_distr::StandardNormal;

/// The simulated rate table (a real driver: used for dry runs and tests).
#[derive(Debug)]
pub struct SimTable {
    world: SharedWorld,
    info: TableInfo,
    next_k: u64,
    hints: [usize; 2],
    rng: ChaCha8Rng,
    position_noise: f64,
    rate_ripple: f64,
    temps: Temperatures,
    ambient_noise: f64,
    report_ambient: bool,
}

fn idx(axis: TableAxisId) -> usize {
    match axis {
        TableAxisId::Outer => 0,
        TableAxisId::Inner => 1,
    }
}

fn invalid(msg: String) -> DriverError {
    DriverError::new(DriverErrorKind::InvalidCommand, msg)
}

impl SimTable {
    pub(crate) fn new(station: &Station, world: SharedWorld, seed: u64) -> Self {
        let t = &station.table;
        SimTable {
            world,
            info: TableInfo {
                model: t.model.clone(),
                max_rate_dps: t.max_rate.0,
                max_accel_dps2: t.max_accel_dps2,
                feedback_hz: t.feedback_rate.0,
                simulated: true,
            },
            next_k: 0,
            hints: [0; 2],
            rng: ChaCha8Rng::seed_from_u64(seed ^ 0x7AB1_E000_0000_0001),
            position_noise: t.position_noise.0,
            rate_ripple: t.rate_ripple.0,
            temps: Temperatures::new(station),
            ambient_noise: station.temperature.ambient.noise.0,
            report_ambient: station.temperature.report_ambient,
        }
    }

    fn check(&self, cmd: &TableCommand) -> Result<(), DriverError> {
        let (vmax, amax) = (self.info.max_rate_dps, self.info.max_accel_dps2);
        match *cmd {
            TableCommand::MoveTo {
                outer_deg,
                inner_deg,
            } if !(outer_deg.is_finite() && inner_deg.is_finite()) => Err(invalid(format!(
                "move to non-finite angles ({outer_deg}, {inner_deg})"
            ))),
            TableCommand::Rate { rate_dps, .. } if rate_dps.is_nan() || rate_dps.abs() > vmax => {
                Err(invalid(format!(
                    "rate {rate_dps} deg/s exceeds the table's {vmax} deg/s"
                )))
            }
            TableCommand::Oscillate {
                center_deg,
                amplitude_deg,
                period_s,
                ..
            } => {
                let w = 2.0 * std::f64::consts::PI / period_s;
                let (a, c) = (amplitude_deg.abs(), center_deg);
                if !(period_s > 0.0 && a.is_finite() && c.is_finite()) {
                    return Err(invalid(format!(
                        "oscillation with period {period_s} s, amplitude {a} deg"
                    )));
                }
                // The smooth start adds up to 5/8 of the steady peak acceleration.
                if a * w > vmax || 1.625 * a * w * w > amax {
                    return Err(invalid(format!(
                        "oscillation of {a} deg over {period_s} s needs {:.1} deg/s and {:.1} deg/s^2; the table allows {vmax} and {amax}",
                        a * w,
                        1.625 * a * w * w
                    )));
                }
                Ok(())
            }
            _ => Ok(()),
        }
    }
}

#[async_trait]
impl TableDriver for SimTable {
    fn info(&self) -> TableInfo {
        self.info.clone()
    }

    async fn command(&mut self, cmd: TableCommand) -> Result<(), DriverError> {
        self.check(&cmd)?;
        let mut w = lock(&self.world)?;
        let now = w.now();
        w.advance(now);
        match cmd {
            TableCommand::MoveTo {
                outer_deg,
                inner_deg,
            } => {
                for (i, target) in [outer_deg, inner_deg].into_iter().enumerate() {
                    if !w.locked(i) {
                        w.axes[i].move_to(now, target);
                    }
                }
            }
            TableCommand::Rate { axis, rate_dps } if !w.locked(idx(axis)) => {
                w.axes[idx(axis)].ramp_to_rate(now, rate_dps);
            }
            TableCommand::Stop { axis } if !w.locked(idx(axis)) => {
                w.axes[idx(axis)].ramp_to_rate(now, 0.0)
            }
            TableCommand::Oscillate {
                axis,
                center_deg,
                amplitude_deg,
                period_s,
            } if !w.locked(idx(axis)) => {
                w.axes[idx(axis)].oscillate(now, center_deg, amplitude_deg, period_s);
            }
            // An emergency stop works even on a faulty axis.
            TableCommand::SafeStop => {
                for axis in &mut w.axes {
                    axis.ramp_to_rate(now, 0.0);
                }
            }
            // A faulty axis accepts the command and does not follow it.
            _ => {}
        }
        Ok(())
    }

    async fn read(&mut self, out: &mut Vec<TableSample>) -> Result<(), DriverError> {
        let mut w = lock(&self.world)?;
        let now = w.now();
        w.advance(now);
        let dt = 1.0 / self.info.feedback_hz;
        loop {
            let t = self.next_k as f64 * dt;
            if t > now {
                break;
            }
            let o = w.axes[0].eval(t, &mut self.hints[0]);
            let i = w.axes[1].eval(t, &mut self.hints[1]);
            let mut n = || -> f64 { self.rng.sample(StandardNormal) };
            let (pn, rr) = (self.position_noise, self.rate_ripple);
            let sample = TableSample {
                t,
                outer_deg: o.angle + pn * n(),
                inner_deg: i.angle + pn * n(),
                outer_rate_dps: o.rate + rr * n(),
                inner_rate_dps: i.rate + rr * n(),
                ambient_c: self
                    .report_ambient
                    .then(|| self.temps.ambient(t) + self.ambient_noise * n()),
                t_host: None,
            };
            out.push(sample);
            self.next_k += 1;
        }
        Ok(())
    }
}
