//! Rate-table and IMU drivers behind small async traits, and the registry that builds them
//! from a station description. The simulated station is a driver like any other.
//! Drivers know nothing of the procedure language.
//!
//! ```
//! # #[tokio::main(flavor = "current_thread", start_paused = true)]
//! # async fn main() {
//! use ratecal_drivers::{Station, TableCommand, registry};
//! let station = Station::default_sim();
//! let (mut table, mut imu) = registry::build(&station, 7).unwrap();
//! table.command(TableCommand::MoveTo { outer_deg: 90.0, inner_deg: 0.0 }).await.unwrap();
//! tokio::time::sleep(std::time::Duration::from_secs(10)).await;
//! let mut samples = Vec::new();
//! imu.read(&mut samples).await.unwrap();
//! assert_eq!(samples.len(), 1001); // 100 Hz, t = 0 ..= 10 s
//! # }
//! ```

pub mod emulate;
pub mod frame;
pub mod hand;
pub mod line;
pub mod link;
pub mod registry;
pub mod replay;
pub mod sim;
pub mod station;
mod traits;

pub use registry::{DRIVERS, DriverKind, DriverSpec, Drivers, build};
pub use station::{
    DEFAULT_STATION_YAML, MANUAL_STATION_YAML, SWAYING_STATION_YAML, Station, StationError,
    StationInfo, yaml_offset,
};
pub use traits::{
    DriverError, DriverErrorKind, ImuDriver, ImuInfo, ImuSample, LinkStats, OperatorAsk,
    TableAxisId, TableCommand, TableDriver, TableInfo, TableSample,
};
