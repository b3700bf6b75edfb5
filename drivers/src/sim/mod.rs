//! The simulated station: a table and an IMU sharing one world.
//!
//! Both drivers read the tokio clock relative to the world's start instant, so under a
//! paused clock (`start_paused = true`) hours of procedure run in seconds. Samples are
//! generated lazily and in bulk when `read` is called (every sample whose time is <= now),
//! each stream from its own seeded RNG, so the samples do not depend on how often the
//! interpreter reads. The table's motion is analytic (`profile.rs`); the IMU senses it
//! through `ratecal_physics` at `t - tau`.

mod imu;
mod profile;
mod table;
mod temperature;

pub use imu::SimImu;
pub use profile::{AxisKinematics, AxisProfile, Servo};
pub use table::SimTable;
pub use temperature::Temperatures;

use crate::DriverError;
use crate::station::{FaultSpec, Station, TableFaultMode};
use std::sync::{Arc, Mutex, MutexGuard};
use tokio::time::Instant;

/// A table fault waiting for its time.
#[derive(Debug, Clone, Copy)]
struct PendingFault {
    at: f64,
    axis: usize,
    mode: TableFaultMode,
    rate: f64,
}

/// What the table and the IMU share: the start instant and the true motion.
#[derive(Debug)]
pub struct World {
    start: Instant,
    /// Outer and inner axis motion.
    pub axes: [AxisProfile; 2],
    /// Axes that no longer follow commands (a rehearsed fault).
    locked: [bool; 2],
    faults: Vec<PendingFault>,
}

impl World {
    /// A world at rest at angles (0, 0), starting now on the tokio clock.
    pub fn new(station: &Station) -> Self {
        let t = &station.table;
        let servo = Servo {
            wn: 2.0 * std::f64::consts::PI * t.settling.natural_frequency.0,
            zeta: t.settling.damping,
            feedforward: t.settling.feedforward,
        };
        // Plan so that the servo's overshoot stays within the table's acceleration limit.
        let plan_accel = t.max_accel_dps2 / servo.accel_derating();
        let axis = || AxisProfile::at_rest(0.0, servo, t.max_rate.0, plan_accel);
        let mut faults: Vec<PendingFault> = station
            .faults
            .iter()
            .filter_map(|f| match f {
                FaultSpec::Table {
                    at,
                    axis,
                    mode,
                    rate,
                } => Some(PendingFault {
                    at: at.0,
                    axis: *axis as usize,
                    mode: *mode,
                    rate: rate.0.clamp(-t.max_rate.0, t.max_rate.0),
                }),
                _ => None,
            })
            .collect();
        faults.sort_by(|a, b| a.at.total_cmp(&b.at));
        World {
            start: Instant::now(),
            axes: [axis(), axis()],
            locked: [false; 2],
            faults,
        }
    }

    /// Seconds since the world's start on the tokio clock.
    pub fn now(&self) -> f64 {
        self.start.elapsed().as_secs_f64()
    }

    /// Applies every table fault whose time has come (at its own time, not at `now`).
    pub fn advance(&mut self, now: f64) {
        while let Some(f) = self.faults.first().copied().filter(|f| f.at <= now) {
            self.faults.remove(0);
            let rate = match f.mode {
                TableFaultMode::Stuck => 0.0,
                TableFaultMode::Runaway => f.rate,
            };
            self.axes[f.axis].ramp_to_rate(f.at, rate);
            self.locked[f.axis] = true;
        }
    }

    /// Whether an axis ignores commands.
    pub fn locked(&self, axis: usize) -> bool {
        self.locked[axis]
    }
}

/// The world behind a mutex, shared by the simulated table and IMU. Each driver locks it
/// once per `read` or `command`, never per sample.
pub type SharedWorld = Arc<Mutex<World>>;

fn lock(world: &SharedWorld) -> Result<MutexGuard<'_, World>, DriverError> {
    world.lock().map_err(|_| {
        DriverError::new(
            crate::DriverErrorKind::Instrument,
            "simulated station state poisoned",
        )
    })
}

/// Builds the simulated table and IMU of a station, seeded.
pub fn build(station: &Station, seed: u64) -> (SimTable, SimImu) {
    let world: SharedWorld = Arc::new(Mutex::new(World::new(station)));
    let table = SimTable::new(station, world.clone(), seed);
    let imu = SimImu::new(station, world, seed);
    (table, imu)
}
