//! Streaming writer of a recording folder (`spec/recording-format.md`): `imu.csv` and
//! `table.csv` are appended batch by batch, on a writer thread (formatting, hashing and
//! writing run beside the interpreter, on the second core), through a fixed-size buffer that
//! is hashed as it is flushed, so memory stays bounded however long the run (a bounded
//! queue of batches) and the files' SHA-256 are known at the end without reading them back. `manifest.yaml` is rewritten atomically at
//! every checkpoint (segment end, abort, end of run), and `journal.jsonl` gets one JSON
//! line per event.

mod fixed;
mod streams;

pub use fixed::push_fixed;
pub use streams::Columns;

use crate::{FORMAT, ImuSample, Manifest, TableSample};
use sha2::{Digest, Sha256};
use std::fs::{File, OpenOptions};
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::sync::mpsc;
use streams::{Stream, Streams};

/// What the interpreter's thread asks the writer thread.
enum Msg {
    Imu(Vec<ImuSample>),
    Table(Vec<TableSample>),
    /// Flush both streams to the OS; reply with the first error so far.
    Sync(mpsc::Sender<io::Result<()>>),
    /// Flush and reply with the files' SHA-256 (imu, table).
    Hashes(mpsc::Sender<io::Result<(String, String)>>),
}

/// Batches in flight before `write_*` waits: bounds memory if the disk is slow.
const QUEUE: usize = 64;

/// Rows gathered before they go to the writer thread (fewer wake-ups than one message per
/// control tick); every checkpoint, `finish` and drop sends what is gathered.
const BATCH_IMU: usize = 512;
const BATCH_TABLE: usize = 64;

/// Writes a recording folder incrementally. Sample times handed in are already on the
/// recording's clock (0 at the start of the run). Samples the format cannot hold are
/// dropped and counted: a time that does not strictly increase, or a non-finite value (a
/// faulty IMU's NaN output; the format refuses non-numeric cells).
///
/// The streams are formatted, hashed and written on a writer thread; an IO error there
/// surfaces at the next [`RecordingWriter::checkpoint`] (every segment end) or write.
pub struct RecordingWriter {
    dir: PathBuf,
    tx: Option<mpsc::SyncSender<Msg>>,
    thread: Option<std::thread::JoinHandle<u64>>,
    journal: File,
    columns: Columns,
    manifest: Manifest,
    pending_imu: Vec<ImuSample>,
    pending_table: Vec<TableSample>,
}

fn writer_thread(mut st: Streams, rx: mpsc::Receiver<Msg>) -> u64 {
    let mut failed: Option<io::Error> = None;
    let keep = |r: io::Result<()>, failed: &mut Option<io::Error>| {
        if let Err(e) = r {
            failed.get_or_insert(e);
        }
    };
    for msg in rx {
        match msg {
            Msg::Imu(v) if failed.is_none() => keep(st.write_imu(&v), &mut failed),
            Msg::Table(v) if failed.is_none() => keep(st.write_table(&v), &mut failed),
            Msg::Imu(_) | Msg::Table(_) => {}
            Msg::Sync(reply) => {
                if failed.is_none() {
                    keep(st.imu.sync().and_then(|()| st.table.sync()), &mut failed);
                }
                let _ = reply.send(
                    failed
                        .as_ref()
                        .map_or(Ok(()), |e| Err(io::Error::new(e.kind(), e.to_string()))),
                );
            }
            Msg::Hashes(reply) => {
                if failed.is_none() {
                    keep(st.imu.sync().and_then(|()| st.table.sync()), &mut failed);
                }
                let r = match &failed {
                    Some(e) => Err(io::Error::new(e.kind(), e.to_string())),
                    None => Ok((st.imu.sha256(), st.table.sha256())),
                };
                let _ = reply.send(r);
            }
        }
    }
    st.dropped
}

fn gone() -> io::Error {
    io::Error::other("the recording writer thread stopped")
}

impl RecordingWriter {
    fn start(dir: &Path, streams: Streams, journal: File, manifest: Manifest) -> io::Result<Self> {
        let columns = streams.columns;
        let (tx, rx) = mpsc::sync_channel(QUEUE);
        let thread = std::thread::Builder::new()
            .name("recording-writer".into())
            .spawn(move || writer_thread(streams, rx))?;
        Ok(RecordingWriter {
            dir: dir.to_path_buf(),
            tx: Some(tx),
            thread: Some(thread),
            journal,
            columns,
            manifest,
            pending_imu: Vec::with_capacity(BATCH_IMU),
            pending_table: Vec::with_capacity(BATCH_TABLE),
        })
    }

    /// Creates `dir` (if needed) and the recording's files; writes the manifest once.
    pub fn create(dir: &Path, manifest: Manifest, columns: Columns) -> io::Result<Self> {
        Self::create_with(dir, manifest, columns, false)
    }

    /// As [`RecordingWriter::create`], but the IMU stream's times and values are written in
    /// their shortest form that reads back to the same `f64` (an import: another system's
    /// samples kept exactly, not rounded to the format's usual decimals).
    pub fn create_exact(dir: &Path, manifest: Manifest, columns: Columns) -> io::Result<Self> {
        Self::create_with(dir, manifest, columns, true)
    }

    fn create_with(
        dir: &Path,
        manifest: Manifest,
        columns: Columns,
        exact: bool,
    ) -> io::Result<Self> {
        std::fs::create_dir_all(dir)?;
        let imu = Stream::create(&dir.join("imu.csv"), &columns.imu_header())?;
        let table = Stream::create(&dir.join("table.csv"), &columns.table_header())?;
        let journal = File::create(dir.join("journal.jsonl"))?;
        let mut manifest = manifest;
        manifest.format = FORMAT.to_string();
        let mut w = Self::start(
            dir,
            Streams {
                imu,
                table,
                columns,
                dropped: 0,
                exact,
            },
            journal,
            manifest,
        )?;
        w.checkpoint()?;
        Ok(w)
    }

    /// Reopens an interrupted recording to continue it (`run --resume`): streams and journal
    /// are appended to, the manifest is read back. Returns the writer and the last time
    /// stamp found in either stream (`None` when both are empty).
    pub fn append(dir: &Path) -> io::Result<(Self, Option<f64>)> {
        let text = std::fs::read_to_string(dir.join("manifest.yaml"))?;
        // The reader's manifest parser, so a resumed run accepts exactly what analysis reads.
        let manifest = crate::parse_manifest("manifest.yaml", &text)
            .map_err(|e| io::Error::new(io::ErrorKind::InvalidData, e.to_string()))?;
        let (imu, imu_header) = Stream::append(&dir.join("imu.csv"))?;
        let (table, table_header) = Stream::append(&dir.join("table.csv"))?;
        let columns = Columns::of_headers(&imu_header, &table_header);
        let journal = OpenOptions::new()
            .append(true)
            .create(true)
            .open(dir.join("journal.jsonl"))?;
        let last = match (imu.last_t, table.last_t) {
            (Some(a), Some(b)) => Some(a.max(b)),
            (a, b) => a.or(b),
        };
        let w = Self::start(
            dir,
            Streams {
                imu,
                table,
                columns,
                dropped: 0,
                exact: false,
            },
            journal,
            manifest,
        )?;
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

    fn send(&self, msg: Msg) -> io::Result<()> {
        self.tx
            .as_ref()
            .ok_or_else(gone)?
            .send(msg)
            .map_err(|_| gone())
    }

    /// Appends IMU samples (times on the recording clock).
    pub fn write_imu(&mut self, samples: &[ImuSample]) -> io::Result<()> {
        self.pending_imu.extend_from_slice(samples);
        if self.pending_imu.len() >= BATCH_IMU {
            self.send_pending()?;
        }
        Ok(())
    }

    /// Appends table feedback samples (times on the recording clock).
    pub fn write_table(&mut self, samples: &[TableSample]) -> io::Result<()> {
        self.pending_table.extend_from_slice(samples);
        if self.pending_table.len() >= BATCH_TABLE {
            self.send_pending()?;
        }
        Ok(())
    }

    /// Hands the gathered rows to the writer thread.
    fn send_pending(&mut self) -> io::Result<()> {
        if !self.pending_imu.is_empty() {
            let v = std::mem::replace(&mut self.pending_imu, Vec::with_capacity(BATCH_IMU));
            self.send(Msg::Imu(v))?;
        }
        if !self.pending_table.is_empty() {
            let v = std::mem::replace(&mut self.pending_table, Vec::with_capacity(BATCH_TABLE));
            self.send(Msg::Table(v))?;
        }
        Ok(())
    }

    /// Samples dropped because the format could not hold them; closes the streams (call
    /// after [`RecordingWriter::finish`]).
    pub fn close(mut self) -> u64 {
        let _ = self.send_pending();
        self.tx = None;
        self.thread.take().and_then(|t| t.join().ok()).unwrap_or(0)
    }

    /// Appends one line to `journal.jsonl` (written through at once: the journal is what
    /// `--resume` trusts).
    pub fn write_journal_line(&mut self, line: &str) -> io::Result<()> {
        let mut l = String::with_capacity(line.len() + 1);
        l.push_str(line);
        l.push('\n');
        self.journal.write_all(l.as_bytes())
    }

    /// Flushes the journal and both streams to the OS (without rewriting the manifest).
    pub fn sync(&mut self) -> io::Result<()> {
        self.journal.flush()?;
        self.send_pending()?;
        let (tx, rx) = mpsc::channel();
        self.send(Msg::Sync(tx))?;
        rx.recv().map_err(|_| gone())?
    }

    /// Flushes both streams to the OS and rewrites the manifest atomically
    /// (`manifest.yaml.tmp` then rename).
    pub fn checkpoint(&mut self) -> io::Result<()> {
        self.send_pending()?;
        let (tx, rx) = mpsc::channel();
        self.send(Msg::Sync(tx))?;
        rx.recv().map_err(|_| gone())??;
        let yaml = manifest_yaml(&self.manifest)?;
        let tmp = self.dir.join("manifest.yaml.tmp");
        std::fs::write(&tmp, yaml)?;
        std::fs::rename(&tmp, self.dir.join("manifest.yaml"))
    }

    /// Ends the recording: records the SHA-256 of each data file in `run.files_sha256`,
    /// sets `run.ended`, and writes the final manifest.
    pub fn finish(&mut self) -> io::Result<()> {
        self.journal.flush()?;
        self.send_pending()?;
        let (tx, rx) = mpsc::channel();
        self.send(Msg::Hashes(tx))?;
        let (imu, table) = rx.recv().map_err(|_| gone())??;
        if let Some(run) = self.manifest.run.as_mut() {
            run.files_sha256.insert("imu.csv".into(), imu);
            run.files_sha256.insert("table.csv".into(), table);
            run.ended = Some(rfc3339(std::time::SystemTime::now()));
        }
        self.checkpoint()
    }
}

impl Drop for RecordingWriter {
    fn drop(&mut self) {
        // Lets the writer thread drain what it holds and close the files.
        let _ = self.send_pending();
        self.tx = None;
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
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

/// The civil date `(year, month, day)` of a count of days since 1970-01-01 (H. Hinnant's
/// algorithm, proleptic Gregorian).
pub fn civil_from_days(days: i64) -> (i64, i64, i64) {
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    (y, m, d)
}

/// Formats a wall-clock time as RFC 3339 in UTC (`2026-11-03T14:05:09Z`).
pub fn rfc3339(t: std::time::SystemTime) -> String {
    let secs = t
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs())
        .unwrap_or(0) as i64;
    let (days, sod) = (secs.div_euclid(86_400), secs.rem_euclid(86_400));
    let (y, m, d) = civil_from_days(days);
    format!(
        "{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}Z",
        sod / 3600,
        sod % 3600 / 60,
        sod % 60
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rfc3339_known_dates() {
        let t = |s: u64| rfc3339(std::time::UNIX_EPOCH + std::time::Duration::from_secs(s));
        assert_eq!(t(0), "1970-01-01T00:00:00Z");
        assert_eq!(t(951_782_400), "2000-02-29T00:00:00Z");
        assert_eq!(t(1_700_000_000), "2023-11-14T22:13:20Z");
    }
}
