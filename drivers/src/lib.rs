//! Rate-table and IMU drivers behind small async traits, and the registry that builds them
//! from a station description. The simulated station is a driver like any other.
//! Drivers know nothing of the procedure language.

mod traits;

pub use traits::{
    DriverError, DriverErrorKind, ImuDriver, ImuInfo, ImuSample, TableAxisId, TableCommand,
    TableDriver, TableInfo, TableSample,
};
