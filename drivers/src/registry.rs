//! The one list of driver kinds, and `build`, which turns a station into a table and an
//! IMU driver. Adding a driver means adding it here (and its keys to the station file's
//! driver section); the station loader, `describe` and the CLI ask this list.

use crate::link::{Endpoint, FramedImu, LinkTable};
use crate::sim::{SharedWorld, SimImu, SimTable};
use crate::station::{ImuDriverSpec, Station, TableDriverSpec};
use crate::{DriverError, DriverErrorKind, ImuDriver, ImuInfo, TableDriver, TableInfo};
use std::sync::{Arc, Mutex};
use std::time::Duration;
use tokio::time::Instant;

/// What the builders of one station share: the seed, the host clock's origin, and the
/// simulated world when the table or the IMU is simulated.
pub struct Context<'a> {
    /// The station.
    pub station: &'a Station,
    /// Seed of every simulated random stream.
    pub seed: u64,
    /// Origin of the host clock every hardware link maps its device time onto.
    pub start: Instant,
    world: Option<SharedWorld>,
}

impl Context<'_> {
    /// The simulated world (made on first use, then shared by table and IMU).
    pub fn world(&mut self) -> SharedWorld {
        self.world
            .get_or_insert_with(|| Arc::new(Mutex::new(crate::sim::World::new(self.station))))
            .clone()
    }
}

type TableBuilder = fn(&mut Context<'_>) -> Result<Box<dyn TableDriver>, DriverError>;
type ImuBuilder = fn(&mut Context<'_>) -> Result<Box<dyn ImuDriver>, DriverError>;

/// A kind of driver the registry knows.
#[derive(Clone, Copy)]
pub struct DriverKind {
    /// Name as written in a station file (`driver: sim`, `driver: { tcp: ... }`).
    pub name: &'static str,
    /// Whether it is a simulation (runs on the paused clock) rather than a device.
    pub simulated: bool,
    /// Builds the table driver, if the kind can drive a table.
    pub table: Option<TableBuilder>,
    /// Builds the IMU driver, if the kind can read an IMU.
    pub imu: Option<ImuBuilder>,
    /// One line for people.
    pub about: &'static str,
}

impl std::fmt::Debug for DriverKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "DriverKind({})", self.name)
    }
}

/// Every driver kind.
pub const DRIVERS: &[DriverKind] = &[
    DriverKind {
        name: "sim",
        simulated: true,
        table: Some(|c| Ok(Box::new(SimTable::new(c.station, c.world(), c.seed)))),
        imu: Some(sim_imu),
        about: "simulated station (physics.md), seeded, virtual time",
    },
    DriverKind {
        name: "tcp",
        simulated: false,
        table: Some(link_table),
        imu: Some(framed_imu),
        about: "table over the line protocol, IMU over binary frames (docs/protocols.md), TCP",
    },
    DriverKind {
        name: "serial",
        simulated: false,
        table: Some(link_table),
        imu: Some(framed_imu),
        about: "the same protocols over a serial port (tokio-serial)",
    },
    DriverKind {
        name: "replay",
        simulated: false,
        table: Some(|c| match &c.station.table.driver {
            TableDriverSpec::Replay { recording } => Ok(Box::new(
                crate::replay::ReplayTable::open(recording, c.station)?,
            )),
            _ => Err(mismatch("replay")),
        }),
        imu: Some(|c| match &c.station.imu.driver {
            ImuDriverSpec::Replay { recording } => Ok(Box::new(crate::replay::ReplayImu::open(
                recording, c.station,
            )?)),
            _ => Err(mismatch("replay")),
        }),
        about: "replays the streams of a recording folder in time",
    },
];

fn mismatch(kind: &str) -> DriverError {
    DriverError::new(
        DriverErrorKind::InvalidCommand,
        format!("internal: the `{kind}` builder was given another kind"),
    )
}

fn sim_imu(c: &mut Context<'_>) -> Result<Box<dyn ImuDriver>, DriverError> {
    if !matches!(c.station.table.driver, TableDriverSpec::Sim) {
        return Err(DriverError::new(
            DriverErrorKind::InvalidCommand,
            "the simulated IMU senses the simulated table's motion: it needs `table.driver: sim`",
        ));
    }
    Ok(Box::new(SimImu::new(c.station, c.world(), c.seed)))
}

fn link_table(c: &mut Context<'_>) -> Result<Box<dyn TableDriver>, DriverError> {
    let (endpoint, timeout) = match &c.station.table.driver {
        TableDriverSpec::Tcp { address, timeout } => (Endpoint::Tcp(address.clone()), timeout.0),
        TableDriverSpec::Serial {
            port,
            baud,
            timeout,
        } => (Endpoint::Serial(port.clone(), *baud), timeout.0),
        _ => return Err(mismatch("tcp/serial")),
    };
    let spec = &c.station.table;
    let info = TableInfo {
        model: spec.model.clone(),
        max_rate_dps: spec.max_rate.0,
        max_accel_dps2: spec.max_accel_dps2,
        feedback_hz: spec.feedback_rate.0,
        simulated: false,
    };
    Ok(Box::new(LinkTable::new(endpoint, info, timeout, c.start)))
}

fn framed_imu(c: &mut Context<'_>) -> Result<Box<dyn ImuDriver>, DriverError> {
    let (endpoint, timeout) = match &c.station.imu.driver {
        ImuDriverSpec::Tcp { address, timeout } => (Endpoint::Tcp(address.clone()), timeout.0),
        ImuDriverSpec::Serial {
            port,
            baud,
            timeout,
        } => (Endpoint::Serial(port.clone(), *baud), timeout.0),
        _ => return Err(mismatch("tcp/serial")),
    };
    let imu = &c.station.imu;
    let info = ImuInfo {
        model: imu.model.clone(),
        serial: imu.serial.clone(),
        grade: imu.grade.clone(),
        sample_hz: imu.sample_rate.0,
        accel_range_mps2: imu.accel_range.0,
        gyro_range_dps: imu.gyro_range.0,
        simulated: false,
    };
    let timeout = Duration::from_secs_f64(timeout);
    Ok(Box::new(FramedImu::spawn(endpoint, info, timeout, c.start)))
}

/// The registered kind of a name.
pub fn kind(name: &str) -> Option<&'static DriverKind> {
    DRIVERS.iter().find(|k| k.name == name)
}

impl TableDriverSpec {
    /// The registry name of this driver.
    pub fn kind(&self) -> &'static str {
        match self {
            TableDriverSpec::Sim => "sim",
            TableDriverSpec::Tcp { .. } => "tcp",
            TableDriverSpec::Serial { .. } => "serial",
            TableDriverSpec::Replay { .. } => "replay",
        }
    }
}

impl ImuDriverSpec {
    /// The registry name of this driver.
    pub fn kind(&self) -> &'static str {
        match self {
            ImuDriverSpec::Sim => "sim",
            ImuDriverSpec::Tcp { .. } => "tcp",
            ImuDriverSpec::Serial { .. } => "serial",
            ImuDriverSpec::Replay { .. } => "replay",
        }
    }
}

/// Whether both of a station's drivers are simulations (the run may use virtual time).
pub fn simulated(station: &Station) -> bool {
    [station.table.driver.kind(), station.imu.driver.kind()]
        .iter()
        .all(|n| kind(n).is_some_and(|k| k.simulated))
}

/// A station's table and IMU drivers.
pub type Drivers = (Box<dyn TableDriver>, Box<dyn ImuDriver>);

/// Builds the station's table and IMU drivers from the registry (inside a tokio runtime:
/// hardware links start their readers). `seed` seeds every simulated random stream.
pub fn build(station: &Station, seed: u64) -> Result<Drivers, DriverError> {
    let mut ctx = Context {
        station,
        seed,
        start: Instant::now(),
        world: None,
    };
    let find = |name: &str| {
        kind(name).ok_or_else(|| {
            DriverError::new(
                DriverErrorKind::InvalidCommand,
                format!("no driver `{name}` in the registry"),
            )
        })
    };
    let table_kind = find(station.table.driver.kind())?;
    let imu_kind = find(station.imu.driver.kind())?;
    let no = |what: &str, k: &DriverKind| {
        DriverError::new(
            DriverErrorKind::InvalidCommand,
            format!("the `{}` driver cannot run {what}", k.name),
        )
    };
    let table = table_kind.table.ok_or_else(|| no("a table", table_kind))?(&mut ctx)?;
    let imu = imu_kind.imu.ok_or_else(|| no("an IMU", imu_kind))?(&mut ctx)?;
    Ok((table, imu))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_driver_spec_is_registered() {
        let yaml = |t: &str, i: &str| {
            crate::DEFAULT_STATION_YAML
                .replace(
                    "driver: sim\n  model: simulated",
                    &format!("driver: {t}\n  model: simulated"),
                )
                .replace(
                    "  driver: sim\n  model: SIM",
                    &format!("  driver: {i}\n  model: SIM"),
                )
        };
        for (t, i) in [
            (
                "{ tcp: { address: \"a:1\" } }",
                "{ tcp: { address: \"a:2\" } }",
            ),
            (
                "{ serial: { port: /dev/x } }",
                "{ serial: { port: /dev/y } }",
            ),
            (
                "{ replay: { recording: r } }",
                "{ replay: { recording: r } }",
            ),
        ] {
            let s = Station::from_yaml(&yaml(t, i), "s.yaml").unwrap();
            let (tk, ik) = (s.table.driver.kind(), s.imu.driver.kind());
            assert!(kind(tk).is_some_and(|k| k.table.is_some()), "{tk}");
            assert!(kind(ik).is_some_and(|k| k.imu.is_some()), "{ik}");
            assert!(!simulated(&s));
        }
        assert!(simulated(&Station::default_sim()));
    }
}
