//! How each kind of driver is built, and `build`, which turns a station into a table and an
//! IMU driver. Adding a driver means adding its kind, with the settings it takes, to the
//! one list of kinds (`station/driver.rs`: the station file's `driver:` values are parsed
//! against it, and `describe` and the CLI ask it), and its builders here.

pub use crate::station::{DRIVERS, DriverKind, DriverSpec, Settings, kind};

use crate::hand::{HandImu, HandTable, HandWorld, ManualTable, SharedHand};
use crate::link::{Endpoint, FramedImu, LinkTable};
use crate::sim::{SharedWorld, SimImu, SimTable};
use crate::station::Station;
use crate::{DriverError, DriverErrorKind, ImuDriver, TableDriver, TableInfo};
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
    hand: Option<SharedHand>,
}

impl Context<'_> {
    /// The simulated operator (made on first use, then shared by table and IMU).
    pub fn hand(&mut self) -> SharedHand {
        let seed = self.seed;
        self.hand
            .get_or_insert_with(|| Arc::new(Mutex::new(HandWorld::new(seed))))
            .clone()
    }

    /// The simulated world (made on first use, then shared by table and IMU).
    pub fn world(&mut self) -> SharedWorld {
        self.world
            .get_or_insert_with(|| Arc::new(Mutex::new(crate::sim::World::new(self.station))))
            .clone()
    }
}

type TableBuilder = fn(&mut Context<'_>, &Settings) -> Result<Box<dyn TableDriver>, DriverError>;
type ImuBuilder = fn(&mut Context<'_>, &Settings) -> Result<Box<dyn ImuDriver>, DriverError>;

/// How a kind is built: its table and IMU builders (`None`: the kind cannot drive that
/// device).
#[derive(Clone, Copy)]
pub struct Builders {
    /// Builds the table driver, if the kind can drive a table.
    pub table: Option<TableBuilder>,
    /// Builds the IMU driver, if the kind can read an IMU.
    pub imu: Option<ImuBuilder>,
}

/// The builders of a kind.
pub fn builders(kind: &DriverKind) -> Builders {
    match kind.name {
        "sim" => Builders {
            table: Some(|c, _| Ok(Box::new(SimTable::new(c.station, c.world(), c.seed)))),
            imu: Some(sim_imu),
        },
        "tcp" | "serial" => Builders {
            table: Some(link_table),
            imu: Some(framed_imu),
        },
        "replay" => Builders {
            table: Some(|c, s| {
                let dir = required(s.recording.as_ref(), "recording")?;
                Ok(Box::new(crate::replay::ReplayTable::open(dir, c.station)?))
            }),
            imu: Some(|c, s| {
                let dir = required(s.recording.as_ref(), "recording")?;
                Ok(Box::new(crate::replay::ReplayImu::open(dir, c.station)?))
            }),
        },
        "manual" => Builders {
            table: Some(manual_table),
            imu: None,
        },
        "hand" => Builders {
            table: Some(|c, _| Ok(Box::new(HandTable::new(c.station, c.hand(), true)))),
            imu: None,
        },
        _ => Builders {
            table: None,
            imu: None,
        },
    }
}

/// A required setting (the station loader checked it: missing is an internal error).
fn required<'a>(v: Option<&'a String>, key: &str) -> Result<&'a String, DriverError> {
    v.ok_or_else(|| {
        DriverError::new(
            DriverErrorKind::InvalidCommand,
            format!("internal: the driver was built without its `{key}`"),
        )
    })
}

/// A manual station's table: the operator; with a simulated IMU, a simulated operator
/// in real time (its prompts shown to a person, the hand simulated).
fn manual_table(c: &mut Context<'_>, _: &Settings) -> Result<Box<dyn TableDriver>, DriverError> {
    if c.station.imu.driver.kind.name == "sim" {
        return Ok(Box::new(HandTable::new(c.station, c.hand(), false)));
    }
    Ok(Box::new(ManualTable::new(c.station, c.start)))
}

fn sim_imu(c: &mut Context<'_>, _: &Settings) -> Result<Box<dyn ImuDriver>, DriverError> {
    let table = c.station.table.driver.kind;
    if table.operator {
        let simulated = table.simulated;
        return Ok(Box::new(HandImu::new(
            c.station,
            c.hand(),
            c.seed,
            simulated,
        )));
    }
    if !c.station.table.driver.kind.simulated {
        return Err(DriverError::new(
            DriverErrorKind::InvalidCommand,
            "the simulated IMU senses the simulated table's motion: it needs `table.driver: sim`",
        ));
    }
    Ok(Box::new(SimImu::new(c.station, c.world(), c.seed)))
}

/// A TCP address or a serial port, whichever the settings name.
fn endpoint(s: &Settings) -> Result<Endpoint, DriverError> {
    match (&s.address, &s.port) {
        (Some(a), _) => Ok(Endpoint::Tcp(a.clone())),
        (None, p) => Ok(Endpoint::Serial(
            required(p.as_ref(), "port")?.clone(),
            s.baud(),
        )),
    }
}

fn link_table(c: &mut Context<'_>, s: &Settings) -> Result<Box<dyn TableDriver>, DriverError> {
    let endpoint = endpoint(s)?;
    let spec = &c.station.table;
    let info = TableInfo {
        model: spec.model.clone(),
        max_rate_dps: spec.max_rate.0,
        max_accel_dps2: spec.max_accel_dps2,
        feedback_hz: spec.feedback_rate.0,
        simulated: false,
    };
    Ok(Box::new(LinkTable::new(
        endpoint,
        info,
        s.timeout_s(),
        c.start,
    )))
}

fn framed_imu(c: &mut Context<'_>, s: &Settings) -> Result<Box<dyn ImuDriver>, DriverError> {
    let endpoint = endpoint(s)?;
    let info = c.station.imu.info(false);
    let timeout = Duration::from_secs_f64(s.timeout_s());
    Ok(Box::new(FramedImu::spawn(endpoint, info, timeout, c.start)))
}

/// Whether both of a station's drivers are simulations (the run may use virtual time).
pub fn simulated(station: &Station) -> bool {
    station.simulated()
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
        hand: None,
    };
    let (table, imu) = (&station.table.driver, &station.imu.driver);
    let no = |what: &str, k: &DriverKind| {
        DriverError::new(
            DriverErrorKind::InvalidCommand,
            format!("the `{}` driver cannot run {what}", k.name),
        )
    };
    let table = builders(table.kind)
        .table
        .ok_or_else(|| no("a table", table.kind))?(&mut ctx, &table.settings)?;
    let imu = builders(imu.kind)
        .imu
        .ok_or_else(|| no("an IMU", imu.kind))?(&mut ctx, &imu.settings)?;
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
            assert!(builders(s.table.driver.kind).table.is_some());
            assert!(builders(s.imu.driver.kind).imu.is_some());
            assert!(!simulated(&s));
        }
        assert!(simulated(&Station::default_sim()));
    }

    #[test]
    fn every_kind_has_its_builders() {
        // A manual station's operator is its table: its IMU is read by another driver.
        for k in DRIVERS.iter().filter(|k| !k.operator) {
            let b = builders(k);
            assert!(b.table.is_some() && b.imu.is_some(), "{}", k.name);
        }
    }
}
