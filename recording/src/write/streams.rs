//! The two CSV streams of a recording, formatted, hashed as they are flushed, and written.
//! They live on a writer thread (see `write.rs`), so the interpreter's loop only hands
//! sample batches over.

use super::fixed::Line;
use crate::{ImuSample, TableSample};
use sha2::{Digest, Sha256};
use std::fs::{File, OpenOptions};
use std::io::{self, Read, Seek, SeekFrom, Write};
use std::path::Path;

/// Header of `imu.csv` (the `temp` column is written only when the IMU reports it).
pub(crate) const IMU_HEADER: &str = "t,ax,ay,az,gx,gy,gz";
/// Header of `table.csv` (the `ambient` column is written only when the station measures it).
pub(crate) const TABLE_HEADER: &str = "t,outer,inner,outer_rate,inner_rate";
/// Flush threshold of a stream buffer, bytes.
const CHUNK: usize = 1 << 16;

/// Decimals written per quantity: 1 us for time, 1e-6 m/s^2, 1e-7 deg/s and deg, 1e-4 degC.
const T_DEC: usize = 6;
const ACCEL_DEC: usize = 6;
const GYRO_DEC: usize = 7;
const ANGLE_DEC: usize = 7;
const TEMP_DEC: usize = 4;

/// Which optional columns the streams carry (fixed for the whole recording).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Columns {
    /// `imu.csv` has a `temp` column.
    pub imu_temp: bool,
    /// `table.csv` has an `ambient` column.
    pub ambient: bool,
    /// `imu.csv` has a `t_host` column (host arrival times: hardware links).
    pub imu_t_host: bool,
    /// `table.csv` has a `t_host` column.
    pub table_t_host: bool,
}

impl Columns {
    /// The header line of `imu.csv` (without the newline).
    pub(crate) fn imu_header(&self) -> String {
        let mut h = IMU_HEADER.to_string();
        if self.imu_temp {
            h.push_str(",temp");
        }
        if self.imu_t_host {
            h.push_str(",t_host");
        }
        h
    }

    /// The header line of `table.csv` (without the newline).
    pub(crate) fn table_header(&self) -> String {
        let mut h = TABLE_HEADER.to_string();
        if self.ambient {
            h.push_str(",ambient");
        }
        if self.table_t_host {
            h.push_str(",t_host");
        }
        h
    }

    /// The optional columns a pair of headers carries (a recording being continued).
    pub(crate) fn of_headers(imu: &str, table: &str) -> Self {
        let has = |h: &str, c: &str| h.split(',').any(|n| n.trim() == c);
        Columns {
            imu_temp: has(imu, "temp"),
            ambient: has(table, "ambient"),
            imu_t_host: has(imu, "t_host"),
            table_t_host: has(table, "t_host"),
        }
    }
}

/// Appends a `t_host` cell: empty when a sample does not carry it (a column of host times
/// is only asked for hardware links, which always stamp their samples).
fn t_host_cell(l: &mut Line, t_host: Option<f64>) {
    l.byte(b',');
    if let Some(h) = t_host.filter(|h| h.is_finite()) {
        l.fixed::<T_DEC>(h);
    }
}

/// One CSV stream: an append-only file, a byte buffer, and the running hash of the file.
pub(crate) struct Stream {
    file: File,
    buf: Vec<u8>,
    hash: Sha256,
    pub(crate) last_t: Option<f64>,
}

impl Stream {
    pub(crate) fn create(path: &Path, header: &str) -> io::Result<Self> {
        let file = File::create(path)?;
        let mut s = Stream {
            file,
            buf: Vec::with_capacity(CHUNK + 512),
            hash: Sha256::new(),
            last_t: None,
        };
        s.buf.extend_from_slice(header.as_bytes());
        s.buf.push(b'\n');
        Ok(s)
    }

    /// Reopens a stream for appending: drops a torn last line (a crash mid-write), hashes
    /// what is kept, and finds the last time stamp.
    pub(crate) fn append(path: &Path) -> io::Result<(Self, String)> {
        let mut file = OpenOptions::new().read(true).write(true).open(path)?;
        let mut text = Vec::new();
        file.read_to_end(&mut text)?;
        let keep = text.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
        text.truncate(keep);
        file.set_len(keep as u64)?;
        file.seek(SeekFrom::End(0))?;
        let header = text.split(|&b| b == b'\n').next().unwrap_or_default();
        let header = String::from_utf8_lossy(header).into_owned();
        let last_t = text
            .split(|&b| b == b'\n')
            .filter(|l| !l.is_empty())
            .skip(1)
            .last()
            .and_then(|l| l.split(|&b| b == b',').next())
            .and_then(|c| std::str::from_utf8(c).ok()?.parse::<f64>().ok());
        let mut hash = Sha256::new();
        hash.update(&text);
        let s = Stream {
            file,
            buf: Vec::with_capacity(CHUNK + 512),
            hash,
            last_t,
        };
        Ok((s, header))
    }

    fn end_row(&mut self) -> io::Result<()> {
        self.buf.push(b'\n');
        if self.buf.len() >= CHUNK {
            self.flush()?;
        }
        Ok(())
    }

    fn flush(&mut self) -> io::Result<()> {
        if !self.buf.is_empty() {
            self.hash.update(&self.buf);
            self.file.write_all(&self.buf)?;
            self.buf.clear();
        }
        Ok(())
    }

    pub(crate) fn sync(&mut self) -> io::Result<()> {
        self.flush()?;
        self.file.flush()
    }

    pub(crate) fn sha256(&self) -> String {
        hex::encode(self.hash.clone().finalize())
    }
}

/// Both streams and the count of samples the format could not hold.
pub(crate) struct Streams {
    pub imu: Stream,
    pub table: Stream,
    pub columns: Columns,
    pub dropped: u64,
    /// IMU values written in their shortest exact form instead of fixed decimals.
    pub exact: bool,
}

impl Streams {
    /// Appends IMU samples (times on the recording clock).
    pub(crate) fn write_imu(&mut self, samples: &[ImuSample]) -> io::Result<()> {
        for s in samples {
            let temp_ok = !self.columns.imu_temp || s.temp_c.is_some_and(f64::is_finite);
            let finite = s.accel.iter().chain(&s.gyro).all(|v| v.is_finite()) && temp_ok;
            if self.imu.last_t.is_some_and(|l| s.t <= l) || !s.t.is_finite() || !finite {
                self.dropped += 1;
                continue;
            }
            self.imu.last_t = Some(s.t);
            let mut l = Line::new();
            if self.exact {
                l.shortest(s.t);
                for v in s.accel.into_iter().chain(s.gyro) {
                    l.byte(b',');
                    l.shortest(v);
                }
            } else {
                l.fixed::<T_DEC>(s.t);
                for v in s.accel {
                    l.byte(b',');
                    l.fixed::<ACCEL_DEC>(v);
                }
                for v in s.gyro {
                    l.byte(b',');
                    l.fixed::<GYRO_DEC>(v);
                }
            }
            if self.columns.imu_temp {
                l.byte(b',');
                l.fixed::<TEMP_DEC>(s.temp_c.unwrap_or(f64::NAN));
            }
            if self.columns.imu_t_host {
                t_host_cell(&mut l, s.t_host);
            }
            self.imu.buf.extend_from_slice(l.as_bytes());
            self.imu.end_row()?;
        }
        Ok(())
    }

    /// Appends table feedback samples (times on the recording clock).
    pub(crate) fn write_table(&mut self, samples: &[TableSample]) -> io::Result<()> {
        for s in samples {
            let ambient_ok = !self.columns.ambient || s.ambient_c.is_some_and(f64::is_finite);
            let finite = [s.outer_deg, s.inner_deg, s.outer_rate_dps, s.inner_rate_dps]
                .iter()
                .all(|v| v.is_finite());
            if self.table.last_t.is_some_and(|l| s.t <= l)
                || !s.t.is_finite()
                || !finite
                || !ambient_ok
            {
                self.dropped += 1;
                continue;
            }
            self.table.last_t = Some(s.t);
            let mut l = Line::new();
            l.fixed::<T_DEC>(s.t);
            for v in [s.outer_deg, s.inner_deg, s.outer_rate_dps, s.inner_rate_dps] {
                l.byte(b',');
                l.fixed::<ANGLE_DEC>(v);
            }
            if self.columns.ambient {
                l.byte(b',');
                l.fixed::<TEMP_DEC>(s.ambient_c.unwrap_or(f64::NAN));
            }
            if self.columns.table_t_host {
                t_host_cell(&mut l, s.t_host);
            }
            self.table.buf.extend_from_slice(l.as_bytes());
            self.table.end_row()?;
        }
        Ok(())
    }
}
