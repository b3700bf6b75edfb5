//! Physics shared by the simulator and the analysis: the conventions of `spec/physics.md`.
//!
//! Frames: L (lab, East-North-Up), P (table inner platform), B (IMU body).
//! One implementation of the table kinematics and of the IMU measurement model serves
//! both the simulated station (which produces outputs from motion) and the analysis
//! (which computes references from the table's feedback).

pub mod effects;
mod frames;
mod kinematics;
mod model;
pub mod nav;
pub mod units;

pub use effects::{Effect, ImuModel, REGISTRY, Sensor, Signals, effect};
pub use frames::{NotARotation, check_rotation};
pub use kinematics::{
    AxisMotion, DEG, EARTH_RATE_RADPS, Geometry, STANDARD_GRAVITY, Site, Snapshot, TableState,
    rotation, skew,
};
pub use model::ImuErrors;

/// 3-vector (f64).
pub type Vec3 = nalgebra::Vector3<f64>;
/// 3x3 matrix (f64).
pub type Mat3 = nalgebra::Matrix3<f64>;
