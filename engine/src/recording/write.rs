//! Streaming writer of a recording folder (`spec/recording-format.md`): `imu.csv` and
//! `table.csv` are appended sample by sample through a fixed-size buffer that is hashed as
//! it is flushed, so memory stays bounded however long the run and the files' SHA-256 are
//! known at the end without reading them back. `manifest.yaml` is rewritten atomically at
//! every checkpoint (segment end, abort, end of run), and `journal.jsonl` gets one JSON
//! line per event.

use super::{FORMAT, Manifest};
use ratecal_drivers::{ImuSample, TableSample};
use sha2::{Digest, Sha256};
use std::fs::{File, OpenOptions};
use std::io::{self, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

/// Header of `imu.csv` (the `temp` column is written only when the IMU reports it).
const IMU_HEADER: &str = "t,ax,ay,az,gx,gy,gz";
/// Header of `table.csv` (the `ambient` column is written only when the station measures it).
const TABLE_HEADER: &str = "t,outer,inner,outer_rate,inner_rate";
/// Flush threshold of a stream buffer, bytes.
const CHUNK: usize = 1 << 16;

/// Decimals written per quantity: 1 us for time, 1e-6 m/s^2, 1e-7 deg/s and deg, 1e-4 degC.
const T_DEC: u32 = 6;
const ACCEL_DEC: u32 = 6;
const GYRO_DEC: u32 = 7;
const ANGLE_DEC: u32 = 7;
const TEMP_DEC: u32 = 4;

/// Which optional columns the streams carry (fixed for the whole recording).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Columns {
    /// `imu.csv` has a `temp` column.
    pub imu_temp: bool,
    /// `table.csv` has an `ambient` column.
    pub ambient: bool,
}

/// One CSV stream: an append-only file, a byte buffer, and the running hash of the file.
struct Stream {
    file: File,
    buf: Vec<u8>,
    hash: Sha256,
    last_t: Option<f64>,
}

impl Stream {
    fn create(path: &Path, header: &str) -> io::Result<Self> {
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
    fn append(path: &Path) -> io::Result<(Self, String)> {
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

    fn sync(&mut self) -> io::Result<()> {
        self.flush()?;
        self.file.flush()
    }

    fn sha256(&self) -> String {
        hex::encode(self.hash.clone().finalize())
    }
}

/// Writes a recording folder incrementally. Sample times handed in are already on the
/// recording's clock (0 at the start of the run). Samples the format cannot hold are
/// dropped and counted: a time that does not strictly increase, or a non-finite value (a
/// faulty IMU's NaN output; the format refuses non-numeric cells).
pub struct RecordingWriter {
    dir: PathBuf,
    imu: Stream,
    table: Stream,
    journal: File,
    columns: Columns,
    manifest: Manifest,
    dropped: u64,
}

impl RecordingWriter {
    /// Creates `dir` (if needed) and the recording's files; writes the manifest once.
    pub fn create(dir: &Path, manifest: Manifest, columns: Columns) -> io::Result<Self> {
        std::fs::create_dir_all(dir)?;
        let mut imu_header = IMU_HEADER.to_string();
        if columns.imu_temp {
            imu_header.push_str(",temp");
        }
        let mut table_header = TABLE_HEADER.to_string();
        if columns.ambient {
            table_header.push_str(",ambient");
        }
        let imu = Stream::create(&dir.join("imu.csv"), &imu_header)?;
        let table = Stream::create(&dir.join("table.csv"), &table_header)?;
        let journal = File::create(dir.join("journal.jsonl"))?;
        let mut w = RecordingWriter {
            dir: dir.to_path_buf(),
            imu,
            table,
            journal,
            columns,
            manifest,
            dropped: 0,
        };
        w.manifest.format = FORMAT.to_string();
        w.checkpoint()?;
        Ok(w)
    }

    /// Reopens an interrupted recording to continue it (`run --resume`): streams and journal
    /// are appended to, the manifest is read back. Returns the writer and the last time
    /// stamp found in either stream (`None` when both are empty).
    pub fn append(dir: &Path) -> io::Result<(Self, Option<f64>)> {
        let text = std::fs::read_to_string(dir.join("manifest.yaml"))?;
        let manifest: Manifest = serde_saphyr::from_str(&text).map_err(|e| {
            io::Error::new(io::ErrorKind::InvalidData, format!("manifest.yaml: {e}"))
        })?;
        let (imu, imu_header) = Stream::append(&dir.join("imu.csv"))?;
        let (table, table_header) = Stream::append(&dir.join("table.csv"))?;
        let columns = Columns {
            imu_temp: imu_header.split(',').any(|c| c == "temp"),
            ambient: table_header.split(',').any(|c| c == "ambient"),
        };
        let journal = OpenOptions::new()
            .append(true)
            .create(true)
            .open(dir.join("journal.jsonl"))?;
        let last = match (imu.last_t, table.last_t) {
            (Some(a), Some(b)) => Some(a.max(b)),
            (a, b) => a.or(b),
        };
        let w = RecordingWriter {
            dir: dir.to_path_buf(),
            imu,
            table,
            journal,
            columns,
            manifest,
            dropped: 0,
        };
        Ok((w, last))
    }

    /// The folder being written.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Optional columns of the streams.
    pub fn columns(&self) -> Columns {
        self.columns
    }

    /// The manifest as it stands (segments so far, run status).
    pub fn manifest(&self) -> &Manifest {
        &self.manifest
    }

    /// Mutable manifest; call [`RecordingWriter::checkpoint`] to persist changes.
    pub fn manifest_mut(&mut self) -> &mut Manifest {
        &mut self.manifest
    }

    /// Samples dropped because their time did not increase.
    pub fn dropped(&self) -> u64 {
        self.dropped
    }

    /// Appends IMU samples (times on the recording clock).
    pub fn write_imu(&mut self, samples: &[ImuSample]) -> io::Result<()> {
        for s in samples {
            let temp_ok = !self.columns.imu_temp || s.temp_c.is_some_and(f64::is_finite);
            let finite = s.accel.iter().chain(&s.gyro).all(|v| v.is_finite()) && temp_ok;
            if self.imu.last_t.is_some_and(|l| s.t <= l) || !s.t.is_finite() || !finite {
                self.dropped += 1;
                continue;
            }
            self.imu.last_t = Some(s.t);
            let b = &mut self.imu.buf;
            push_fixed(b, s.t, T_DEC);
            for v in s.accel {
                b.push(b',');
                push_fixed(b, v, ACCEL_DEC);
            }
            for v in s.gyro {
                b.push(b',');
                push_fixed(b, v, GYRO_DEC);
            }
            if self.columns.imu_temp {
                b.push(b',');
                push_fixed(b, s.temp_c.unwrap_or(f64::NAN), TEMP_DEC);
            }
            self.imu.end_row()?;
        }
        Ok(())
    }

    /// Appends table feedback samples (times on the recording clock).
    pub fn write_table(&mut self, samples: &[TableSample]) -> io::Result<()> {
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
            let b = &mut self.table.buf;
            push_fixed(b, s.t, T_DEC);
            for v in [s.outer_deg, s.inner_deg, s.outer_rate_dps, s.inner_rate_dps] {
                b.push(b',');
                push_fixed(b, v, ANGLE_DEC);
            }
            if self.columns.ambient {
                b.push(b',');
                push_fixed(b, s.ambient_c.unwrap_or(f64::NAN), TEMP_DEC);
            }
            self.table.end_row()?;
        }
        Ok(())
    }

    /// Appends one line to `journal.jsonl` (written through at once: the journal is what
    /// `--resume` trusts).
    pub fn write_journal_line(&mut self, line: &str) -> io::Result<()> {
        let mut l = String::with_capacity(line.len() + 1);
        l.push_str(line);
        l.push('\n');
        self.journal.write_all(l.as_bytes())
    }

    /// Flushes both streams to the OS and rewrites the manifest atomically
    /// (`manifest.yaml.tmp` then rename).
    pub fn checkpoint(&mut self) -> io::Result<()> {
        self.imu.sync()?;
        self.table.sync()?;
        let yaml = manifest_yaml(&self.manifest)?;
        let tmp = self.dir.join("manifest.yaml.tmp");
        std::fs::write(&tmp, yaml)?;
        std::fs::rename(&tmp, self.dir.join("manifest.yaml"))
    }

    /// Ends the recording: records the SHA-256 of each data file in `run.files_sha256`,
    /// sets `run.ended`, and writes the final manifest.
    pub fn finish(&mut self) -> io::Result<()> {
        self.imu.sync()?;
        self.table.sync()?;
        self.journal.flush()?;
        let imu = self.imu.sha256();
        let table = self.table.sha256();
        if let Some(run) = self.manifest.run.as_mut() {
            run.files_sha256.insert("imu.csv".into(), imu);
            run.files_sha256.insert("table.csv".into(), table);
            run.ended = Some(rfc3339(std::time::SystemTime::now()));
        }
        self.checkpoint()
    }
}

/// Serializes a manifest the way ratecal writes it.
pub fn manifest_yaml(m: &Manifest) -> io::Result<String> {
    serde_saphyr::to_string(m).map_err(|e| io::Error::other(format!("manifest: {e}")))
}

/// Lowercase hex SHA-256 of bytes.
pub fn sha256_hex(bytes: &[u8]) -> String {
    hex::encode(Sha256::digest(bytes))
}

/// Formats a wall-clock time as RFC 3339 in UTC (`2026-11-03T14:05:09Z`).
pub fn rfc3339(t: std::time::SystemTime) -> String {
    let secs = t
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs())
        .unwrap_or(0) as i64;
    let (days, sod) = (secs.div_euclid(86_400), secs.rem_euclid(86_400));
    // Civil date from days since 1970-01-01 (H. Hinnant's algorithm).
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!(
        "{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}Z",
        sod / 3600,
        sod % 3600 / 60,
        sod % 60
    )
}

/// Appends `x` with exactly `dec` decimals (rounded half away from zero); non-finite values
/// are written `NaN`, `inf`, `-inf` (so that a reader refuses them, naming the cell).
pub fn push_fixed(buf: &mut Vec<u8>, x: f64, dec: u32) {
    let scale = 10f64.powi(dec as i32);
    let scaled = (x * scale).round();
    if !x.is_finite() {
        buf.extend_from_slice(if x.is_nan() {
            b"NaN"
        } else if x > 0.0 {
            b"inf"
        } else {
            b"-inf"
        });
        return;
    }
    if scaled.abs() >= 9.0e18 {
        // Beyond i64: fall back to the shortest exact representation.
        let mut r = ryu::Buffer::new();
        buf.extend_from_slice(r.format_finite(x).as_bytes());
        return;
    }
    let n = scaled as i64;
    if n < 0 {
        buf.push(b'-');
    }
    let n = n.unsigned_abs();
    let p = 10u64.pow(dec);
    push_uint(buf, n / p);
    if dec > 0 {
        buf.push(b'.');
        let frac = n % p;
        let mut digits = [b'0'; 20];
        let mut f = frac;
        for i in (0..dec as usize).rev() {
            digits[i] = b'0' + (f % 10) as u8;
            f /= 10;
        }
        buf.extend_from_slice(&digits[..dec as usize]);
    }
}

fn push_uint(buf: &mut Vec<u8>, mut n: u64) {
    let mut digits = [0u8; 20];
    let mut i = digits.len();
    loop {
        i -= 1;
        digits[i] = b'0' + (n % 10) as u8;
        n /= 10;
        if n == 0 {
            break;
        }
    }
    buf.extend_from_slice(&digits[i..]);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fixed(x: f64, dec: u32) -> String {
        let mut b = Vec::new();
        push_fixed(&mut b, x, dec);
        String::from_utf8(b).unwrap()
    }

    #[test]
    fn fixed_matches_std_formatting() {
        for &x in &[
            0.0,
            1.5,
            -0.25,
            9.80665,
            -123.456789012,
            1e-7,
            -4e-7,
            5700.000001,
            359.9999999,
        ] {
            for dec in [0u32, 4, 6, 7] {
                let text = fixed(x, dec);
                let ours: f64 = text.parse().unwrap();
                // Rounded to the nearest step (ties may go either way), with exactly `dec` decimals.
                assert!(
                    (ours - x).abs() <= 0.5 * 10f64.powi(-(dec as i32)) * (1.0 + 1e-9),
                    "{x} {dec}: {text}"
                );
                assert_eq!(text.split('.').nth(1).map_or(0, str::len), dec as usize);
            }
        }
        assert_eq!(fixed(-0.0000001, 6), "0.000000");
        assert_eq!(fixed(f64::NAN, 6), "NaN");
        assert_eq!(fixed(1e300, 6), "1e300");
    }

    #[test]
    fn rfc3339_known_dates() {
        let t = |s: u64| rfc3339(std::time::UNIX_EPOCH + std::time::Duration::from_secs(s));
        assert_eq!(t(0), "1970-01-01T00:00:00Z");
        assert_eq!(t(951_782_400), "2000-02-29T00:00:00Z");
        assert_eq!(t(1_700_000_000), "2023-11-14T22:13:20Z");
    }
}
