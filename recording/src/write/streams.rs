//! The two CSV streams of a recording, formatted, hashed as they are flushed, and written.
//! They live on a writer thread (see `write.rs`), so the interpreter's loop only hands
//! sample batches over.

use super::fixed::Line;
use super::writeback::{WRITEBACK, Writeback};
use crate::chain::{BlockRecord, CHAIN_START, Chain, check_stream};
use crate::{ImuSample, TableSample, WriteFailure};
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

/// One CSV stream: an append-only file, a byte buffer, the running hash of the file and its
/// chain of blocks (recorded in the journal).
pub(crate) struct Stream {
    name: String,
    file: File,
    buf: Vec<u8>,
    hash: Sha256,
    chain: Chain,
    /// The chain is kept (its blocks recorded in the journal); off for a caller that keeps
    /// no journal (an import), where it would be hashing for nothing.
    pub(crate) chained: bool,
    written: u64,
    /// The early syncs of the file (`None` if its thread could not start) and the length
    /// at the last one asked for.
    writeback: Option<(Writeback, u64)>,
    pub(crate) last_t: Option<f64>,
    /// The stamp of the last row on disk (what a failed write leaves).
    written_t: Option<f64>,
    /// The first write that failed: the stream takes no more.
    pub(crate) failure: Option<WriteFailure>,
}

impl Stream {
    fn new(path: &Path, file: File, hash: Sha256, chain: Chain, written: u64) -> Self {
        Stream {
            name: file_name(path),
            file,
            buf: Vec::with_capacity(CHUNK + 512),
            hash,
            chain,
            chained: true,
            written,
            writeback: Writeback::start(path).map(|w| (w, written)),
            last_t: None,
            written_t: None,
            failure: None,
        }
    }

    pub(crate) fn create(path: &Path, header: &str) -> io::Result<Self> {
        let file = crate::commit::open_nofollow(path, true, false)?;
        let mut s = Self::new(path, file, Sha256::new(), Chain::new(CHAIN_START, 0), 0);
        s.buf.extend_from_slice(header.as_bytes());
        s.buf.push(b'\n');
        s.flush()?;
        Ok(s)
    }

    /// Reopens a stream for appending (`run --resume`), read streaming against its block
    /// records: refused when a recorded block is not as written; the bytes after the last
    /// record (a crash's unrecorded tail) are kept when `keep_tail` (a sealed folder vouches
    /// for them) and cut otherwise. A stream without records (an older ratecal's) keeps what
    /// it holds up to its last full line. Returns the stream, its header and the bytes cut.
    pub(crate) fn append(
        path: &Path,
        records: Option<&[BlockRecord]>,
        keep_tail: bool,
    ) -> io::Result<(Self, String, u64)> {
        let check = check_stream(path, records.unwrap_or_default())?
            .map_err(|why| io::Error::new(io::ErrorKind::InvalidData, why))?;
        let mut file =
            crate::commit::open_with_nofollow(OpenOptions::new().read(true).write(true), path)?;
        let header = first_line(&mut file)?;
        let (keep, cut) = if keep_tail {
            (check.size, 0)
        } else if records.is_none() {
            let end = last_newline_end(&mut file, check.size)?;
            (end, check.size - end)
        } else {
            (check.covered, check.tail())
        };
        if cut > 0 {
            file.set_len(keep)?;
            file.sync_all()?;
        }
        let (mut hash, mut chain) = (check.covered_hash, Chain::new(check.chain, check.covered));
        // What is kept beyond the records joins the file's hash and the open block.
        file.seek(SeekFrom::Start(check.covered))?;
        let mut rest = (&mut file).take(keep - check.covered);
        let mut b = vec![0u8; 1 << 16];
        loop {
            let n = rest.read(&mut b)?;
            if n == 0 {
                break;
            }
            hash.update(&b[..n]);
            chain.update(&b[..n]);
        }
        let last_t = last_time(&mut file, keep)?;
        file.seek(SeekFrom::End(0))?;
        let mut s = Self::new(path, file, hash, chain, keep);
        s.last_t = last_t;
        Ok((s, header, cut))
    }

    fn end_row(&mut self) -> io::Result<()> {
        self.buf.push(b'\n');
        if self.buf.len() >= CHUNK {
            self.flush()?;
        }
        Ok(())
    }

    /// Writes the buffer. A write that fails (a full disk, a file-size limit) leaves the
    /// file cut after its last full line, the failure kept, and the stream closed.
    fn flush(&mut self) -> io::Result<()> {
        if let Some(f) = &self.failure {
            return Err(io::Error::other(format!("{}: {}", f.file, f.error)));
        }
        if self.buf.is_empty() {
            return Ok(());
        }
        let mut done = 0;
        let failed = loop {
            if done == self.buf.len() {
                break None;
            }
            match self.file.write(&self.buf[done..]) {
                Ok(0) => break Some(io::Error::from(io::ErrorKind::WriteZero)),
                Ok(n) => done += n,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                Err(e) => break Some(e),
            }
        };
        // The buffer always starts on a row: cut back to the last full row written.
        let keep = match failed {
            None => done,
            Some(_) => self.buf[..done]
                .iter()
                .rposition(|&b| b == b'\n')
                .map_or(0, |i| i + 1),
        };
        self.hash.update(&self.buf[..keep]);
        if self.chained {
            self.chain.update(&self.buf[..keep]);
        }
        self.written += keep as u64;
        if let Some(t) = last_row_t(&self.buf[..keep]) {
            self.written_t = Some(t);
        }
        self.buf.clear();
        let Some(e) = failed else {
            if let Some((w, asked)) = &mut self.writeback
                && self.written - *asked >= WRITEBACK
            {
                w.ask();
                *asked = self.written;
            }
            return Ok(());
        };
        let cut = (done - keep) as u64;
        if cut > 0 {
            // Shrinking is allowed under a file-size limit and on a full disk.
            let _ = self.file.set_len(self.written);
        }
        let f = WriteFailure {
            file: self.name.clone(),
            error: e.to_string(),
            cut_bytes: cut,
            data_end_s: self.written_t,
        };
        let err = io::Error::new(e.kind(), format!("{}: {e}", f.file));
        self.failure = Some(f);
        Err(err)
    }

    /// Flushes to the OS; `durable`: also to the disk.
    pub(crate) fn sync(&mut self, durable: bool) -> io::Result<()> {
        self.flush()?;
        if durable {
            self.file.sync_data()?;
        }
        Ok(())
    }

    /// The block written since the last record, when it is due (a full chunk, or `force`).
    pub(crate) fn due_record(&mut self, force: bool) -> Option<(BlockRecord, f64)> {
        if !self.chained || (!force && self.chain.open_len() < CHUNK as u64) {
            return None;
        }
        let t = self.last_t.unwrap_or(0.0);
        self.chain.record(&self.name).map(|r| (r, t))
    }

    pub(crate) fn sha256(&self) -> String {
        hex::encode(self.hash.clone().finalize())
    }

    /// The file as written so far: its name, SHA-256 and length.
    pub(crate) fn written(&self) -> crate::WrittenFile {
        crate::WrittenFile {
            name: self.name.clone(),
            sha256: self.sha256(),
            len: self.written,
        }
    }
}

fn file_name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// The first line of a file (at most 64 KiB of it), without its newline.
fn first_line(file: &mut File) -> io::Result<String> {
    file.seek(SeekFrom::Start(0))?;
    let mut head = Vec::new();
    file.take(1 << 16).read_to_end(&mut head)?;
    let end = head.iter().position(|&b| b == b'\n').unwrap_or(head.len());
    Ok(String::from_utf8_lossy(&head[..end]).into_owned())
}

/// The end of the last full line within the first `size` bytes.
fn last_newline_end(file: &mut File, size: u64) -> io::Result<u64> {
    let mut end = size;
    while end > 0 {
        let from = end.saturating_sub(1 << 16);
        let mut b = vec![0u8; (end - from) as usize];
        file.seek(SeekFrom::Start(from))?;
        file.read_exact(&mut b)?;
        if let Some(i) = b.iter().rposition(|&x| x == b'\n') {
            return Ok(from + i as u64 + 1);
        }
        end = from;
    }
    Ok(0)
}

/// The time stamp of the last data row within the first `size` bytes (read from the end).
fn last_time(file: &mut File, size: u64) -> io::Result<Option<f64>> {
    let from = size.saturating_sub(1 << 16);
    let mut b = vec![0u8; (size - from) as usize];
    file.seek(SeekFrom::Start(from))?;
    file.read_exact(&mut b)?;
    Ok(b.split(|&x| x == b'\n')
        .rfind(|l| !l.is_empty())
        .and_then(|l| l.split(|&x| x == b',').next())
        .and_then(|c| std::str::from_utf8(c).ok()?.parse::<f64>().ok()))
}

/// Both streams and the count of samples the format could not hold.
pub(crate) struct Streams {
    pub imu: Stream,
    pub table: Stream,
    pub columns: Columns,
    pub dropped: u64,
    /// `journal.jsonl`: the run's events and the streams' block records, in order.
    pub journal: File,
    /// IMU values written in their shortest exact form instead of fixed decimals.
    pub exact: bool,
}

impl Streams {
    /// Appends one line to the journal.
    pub(crate) fn journal_line(&mut self, line: &str) -> io::Result<()> {
        let mut l = Vec::with_capacity(line.len() + 1);
        l.extend_from_slice(line.as_bytes());
        l.push(b'\n');
        self.journal
            .write_all(&l)
            .map_err(|e| io::Error::new(e.kind(), format!("journal.jsonl: {e}")))
    }

    /// Records in the journal the blocks due (`force`: every block written so far).
    pub(crate) fn record_blocks(&mut self, force: bool) -> io::Result<()> {
        for k in 0..2 {
            let s = if k == 0 {
                &mut self.imu
            } else {
                &mut self.table
            };
            if let Some((r, t)) = s.due_record(force) {
                self.journal_line(&r.journal_line(t))?;
            }
        }
        Ok(())
    }

    /// Flushes both streams and records their blocks; `durable`: the streams reach the
    /// disk before the records that vouch for them, and the journal after.
    pub(crate) fn sync(&mut self, durable: bool) -> io::Result<()> {
        let streams = self.imu.sync(durable).and(self.table.sync(durable));
        // Blocks written before a failure are recorded all the same.
        self.record_blocks(durable || streams.is_err())?;
        streams?;
        if durable {
            self.journal.sync_data()?;
        }
        Ok(())
    }

    /// The first failed write of either stream.
    pub(crate) fn failure(&self) -> Option<&WriteFailure> {
        self.imu.failure.as_ref().or(self.table.failure.as_ref())
    }

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

/// The stamp (first field) of the last full row of `rows` (whole rows, each ending in a
/// line break).
fn last_row_t(rows: &[u8]) -> Option<f64> {
    let body = rows.strip_suffix(b"\n")?;
    let start = body.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
    let row = &body[start..];
    let end = row.iter().position(|&b| b == b',').unwrap_or(row.len());
    std::str::from_utf8(&row[..end]).ok()?.trim().parse().ok()
}

#[cfg(test)]
mod row_tests {
    use super::last_row_t;

    #[test]
    fn the_last_rows_stamp() {
        assert_eq!(last_row_t(b"1.5,2,3\n2.25,4,5\n"), Some(2.25));
        assert_eq!(last_row_t(b"7,1\n"), Some(7.0));
        assert_eq!(last_row_t(b""), None);
        assert_eq!(last_row_t(b"t,ax\n"), None);
    }
}
