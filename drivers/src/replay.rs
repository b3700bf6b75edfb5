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
use std::path::Path;
use tokio::time::Instant;

fn bad(msg: String) -> DriverError {
    DriverError::new(DriverErrorKind::Transport, msg)
}

/// Reads a CSV stream: for each row, the named columns (`None` for a missing optional one).
fn read_columns(
    path: &Path,
    required: &[&str],
    optional: &[&str],
) -> Result<Vec<Vec<Option<f64>>>, DriverError> {
    let shown = path.display();
    let mut rdr = csv::Reader::from_path(path).map_err(|e| bad(format!("{shown}: {e}")))?;
    let headers = rdr
        .headers()
        .map_err(|e| bad(format!("{shown}: {e}")))?
        .clone();
    let mut idx = Vec::new();
    for name in required {
        let i = headers.iter().position(|h| h.trim() == *name);
        idx.push(Some(
            i.ok_or_else(|| bad(format!("{shown}:1: no `{name}` column")))?,
        ));
    }
    for name in optional {
        idx.push(headers.iter().position(|h| h.trim() == *name));
    }
    let mut rows = Vec::new();
    let mut record = csv::StringRecord::new();
    let mut line = 1;
    while rdr
        .read_record(&mut record)
        .map_err(|e| bad(format!("{shown}: {e}")))?
    {
        line += 1;
        let mut row = Vec::with_capacity(idx.len());
        for i in &idx {
            let cell = match i {
                Some(i) => {
                    let text = record.get(*i).unwrap_or("").trim();
                    let v = text.parse::<f64>().map_err(|_| {
                        bad(format!(
                            "{shown}:{line}:{}: `{text}` is not a number",
                            i + 1
                        ))
                    })?;
                    Some(v)
                }
                None => None,
            };
            row.push(cell);
        }
        rows.push(row);
    }
    Ok(rows)
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
        let rows = read_columns(
            &Path::new(folder).join("table.csv"),
            &["t", "outer", "inner", "outer_rate", "inner_rate"],
            &["ambient"],
        )?;
        let t0 = rows.first().and_then(|r| r[0]).unwrap_or(0.0);
        let samples = rows
            .iter()
            .map(|r| TableSample {
                t: r[0].unwrap_or(0.0) - t0,
                outer_deg: r[1].unwrap_or(f64::NAN),
                inner_deg: r[2].unwrap_or(f64::NAN),
                outer_rate_dps: r[3].unwrap_or(f64::NAN),
                inner_rate_dps: r[4].unwrap_or(f64::NAN),
                ambient_c: r[5],
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
        let rows = read_columns(
            &dir.join("imu.csv"),
            &["t", "ax", "ay", "az", "gx", "gy", "gz"],
            &["temp"],
        )?;
        let t0 = read_columns(&dir.join("table.csv"), &["t"], &[])
            .ok()
            .and_then(|r| r.first().and_then(|r| r[0]))
            .or_else(|| rows.first().and_then(|r| r[0]))
            .unwrap_or(0.0);
        let v = |r: &[Option<f64>], i: usize| r[i].unwrap_or(f64::NAN);
        let samples = rows
            .iter()
            .map(|r| ImuSample {
                t: v(r, 0) - t0,
                accel: [v(r, 1), v(r, 2), v(r, 3)],
                gyro: [v(r, 4), v(r, 5), v(r, 6)],
                temp_c: r[7],
            })
            .collect();
        let imu = &station.imu;
        let info = ImuInfo {
            model: imu.model.clone(),
            serial: imu.serial.clone(),
            grade: imu.grade.clone(),
            sample_hz: imu.sample_rate.0,
            accel_range_mps2: imu.accel_range.0,
            gyro_range_dps: imu.gyro_range.0,
            simulated: true,
        };
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
