//! Strapdown navigation for the size-effect experiment (spec/physics.md, "The size-effect
//! experiment"): initial alignment at rest, attitude by rotation vectors with a coning
//! term, velocity in the lab frame L with gravity and the Earth's rotation, and the
//! accelerometer size-effect compensation of Kozlov & Kapralov's equation (1).

mod align;
mod compensate;
mod strapdown;
mod sway;

pub use align::{AlignError, align};
pub use compensate::{angular_accel, compensate};
pub use strapdown::{Strapdown, Trajectory, navigate};
pub use sway::sway_coefficient;
