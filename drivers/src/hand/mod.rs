//! The manual station: the operator is the actuator. [`ManualTable`] is a table without
//! motion (its feedback is zeros: nothing to measure) that accepts the operator's requests;
//! the interpreter prompts the operator and waits for the IMU's rest. [`HandTable`] and
//! [`HandImu`] are the simulated operator and the simulated IMU in its hand (`--dry-run`,
//! or a `manual` station with `imu: sim`): poses placed with a random tilt of a few
//! degrees, turns of uneven speed with a small wobble, a tremor until the unit is put down.
//! The IMU's outputs come from the station's error model (`ratecal_physics`), as the
//! simulator's do, so that the recording can be fitted.

mod imu;
mod table;
mod world;

pub use imu::HandImu;
pub use table::{HandTable, ManualTable};
pub use world::{HandWorld, SharedHand};
