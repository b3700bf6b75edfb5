//! The one list of driver kinds, and `build`, which turns a station into a table and an
//! IMU driver. Adding a driver means adding it here and nowhere else.

use crate::station::{ImuDriverSpec, Station, TableDriverSpec};
use crate::{DriverError, DriverErrorKind, ImuDriver, TableDriver};

/// A kind of driver the registry knows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DriverKind {
    /// Name as written in a station file (`driver: sim`).
    pub name: &'static str,
    /// Whether it can drive a table.
    pub table: bool,
    /// Whether it can read an IMU.
    pub imu: bool,
    /// One line for people.
    pub about: &'static str,
}

/// Every driver kind.
pub const DRIVERS: &[DriverKind] = &[
    DriverKind {
        name: "sim",
        table: true,
        imu: true,
        about: "simulated station (physics.md), seeded, virtual time",
    },
    DriverKind {
        name: "tcp",
        table: true,
        imu: false,
        about: "table over the ratecal line protocol (TCP)",
    },
    DriverKind {
        name: "replay",
        table: true,
        imu: true,
        about: "replays the streams of a recording folder in time",
    },
];

/// A station's table and IMU drivers.
pub type Drivers = (Box<dyn TableDriver>, Box<dyn ImuDriver>);

/// Builds the station's table and IMU drivers. `seed` seeds every simulated random stream.
pub fn build(station: &Station, seed: u64) -> Result<Drivers, DriverError> {
    match (&station.table.driver, &station.imu.driver) {
        (TableDriverSpec::Sim, ImuDriverSpec::Sim) => {
            let (table, imu) = crate::sim::build(station, seed);
            Ok((Box::new(table), Box::new(imu)))
        }
        (_, ImuDriverSpec::Sim) => Err(DriverError::new(
            DriverErrorKind::InvalidCommand,
            "the simulated IMU senses the simulated table's motion: it needs `table.driver: sim`",
        )),
        (table, ImuDriverSpec::Replay { recording }) => {
            let table: Box<dyn TableDriver> = match table {
                TableDriverSpec::Sim => Box::new(crate::sim::build(station, seed).0),
                TableDriverSpec::Tcp { address, timeout } => Box::new(crate::tcp::TcpTable::new(
                    address.clone(),
                    station.table.clone(),
                    timeout.0,
                )),
                TableDriverSpec::Replay { recording } => {
                    Box::new(crate::replay::ReplayTable::open(recording, station)?)
                }
            };
            let imu = crate::replay::ReplayImu::open(recording, station)?;
            Ok((table, Box::new(imu)))
        }
    }
}
