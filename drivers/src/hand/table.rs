//! The manual station's table: no motion, no feedback worth the name (zeros at a low
//! rate, so that the streams stay alive), and the operator's requests.

use super::SharedHand;
use crate::station::Station;
use crate::{
    DriverError, DriverErrorKind, OperatorAsk, TableCommand, TableDriver, TableInfo, TableSample,
};
use async_trait::async_trait;
use tokio::time::Instant;

/// Rate of the (empty) feedback stream, Hz.
const FEEDBACK_HZ: f64 = 10.0;

fn info(station: &Station, simulated: bool) -> TableInfo {
    TableInfo {
        model: station.table.model.clone(),
        max_rate_dps: 0.0,
        max_accel_dps2: 0.0,
        feedback_hz: FEEDBACK_HZ,
        simulated,
    }
}

fn refuse(cmd: &TableCommand) -> Result<(), DriverError> {
    match cmd {
        // Nothing moves by itself: a safe stop has nothing to stop.
        TableCommand::SafeStop => Ok(()),
        _ => Err(DriverError::new(
            DriverErrorKind::InvalidCommand,
            "a manual station has no rate table to move",
        )),
    }
}

/// Zero feedback samples from `next_k` up to `now`.
fn zeros(next_k: &mut u64, now: f64, out: &mut Vec<TableSample>) {
    loop {
        let t = *next_k as f64 / FEEDBACK_HZ;
        if t > now {
            break;
        }
        *next_k += 1;
        out.push(TableSample {
            t,
            outer_deg: 0.0,
            inner_deg: 0.0,
            outer_rate_dps: 0.0,
            inner_rate_dps: 0.0,
            ambient_c: None,
            t_host: None,
        });
    }
}

/// The table of a manual station with a real operator: it reads the prompts the
/// interpreter shows.
#[derive(Debug)]
pub struct ManualTable {
    info: TableInfo,
    start: Instant,
    next_k: u64,
}

impl ManualTable {
    /// The manual table of a station, its clock starting at `start`.
    pub fn new(station: &Station, start: Instant) -> Self {
        ManualTable {
            info: info(station, false),
            start,
            next_k: 0,
        }
    }
}

#[async_trait]
impl TableDriver for ManualTable {
    fn info(&self) -> TableInfo {
        self.info.clone()
    }

    async fn command(&mut self, cmd: TableCommand) -> Result<(), DriverError> {
        refuse(&cmd)
    }

    async fn read(&mut self, out: &mut Vec<TableSample>) -> Result<(), DriverError> {
        zeros(&mut self.next_k, self.start.elapsed().as_secs_f64(), out);
        Ok(())
    }

    async fn ask(&mut self, _ask: OperatorAsk) -> Result<(), DriverError> {
        Ok(())
    }
}

/// The table of a manual station whose operator is simulated.
#[derive(Debug)]
pub struct HandTable {
    info: TableInfo,
    hand: SharedHand,
    next_k: u64,
}

impl HandTable {
    /// The simulated operator's table; `simulated` is false when the run keeps real time
    /// (a manual station with a simulated IMU, its prompts shown to a person).
    pub fn new(station: &Station, hand: SharedHand, simulated: bool) -> Self {
        HandTable {
            info: info(station, simulated),
            hand,
            next_k: 0,
        }
    }

    fn lock(&self) -> Result<std::sync::MutexGuard<'_, super::HandWorld>, DriverError> {
        self.hand.lock().map_err(|_| {
            DriverError::new(DriverErrorKind::Instrument, "simulated hand state poisoned")
        })
    }
}

#[async_trait]
impl TableDriver for HandTable {
    fn info(&self) -> TableInfo {
        self.info.clone()
    }

    async fn command(&mut self, cmd: TableCommand) -> Result<(), DriverError> {
        refuse(&cmd)
    }

    async fn read(&mut self, out: &mut Vec<TableSample>) -> Result<(), DriverError> {
        let now = self.lock()?.now();
        zeros(&mut self.next_k, now, out);
        Ok(())
    }

    async fn ask(&mut self, ask: OperatorAsk) -> Result<(), DriverError> {
        self.lock()?.ask(ask);
        Ok(())
    }
}
