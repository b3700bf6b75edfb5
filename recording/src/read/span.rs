//! A recording read by time span: [`Recording::open`] reads the manifest and the table
//! feedback, and indexes the IMU stream by time; [`OpenRecording::read_span`] parses only
//! the blocks that hold a span, so a long 1 kHz recording is analysed segment by segment in
//! bounded memory.

// A refused recording is built once per read: the error's size costs nothing.
#![allow(clippy::result_large_err)]

use super::check;
use super::check::Extent;
use super::csvread::read_rows;
use super::index::{StreamIndex, Times};
use super::scan::{self, MAX_SLOTS, RowSink};
use super::stream::Stream;
use super::{io_error, read_manifest, read_stream};
use crate::error::RecordingError;
use crate::{ImuStream, Manifest, Recording, TableStream};
use std::io::{Read, Seek, SeekFrom};
use std::path::Path;

/// A recording folder opened for reading by time span: its manifest, the IMU stream indexed
/// by time (one entry per 256 KiB of CSV), never held whole, and the table feedback stream
/// (tens of hertz beside the IMU's hundreds or thousands), read whole.
#[derive(Debug, Clone)]
pub struct OpenRecording {
    manifest: Manifest,
    imu: StreamIndex,
    table: TableStream,
    /// IMU rows, first and last stamp.
    imu_rows: usize,
    imu_extent: (f64, f64),
    /// Gaps and jitter of the IMU stamps.
    imu_cadence: crate::CadenceReport,
}

/// The rows of both streams whose time lies in a span.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SpanRows {
    /// IMU rows.
    pub imu: ImuStream,
    /// Table feedback rows.
    pub table: TableStream,
}

impl Recording {
    /// Opens `dir` for reading by time span. It checks what [`crate::read`] checks, with
    /// the same located errors, except the IMU cells outside the time column, which are
    /// checked when a span holding them is read (an `imu.csv` whose time column the range
    /// parser gives up on, quoted cells for one, is read whole once here, and checked whole).
    pub fn open(dir: &Path) -> Result<OpenRecording, RecordingError> {
        let (manifest_name, manifest_text, manifest) = read_manifest(dir)?;
        let mut starts: Vec<f64> = manifest.segments.iter().map(|s| s.t_start).collect();
        starts.sort_by(f64::total_cmp);
        let mut imu_times = Times::new(&starts);
        let (imu, table) = std::thread::scope(|s| {
            let h = s.spawn(|| read_stream::<TableStream>(&dir.join(TableStream::FILE)));
            let imu = StreamIndex::build::<ImuStream>(dir, &mut imu_times);
            (imu, h.join().expect("table thread"))
        });
        let imu = imu?;
        if imu_times.rows < 2 {
            return Err(check::too_few(&imu.path));
        }
        if let Some((row, prev, t)) = imu_times.backwards {
            return Err(check::time_error(&imu.path, row, prev, t));
        }
        let table = table?;
        check::check_overlap(
            &dir.join(TableStream::FILE),
            imu_times.extent(),
            Extent::of(&table.t),
        )?;
        check::check_segments(
            &manifest_name,
            &manifest_text,
            &manifest,
            imu_times.extent(),
            Extent::of(&table.t),
            |a, b| imu_times.holds_sample(a, b),
        )?;
        let extent = imu_times.extent();
        Ok(OpenRecording {
            manifest,
            imu,
            table,
            imu_rows: imu_times.rows,
            imu_extent: (extent.first, extent.last),
            imu_cadence: imu_times.cadence.report(),
        })
    }
}

impl OpenRecording {
    /// The manifest.
    pub fn manifest(&self) -> &Manifest {
        &self.manifest
    }

    /// The rows of both streams with `t0 <= t <= t1`: the same rows, and the same numbers,
    /// as that slice of a whole [`crate::read`]. A bad cell among the blocks read is
    /// refused with the location a whole read gives it.
    pub fn read_span(&self, t0: f64, t1: f64) -> Result<SpanRows, RecordingError> {
        Ok(SpanRows {
            imu: span::<ImuStream>(&self.imu, t0, t1)?,
            table: table_span(&self.table, t0, t1),
        })
    }

    /// The IMU rows with `t0 <= t <= t1` (as [`OpenRecording::read_span`], the IMU only).
    pub fn read_imu_span(&self, t0: f64, t1: f64) -> Result<ImuStream, RecordingError> {
        span::<ImuStream>(&self.imu, t0, t1)
    }

    /// The whole table feedback stream.
    pub fn table(&self) -> &TableStream {
        &self.table
    }

    /// How many IMU rows the file holds.
    pub fn imu_rows(&self) -> usize {
        self.imu_rows
    }

    /// The first and the last IMU stamp, s.
    pub fn imu_extent(&self) -> (f64, f64) {
        self.imu_extent
    }

    /// Gaps and jitter of the IMU stamps, counted when the file was indexed.
    pub fn imu_cadence(&self) -> crate::CadenceReport {
        self.imu_cadence
    }

    /// Whether `imu.csv` has the optional `temp` column.
    pub fn imu_has_temp(&self) -> bool {
        self.imu.optional
    }

    /// The mean of the IMU's finite `temp` cells over every row (`None` without the
    /// column or a finite cell): one pass that parses that cell of each line alone.
    pub fn imu_mean_temp(&self) -> Result<Option<f64>, RecordingError> {
        if !self.imu.optional {
            return Ok(None);
        }
        let slot = ImuStream::REQUIRED.len();
        let mut sum = TempSum { slot, s: 0.0, n: 0 };
        if let Some(full) = &self.imu.fast {
            let layout = full.only(&[slot]);
            // Two halves side by side (a range owns the lines that start in it).
            let (from, to) = (self.imu.head_end, self.imu.len);
            let mid = from + (to - from) / 2;
            let path = &self.imu.path;
            let mut second = TempSum { slot, s: 0.0, n: 0 };
            let (a, b) = std::thread::scope(|sc| {
                let h = sc.spawn(|| scan::scan_range(path, &layout, mid, to, &mut second));
                let a = scan::scan_range(path, &layout, from, mid, &mut sum);
                (a, h.join().expect("scan thread"))
            });
            if a.is_ok() && b.is_ok() {
                sum.s += second.s;
                sum.n += second.n;
                return Ok(sum.mean());
            }
            sum = TempSum { slot, s: 0.0, n: 0 };
        }
        // The exact reader, whole (it locates a bad cell).
        let all = self.read_imu_span(f64::NEG_INFINITY, f64::INFINITY)?;
        for v in all.temp.iter().flatten() {
            sum.add(*v);
        }
        Ok(sum.mean())
    }

    /// Every `every`-th IMU row's `(t, temp)`, counting from the first row (`None` without
    /// the column): one pass that parses those two cells of the kept lines alone and only
    /// finds the end of the others, for a plot of the temperature over the run (the rows a
    /// window-by-window pass would keep). The lines passed over are not checked: whatever
    /// reads the recording's samples does that.
    pub fn imu_temp_every(&self, every: usize) -> Result<Option<Vec<(f64, f64)>>, RecordingError> {
        if !self.imu.optional {
            return Ok(None);
        }
        let every = every.max(1);
        let slot = ImuStream::REQUIRED.len();
        if let Some(full) = &self.imu.fast {
            let layout = full.only(&[0, slot]);
            let (from, to) = (self.imu.head_end, self.imu.len);
            let mut kept = TempEvery::new(slot, every);
            if scan::scan_range(&self.imu.path, &layout, from, to, &mut kept).is_ok() {
                return Ok(Some(kept.kept));
            }
        }
        // The exact reader, whole (it locates a bad cell).
        let all = self.read_imu_span(f64::NEG_INFINITY, f64::INFINITY)?;
        let temp = all.temp.unwrap_or_default();
        let rows = all.t.iter().zip(&temp).step_by(every);
        Ok(Some(rows.map(|(t, c)| (*t, *c)).collect()))
    }
}

/// Keeps every n-th row's time and temperature the range parser hands over.
struct TempEvery {
    slot: usize,
    every: usize,
    row: usize,
    kept: Vec<(f64, f64)>,
}

impl TempEvery {
    fn new(slot: usize, every: usize) -> Self {
        TempEvery {
            slot,
            every,
            row: 0,
            kept: Vec::new(),
        }
    }
}

impl RowSink for TempEvery {
    /// The rows between two kept ones are passed over: only their line ends are found.
    #[inline]
    fn wants(&mut self) -> bool {
        let kept = self.row.is_multiple_of(self.every);
        self.row += 1;
        kept
    }

    #[inline]
    fn push(&mut self, r: &[f64; MAX_SLOTS]) {
        self.kept.push((r[0], r[self.slot]));
    }
}

/// Sums the finite temperatures the range parser hands over.
struct TempSum {
    slot: usize,
    s: f64,
    n: usize,
}

impl TempSum {
    fn add(&mut self, v: f64) {
        if v.is_finite() {
            self.s += v;
            self.n += 1;
        }
    }

    fn mean(&self) -> Option<f64> {
        (self.n > 0).then(|| self.s / self.n as f64)
    }
}

impl RowSink for TempSum {
    #[inline]
    fn push(&mut self, r: &[f64; MAX_SLOTS]) {
        self.add(r[self.slot]);
    }
}

/// The table rows with `t0 <= t <= t1`.
fn table_span(tab: &TableStream, t0: f64, t1: f64) -> TableStream {
    // Bounds no time lies between (upside down, NaN): no rows.
    if t0.partial_cmp(&t1).is_none_or(|o| o.is_gt()) {
        return TableStream::default();
    }
    let a = tab.t.partition_point(|&x| x < t0);
    let b = tab.t.partition_point(|&x| x <= t1).max(a);
    let cut = |v: &[f64]| v[a..b].to_vec();
    TableStream {
        t: cut(&tab.t),
        outer: cut(&tab.outer),
        inner: cut(&tab.inner),
        outer_rate: cut(&tab.outer_rate),
        inner_rate: cut(&tab.inner_rate),
        ambient: tab.ambient.as_deref().map(cut),
    }
}

/// Keeps the rows of the span from what the range parser hands over.
struct Within<S> {
    t0: f64,
    t1: f64,
    rows: S,
}

impl<S: RowSink> RowSink for Within<S> {
    #[inline]
    fn push(&mut self, r: &[f64; MAX_SLOTS]) {
        if r[0] >= self.t0 && r[0] <= self.t1 {
            self.rows.push(r);
        }
    }
}

/// The rows of one stream in `[t0, t1]`.
fn span<S: Stream>(ix: &StreamIndex, t0: f64, t1: f64) -> Result<S, RecordingError> {
    let e = &ix.entries;
    // No rows, or bounds no time lies between (upside down, NaN).
    if e.is_empty() || t0.partial_cmp(&t1).is_none_or(|o| o.is_gt()) {
        return Ok(S::with_capacity(ix.optional, 0));
    }
    // The block where the span starts, to the first block that starts after it.
    let a = e.partition_point(|x| x.1 <= t0).saturating_sub(1);
    let b = e.partition_point(|x| x.1 <= t1);
    let (start, end) = (e[a].0, e.get(b).map_or(ix.len, |x| x.0));
    let Some(layout) = &ix.fast else {
        return exact_span(ix, start as usize, end as usize, t0, t1);
    };
    let rows = scan::rows_for(ix.density, end - start);
    let mut within = Within {
        t0,
        t1,
        rows: S::with_capacity(ix.optional, rows),
    };
    if scan::scan_range(&ix.path, layout, start, end, &mut within).is_ok() {
        return Ok(within.rows);
    }
    // The exact reader takes the lines that start in the range, as the range parser
    // splits them (its index found no quote: every line start is a record start).
    let (la, lb) = (line_start(ix, start)?, line_start(ix, end)?);
    exact_span(ix, la, lb, t0, t1)
}

/// Where the first line that starts at or after byte `at` starts (the range parser's
/// rule: after a LF).
fn line_start(ix: &StreamIndex, at: u64) -> Result<usize, RecordingError> {
    if at <= ix.head_end || at >= ix.len {
        return Ok(at.min(ix.len) as usize);
    }
    let io = |e| io_error(&ix.path, e);
    let mut f = std::fs::File::open(&ix.path).map_err(io)?;
    f.seek(SeekFrom::Start(at - 1)).map_err(io)?;
    let mut buf = [0u8; 4096];
    let mut pos = at - 1;
    loop {
        let n = f.read(&mut buf).map_err(io)?;
        if n == 0 {
            return Ok(ix.len as usize);
        }
        if let Some(p) = buf[..n].iter().position(|&b| b == b'\n') {
            return Ok((pos + p as u64 + 1).min(ix.len) as usize);
        }
        pos += n as u64;
    }
}

/// The exact reader over the header and the records that start in `[from, to)`; a
/// problem there is located in the whole file (read again, only then).
fn exact_span<S: Stream>(
    ix: &StreamIndex,
    from: usize,
    to: usize,
    t0: f64,
    t1: f64,
) -> Result<S, RecordingError> {
    let io = |e| io_error(&ix.path, e);
    let head = ix.head_end as usize;
    let mut buf = vec![0u8; head + to.saturating_sub(from)];
    let mut f = std::fs::File::open(&ix.path).map_err(io)?;
    f.read_exact(&mut buf[..head]).map_err(io)?;
    f.seek(SeekFrom::Start(from as u64)).map_err(io)?;
    f.read_exact(&mut buf[head..]).map_err(io)?;
    let file = ix.path.display().to_string();
    let cols = |bytes: &[u8], data| {
        read_rows(
            &file,
            bytes,
            Some(data),
            S::REQUIRED,
            &[S::OPTIONAL],
            |_| {},
        )
    };
    let mut rows = match cols(&buf, head..buf.len()) {
        Ok(c) => S::from_columns(c),
        Err(e) => {
            let whole = std::fs::read(&ix.path).map_err(io)?;
            return Err(cols(&whole, from..to).err().unwrap_or(e));
        }
    };
    let t = rows.t();
    let keep = t.partition_point(|&x| x < t0)..t.partition_point(|&x| x <= t1);
    rows.keep(keep);
    Ok(rows)
}
