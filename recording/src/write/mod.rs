//! Streaming writer of a recording folder (`spec/recording-format.md`): `imu.csv` and
//! `table.csv` are appended batch by batch, on a writer thread (formatting, hashing and
//! writing run beside the interpreter, on the second core), through a fixed-size buffer that
//! is hashed as it is flushed, so memory stays bounded however long the run (a bounded
//! queue of batches) and the files' SHA-256 are known at the end without reading them back. `manifest.yaml` is rewritten atomically at
//! every checkpoint (segment end, abort, end of run), and `journal.jsonl` gets one JSON
//! line per event.

mod fixed;
mod streams;
mod writeback;

pub use fixed::push_fixed;
pub use streams::Columns;

use crate::commit::crash_point;
use crate::{FORMAT, ImuSample, Manifest, TableSample, WriteFailure, WrittenFile};
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::io;
use std::path::{Path, PathBuf};
use std::sync::mpsc;
use streams::{Stream, Streams};

/// What the interpreter's thread asks the writer thread.
enum Msg {
    Imu(Vec<ImuSample>),
    Table(Vec<TableSample>),
    /// One journal line (written in order with the streams' block records).
    Journal(String),
    /// Flush both streams to the OS (`true`: to the disk, with every block recorded); reply
    /// with the first error so far.
    Sync(bool, mpsc::Sender<io::Result<()>>),
    /// Flush to the disk and reply with the files' SHA-256 (imu, table) and the failed
    /// write, if one failed (the streams are then cut after their last full line).
    Hashes(mpsc::Sender<io::Result<Hashes>>),
    /// A checkpoint: both streams to the disk with every block recorded, then this manifest
    /// (`manifest.yaml`'s text) replaced atomically; reply with the first error.
    Checkpoint(String, mpsc::Sender<io::Result<()>>),
}

/// The streams as written (imu, table: SHA-256 and length), and the write that failed, if
/// one did.
type Hashes = (WrittenFile, WrittenFile, Option<WriteFailure>);

/// Batches in flight before `write_*` waits: bounds memory if the disk is slow.
const QUEUE: usize = 64;

/// Rows gathered before they go to the writer thread (fewer wake-ups than one message per
/// control tick); every checkpoint, `finish` and drop sends what is gathered.
const BATCH_IMU: usize = 512;
const BATCH_TABLE: usize = 512;

/// Writes a recording folder incrementally. Sample times handed in are already on the
/// recording's clock (0 at the start of the run). Samples the format cannot hold are
/// dropped and counted: a time that does not strictly increase, or a non-finite value (a
/// faulty IMU's NaN output; the format refuses non-numeric cells).
///
/// The streams are formatted, hashed and written on a writer thread, which also writes the
/// journal: the run's events and, as blocks of each stream are written, their running hash
/// (`block` lines, [`crate::chain`]). An IO error there surfaces at the next
/// [`RecordingWriter::checkpoint`] (every segment end) or [`RecordingWriter::sync`].
pub struct RecordingWriter {
    dir: PathBuf,
    tx: Option<mpsc::SyncSender<Msg>>,
    thread: Option<std::thread::JoinHandle<u64>>,
    columns: Columns,
    manifest: Manifest,
    pending_imu: Vec<ImuSample>,
    pending_table: Vec<TableSample>,
    cut: BTreeMap<String, u64>,
    /// The streams as [`RecordingWriter::finish`] left them.
    written: Vec<WrittenFile>,
    failure: Option<WriteFailure>,
    /// The checkpoint the writer thread is doing ([`RecordingWriter::checkpoint_begin`]):
    /// its reply, and the segments its manifest lists.
    in_flight: Option<(mpsc::Receiver<io::Result<()>>, usize)>,
    /// Segments the manifest on the disk lists (the last checkpoint's that succeeded).
    durable: usize,
}

fn copy_err(e: &io::Error) -> io::Error {
    io::Error::new(e.kind(), e.to_string())
}

fn writer_thread(mut st: Streams, dir: PathBuf, rx: mpsc::Receiver<Msg>) -> u64 {
    let mut failed: Option<io::Error> = None;
    let keep = |r: io::Result<()>, failed: &mut Option<io::Error>| {
        if let Err(e) = r {
            failed.get_or_insert(e);
        }
    };
    for msg in rx {
        match msg {
            Msg::Imu(v) if failed.is_none() => {
                let r = st.write_imu(&v).and_then(|()| st.record_blocks(false));
                keep(r, &mut failed);
            }
            Msg::Table(v) if failed.is_none() => {
                let r = st.write_table(&v).and_then(|()| st.record_blocks(false));
                keep(r, &mut failed);
            }
            Msg::Imu(_) | Msg::Table(_) => {}
            Msg::Journal(line) => {
                // The journal goes on after a stream failed: the abort is recorded.
                let r = st.journal_line(&line);
                keep(r, &mut failed);
            }
            Msg::Sync(durable, reply) => {
                sync_or_record(&mut st, durable, &mut failed);
                let _ = reply.send(failed.as_ref().map_or(Ok(()), |e| Err(copy_err(e))));
            }
            Msg::Checkpoint(yaml, reply) => {
                sync_or_record(&mut st, true, &mut failed);
                let r = match &failed {
                    Some(e) => Err(copy_err(e)),
                    // A manifest that could not be replaced fails this checkpoint only.
                    None => write_manifest_text(&dir, &yaml),
                };
                if r.is_ok() {
                    crash_point("after-checkpoint");
                }
                let _ = reply.send(r);
            }
            Msg::Hashes(reply) => {
                sync_or_record(&mut st, true, &mut failed);
                // A failed stream write is recorded and sealed as cut; any other failure
                // (the journal, an fsync) leaves the recording unfinished.
                let r = match (&failed, st.failure()) {
                    (Some(_), Some(f)) => {
                        Ok((st.imu.written(), st.table.written(), Some(f.clone())))
                    }
                    (Some(e), None) => Err(copy_err(e)),
                    (None, _) => Ok((st.imu.written(), st.table.written(), None)),
                };
                let _ = reply.send(r);
            }
        }
    }
    st.dropped
}

/// Flushes both streams (`durable`: to the disk), or after a failure records the blocks
/// written before it and syncs the journal.
fn sync_or_record(st: &mut Streams, durable: bool, failed: &mut Option<io::Error>) {
    if failed.is_none() {
        if let Err(e) = st.sync(durable) {
            *failed = Some(e);
        }
    } else {
        let _ = st.record_blocks(true).and_then(|()| st.journal.sync_data());
    }
}

/// Replaces `manifest.yaml` in `dir` atomically with `yaml`.
fn write_manifest_text(dir: &Path, yaml: &str) -> io::Result<()> {
    crate::commit::write_atomic(dir, "manifest.yaml", yaml.as_bytes())
        .map_err(|e| io::Error::new(e.kind(), format!("manifest.yaml: {e}")))
}

fn gone() -> io::Error {
    io::Error::other("the recording writer thread stopped")
}

impl RecordingWriter {
    fn start(dir: &Path, streams: Streams, manifest: Manifest) -> io::Result<Self> {
        let columns = streams.columns;
        let (tx, rx) = mpsc::sync_channel(QUEUE);
        let at = dir.to_path_buf();
        let thread = std::thread::Builder::new()
            .name("recording-writer".into())
            .spawn(move || writer_thread(streams, at, rx))?;
        Ok(RecordingWriter {
            dir: dir.to_path_buf(),
            tx: Some(tx),
            thread: Some(thread),
            columns,
            manifest,
            pending_imu: Vec::with_capacity(BATCH_IMU),
            pending_table: Vec::with_capacity(BATCH_TABLE),
            cut: BTreeMap::new(),
            written: Vec::new(),
            failure: None,
            in_flight: None,
            durable: 0,
        })
    }

    /// Creates `dir` (if needed) and the recording's files; writes the manifest once.
    pub fn create(dir: &Path, manifest: Manifest, columns: Columns) -> io::Result<Self> {
        Self::create_with(dir, manifest, columns, false, true)
    }

    /// As [`RecordingWriter::create`], but the IMU stream's times and values are written in
    /// their shortest form that reads back to the same `f64` (an import: another system's
    /// samples kept exactly, not rounded to the format's usual decimals).
    pub fn create_exact(dir: &Path, manifest: Manifest, columns: Columns) -> io::Result<Self> {
        Self::create_with(dir, manifest, columns, true, true)
    }

    /// As [`RecordingWriter::create_exact`], but the journal gets no running hash of the
    /// streams (no `block` lines, [`crate::chain`]): for a caller that deletes
    /// `journal.jsonl` when done (an import), so the folder is never resumed. The files
    /// written are byte for byte those of [`RecordingWriter::create_exact`].
    pub fn create_exact_unchained(
        dir: &Path,
        manifest: Manifest,
        columns: Columns,
    ) -> io::Result<Self> {
        Self::create_with(dir, manifest, columns, true, false)
    }

    fn create_with(
        dir: &Path,
        manifest: Manifest,
        columns: Columns,
        exact: bool,
        chained: bool,
    ) -> io::Result<Self> {
        std::fs::create_dir_all(dir)?;
        let mut imu = Stream::create(&dir.join("imu.csv"), &columns.imu_header())?;
        let mut table = Stream::create(&dir.join("table.csv"), &columns.table_header())?;
        imu.chained = chained;
        table.chained = chained;
        let journal = crate::commit::open_nofollow(&dir.join("journal.jsonl"), true, false)?;
        let mut manifest = manifest;
        manifest.format = FORMAT.to_string();
        let streams = Streams {
            imu,
            table,
            columns,
            dropped: 0,
            exact,
            journal,
        };
        let mut w = Self::start(dir, streams, manifest)?;
        w.checkpoint()?;
        crash_point("after-create");
        Ok(w)
    }

    /// Reopens an interrupted recording to continue it (`run --resume`): streams and journal
    /// are appended to, the manifest is read back. Each stream is read (streaming) against
    /// the running hash the journal recorded: refused when it no longer matches; the bytes
    /// written after the last record (a crash's tail, never part of a segment) are cut,
    /// unless `sealed` (the folder's seal vouches for them). Returns the writer and the
    /// last time stamp found in either stream (`None` when both are empty).
    pub fn append(dir: &Path, sealed: bool) -> io::Result<(Self, Option<f64>)> {
        let text = std::fs::read_to_string(dir.join("manifest.yaml"))?;
        // The reader's manifest parser, so a resumed run accepts exactly what analysis reads.
        let manifest = crate::parse_manifest("manifest.yaml", &text)
            .map_err(|e| io::Error::new(io::ErrorKind::InvalidData, e.to_string()))?;
        let blocks = crate::chain::journal_blocks(&dir.join("journal.jsonl"))?;
        let open = |name: &str| {
            let records = blocks.get(name).map(Vec::as_slice);
            Stream::append(&dir.join(name), records, sealed)
        };
        let (imu, imu_header, imu_cut) = open("imu.csv")?;
        let (table, table_header, table_cut) = open("table.csv")?;
        let columns = Columns::of_headers(&imu_header, &table_header);
        let journal = crate::commit::open_nofollow(&dir.join("journal.jsonl"), false, true)?;
        let last = match (imu.last_t, table.last_t) {
            (Some(a), Some(b)) => Some(a.max(b)),
            (a, b) => a.or(b),
        };
        let streams = Streams {
            imu,
            table,
            columns,
            dropped: 0,
            exact: false,
            journal,
        };
        let mut w = Self::start(dir, streams, manifest)?;
        w.durable = w.manifest.segments.len();
        for (name, n) in [("imu.csv", imu_cut), ("table.csv", table_cut)] {
            if n > 0 {
                w.cut.insert(name.into(), n);
            }
        }
        Ok((w, last))
    }

    /// Bytes [`RecordingWriter::append`] cut from each stream (the unrecorded tail of a
    /// crash), by file name.
    pub fn cut_tails(&self) -> &BTreeMap<String, u64> {
        &self.cut
    }

    /// The streams as [`RecordingWriter::finish`] left them (name, SHA-256, length), hashed
    /// as they were written: a seal of the freshly written folder can take them instead of
    /// reading the files again ([`crate::hash_folder_known`]). Empty before `finish`.
    pub fn written(&self) -> &[WrittenFile] {
        &self.written
    }

    /// The stream write that failed, as [`RecordingWriter::finish`] found it (the stream
    /// then ends cut after its last full line).
    pub fn write_failure(&self) -> Option<&WriteFailure> {
        self.failure.as_ref()
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

    /// Appends one line to `journal.jsonl` (through the writer thread, in order with the
    /// streams' block records; the journal is what `--resume` trusts).
    pub fn write_journal_line(&mut self, line: &str) -> io::Result<()> {
        self.send(Msg::Journal(line.to_string()))
    }

    fn sync_streams(&mut self, durable: bool) -> io::Result<()> {
        self.settle()?;
        self.send_pending()?;
        let (tx, rx) = mpsc::channel();
        self.send(Msg::Sync(durable, tx))?;
        rx.recv().map_err(|_| gone())?
    }

    /// Flushes the journal and both streams to the OS (without rewriting the manifest).
    pub fn sync(&mut self) -> io::Result<()> {
        self.sync_streams(false)
    }

    /// Flushes both streams to the disk, records their blocks in the journal, and replaces
    /// the manifest atomically (written whole and fsynced, then renamed).
    pub fn checkpoint(&mut self) -> io::Result<()> {
        self.checkpoint_begin()?;
        self.settle()
    }

    /// Begins a checkpoint ([`RecordingWriter::checkpoint`]) of the manifest as it stands
    /// and returns at once: the writer thread does it after the rows already handed over,
    /// while the caller goes on. Its error surfaces at the next checkpoint, sync or
    /// [`RecordingWriter::settle`] ([`RecordingWriter::finish`] settles first); then the
    /// segments it added are taken out of the manifest again, since their data may not all
    /// be on the disk. An error of the checkpoint before this one is returned here, and
    /// this one is not begun.
    pub fn checkpoint_begin(&mut self) -> io::Result<()> {
        self.settle()?;
        self.send_pending()?;
        let yaml = manifest_yaml(&self.manifest)?;
        let (tx, rx) = mpsc::channel();
        self.send(Msg::Checkpoint(yaml, tx))?;
        self.in_flight = Some((rx, self.manifest.segments.len()));
        Ok(())
    }

    /// Waits for the checkpoint begun, if any ([`RecordingWriter::checkpoint_begin`]): its
    /// error, with the segments listed since the last checkpoint that succeeded taken out
    /// of the manifest.
    pub fn settle(&mut self) -> io::Result<()> {
        let Some((rx, listed)) = self.in_flight.take() else {
            return Ok(());
        };
        let r = rx.recv().map_err(|_| gone()).and_then(|r| r);
        match r {
            Ok(()) => self.durable = listed,
            Err(_) => self.manifest.segments.truncate(self.durable),
        }
        r
    }

    fn write_manifest(&self) -> io::Result<()> {
        let yaml = manifest_yaml(&self.manifest)?;
        write_manifest_text(&self.dir, &yaml)
    }

    /// Ends the recording: records the SHA-256 of each data file in `run.files_sha256`,
    /// sets `run.ended`, and writes the final manifest. After a failed write the streams
    /// end cut after their last full line and the manifest says so (`run.write_failure`).
    pub fn finish(&mut self) -> io::Result<()> {
        // A failed checkpoint's error is the writer thread's too: `Hashes` reports it.
        let _ = self.settle();
        self.send_pending()?;
        let (tx, rx) = mpsc::channel();
        self.send(Msg::Hashes(tx))?;
        let (imu, table, failure) = rx.recv().map_err(|_| gone())??;
        if let Some(run) = self.manifest.run.as_mut() {
            run.files_sha256
                .insert("imu.csv".into(), imu.sha256.clone());
            run.files_sha256
                .insert("table.csv".into(), table.sha256.clone());
            run.ended = Some(rfc3339(std::time::SystemTime::now()));
            if failure.is_some() {
                run.write_failure = failure.clone();
            }
        }
        self.written = vec![imu, table];
        self.failure = failure;
        self.write_manifest()?;
        crash_point("after-manifest");
        Ok(())
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
