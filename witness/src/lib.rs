//! A second, deliberately simple implementation of `spec/physics.md` that writes recording
//! folders (`spec/recording-format.md`) from closed forms, for tests: it shares no code with
//! `physics/`, `drivers/` or `recording/`, so a test that analyses its recordings checks the
//! analysis against the spec, not against the project's own simulator.
//!
//! ```
//! use ratecal_witness::{Axis, Hidden, Plan, Scenario};
//! # fn main() -> std::io::Result<()> {
//! let dir = tempfile::tempdir()?;
//! let mut s = Scenario::standard("k2", 7).with(Hidden::AccelSecondOrder {
//!     k2_ug_per_g2: [150.0, -120.0, 90.0],
//! });
//! // A short plan instead of the standard one: one attitude, one rate point.
//! s.plan = Plan::new()
//!     .at("accel_static/1", 0.0, 0.0, 2.0)
//!     .spin("gyro_scale/outer/+50", Axis::Outer, 50.0, 2.0)
//!     .stop(Axis::Outer);
//! let truth = ratecal_witness::write(dir.path(), &s)?;
//! assert_eq!(truth.hidden[0].id, "accel_second_order");
//! assert!(dir.path().join("imu.csv").exists() && dir.path().join("truth.json").exists());
//! # Ok(())
//! # }
//! ```

mod hidden;
mod imu;
mod manual;
mod motion;
mod rot;
mod scenario;
mod station;
mod table;
mod write;

pub use hidden::{CustomFn, Hidden, HiddenTruth};
pub use imu::{GaussMarkov, Imu};
pub use manual::{ManualKind, ManualSession, ManualTruth, write_manual};
pub use motion::{AxesState, Axis, Plan, SegmentSpec, Step, Timeline};
pub use rot::{M3, V3};
pub use scenario::{Scenario, Thermal};
pub use station::{Instant, OMEGA_E, Station};
pub use table::{ARCSEC, true_axis};
pub use write::{Noise, Nominal, Truth, write};
