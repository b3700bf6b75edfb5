//! Replays the streams of a recording folder (recording-format.md) in time, as if a
//! station were producing them: every sample whose time (shifted so that the recording
//! starts at 0) is <= now. The table accepts commands and ignores them: it does what the
//! recording did.

use crate::station::Station;
use crate::{
    DriverError, DriverErrorKind, ImuDriver, ImuInfo, ImuSample, TableCommand, TableDriver,
    TableInfo, TableSample,
};
use async_trait::async_trait;
use ratecal_recording::{RecordingError, read_imu, read_table};
use std::path::Path;
use tokio::time::Instant;

/// A stream the recording crate refused, as a driver error (its message names the file,
/// line and column).
fn bad(e: RecordingError) -> DriverError {
    DriverError::new(DriverErrorKind::Transport, e.to_string())
}

/// A stream of samples replayed against the tokio clock.
#[derive(Debug)]
struct Replayer<T> {
    samples: Vec<T>,
    next: usize,
    start: Instant,
}

impl<T: Copy> Replayer<T> {
    fn drain(&mut self, time: impl Fn(&T) -> f64, out: &mut Vec<T>) {
        let now = self.start.elapsed().as_secs_f64();
        while self.next < self.samples.len() && time(&self.samples[self.next]) <= now {
            out.push(self.samples[self.next]);
            self.next += 1;
        }
    }
}

/// The table stream of a recording, replayed.
#[derive(Debug)]
pub struct ReplayTable {
    info: TableInfo,
    stream: Replayer<TableSample>,
}

impl ReplayTable {
    /// Opens `folder/table.csv`.
    pub fn open(folder: &str, station: &Station) -> Result<Self, DriverError> {
        let s = read_table(&Path::new(folder).join("table.csv")).map_err(bad)?;
        let t0 = s.t.first().copied().unwrap_or(0.0);
        let samples = (0..s.t.len())
            .map(|i| TableSample {
                t: s.t[i] - t0,
                outer_deg: s.outer[i],
                inner_deg: s.inner[i],
                outer_rate_dps: s.outer_rate[i],
                inner_rate_dps: s.inner_rate[i],
                ambient_c: s.ambient.as_ref().map(|a| a[i]),
                t_host: None,
            })
            .collect();
        let t = &station.table;
        let info = TableInfo {
            model: format!("replay of {folder}"),
            max_rate_dps: t.max_rate.0,
            max_accel_dps2: t.max_accel_dps2,
            feedback_hz: t.feedback_rate.0,
            simulated: true,
        };
        Ok(ReplayTable {
            info,
            stream: Replayer {
                samples,
                next: 0,
                start: Instant::now(),
            },
        })
    }
}

#[async_trait]
impl TableDriver for ReplayTable {
    fn info(&self) -> TableInfo {
        self.info.clone()
    }

    async fn command(&mut self, _cmd: TableCommand) -> Result<(), DriverError> {
        Ok(())
    }

    async fn read(&mut self, out: &mut Vec<TableSample>) -> Result<(), DriverError> {
        self.stream.drain(|s| s.t, out);
        Ok(())
    }
}

/// The IMU stream of a recording, replayed.
#[derive(Debug)]
pub struct ReplayImu {
    info: ImuInfo,
    stream: Replayer<ImuSample>,
}

impl ReplayImu {
    /// Opens `folder/imu.csv`. Times are shifted by the table stream's first time when
    /// there is one, so that both streams keep their common clock.
    pub fn open(folder: &str, station: &Station) -> Result<Self, DriverError> {
        let dir = Path::new(folder);
        let s = read_imu(&dir.join("imu.csv")).map_err(bad)?;
        let t0 = read_table(&dir.join("table.csv"))
            .ok()
            .and_then(|table| table.t.first().copied())
            .or_else(|| s.t.first().copied())
            .unwrap_or(0.0);
        let row = |c: &[Vec<f64>; 3], i: usize| [c[0][i], c[1][i], c[2][i]];
        let samples = (0..s.t.len())
            .map(|i| ImuSample {
                t: s.t[i] - t0,
                accel: row(&s.accel, i),
                gyro: row(&s.gyro, i),
                temp_c: s.temp.as_ref().map(|c| c[i]),
                t_host: None,
            })
            .collect();
        let info = station.imu.info(true);
        Ok(ReplayImu {
            info,
            stream: Replayer {
                samples,
                next: 0,
                start: Instant::now(),
            },
        })
    }
}

#[async_trait]
impl ImuDriver for ReplayImu {
    fn info(&self) -> ImuInfo {
        self.info.clone()
    }

    async fn read(&mut self, out: &mut Vec<ImuSample>) -> Result<(), DriverError> {
        self.stream.drain(|s| s.t, out);
        Ok(())
    }
}
