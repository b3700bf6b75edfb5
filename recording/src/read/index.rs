//! A stream file indexed by time, for reading it span by span: the byte offset and the
//! first time stamp of each block of about `BLOCK` bytes, found by the range parser
//! (`scan::scan_range`, block by block, the time column only) or, for a file it gives up
//! on, by the exact reader. Opening checks what `read` checks of the time column (cells,
//! order, count) and of the header; the other cells are checked when their span is read.

// A refused recording is built once per read: the error's size costs nothing.
#![allow(clippy::result_large_err)]

use super::check::Extent;
use super::csvread::read_rows;
use super::fast::{head, layout};
use super::io_error;
use super::scan::{self, Layout, MAX_SLOTS, RowSink};
use super::stream::Stream;
use crate::error::RecordingError;
use std::path::{Path, PathBuf};

/// Bytes of CSV per index entry: a span read parses at most two blocks it does not keep.
pub(super) const BLOCK: u64 = 256 * 1024;

/// Where the rows of one stream file are, by time.
#[derive(Debug, Clone)]
pub(super) struct StreamIndex {
    pub path: PathBuf,
    /// The fast path's layout; `None` when the exact reader reads this file (its entries
    /// are then the csv crate's record starts).
    pub fast: Option<Layout>,
    /// Whether the header has the optional column.
    pub optional: bool,
    /// Where the data starts (after the header).
    pub head_end: u64,
    /// File length when opened: rows whose line starts later are not read.
    pub len: u64,
    /// Data lines per byte, to size a span's columns.
    pub density: f64,
    /// `(offset, t)`: a block's rows are those whose line starts at or after its offset and
    /// before the next block's; `t` is the first one's time. Blocks without rows are left
    /// out (their bytes belong to the block before).
    pub entries: Vec<(u64, f64)>,
}

/// What the time column says, seen row by row: count, order, extent, and, for each
/// segment start asked about, the first stamp at or after it.
#[derive(Debug)]
pub(super) struct Times<'a> {
    pub rows: usize,
    first: [f64; 2],
    last: f64,
    /// First row whose time is not after the previous one: `(row, previous, t)`.
    pub backwards: Option<(usize, f64, f64)>,
    /// Gaps and jitter of the stamps.
    pub cadence: crate::Cadence,
    /// Segment starts, ascending.
    starts: &'a [f64],
    first_at: Vec<f64>,
    next: usize,
}

impl<'a> Times<'a> {
    pub fn new(starts: &'a [f64]) -> Self {
        Times {
            rows: 0,
            first: [f64::NAN; 2],
            last: f64::NAN,
            backwards: None,
            cadence: crate::Cadence::default(),
            starts,
            first_at: vec![f64::INFINITY; starts.len()],
            next: 0,
        }
    }

    #[inline]
    fn see(&mut self, t: f64) {
        if self.rows < 2 {
            self.first[self.rows] = t;
        }
        if self.rows > 0 && self.backwards.is_none() && t <= self.last {
            self.backwards = Some((self.rows, self.last, t));
        }
        self.cadence.see(t);
        while self.next < self.starts.len() && self.starts[self.next] <= t {
            self.first_at[self.next] = t;
            self.next += 1;
        }
        self.last = t;
        self.rows += 1;
    }

    /// The stream's extent (at least two rows).
    pub fn extent(&self) -> Extent {
        Extent {
            first: self.first[0],
            second: self.first[1],
            last: self.last,
        }
    }

    /// Whether a stamp lies in `[t_start, t_end]`, for a `t_start` among the starts.
    pub fn holds_sample(&self, t_start: f64, t_end: f64) -> bool {
        let i = self.starts.partition_point(|&s| s < t_start);
        i < self.starts.len() && self.starts[i] == t_start && self.first_at[i] <= t_end
    }
}

impl StreamIndex {
    /// Indexes `dir`'s file of stream `S`, feeding every time stamp to `times`.
    pub fn build<S: Stream>(dir: &Path, times: &mut Times) -> Result<Self, RecordingError> {
        let path = dir.join(S::FILE);
        let (names, data_start, len) = head(&path)?;
        if let Some((full, optional)) = layout::<S>(&names, data_start) {
            // The time column alone (slot 0); the other cells wait for their span.
            let only_t = full.only(&[0]);
            let mut fast = Times::new(times.starts);
            if let Some(entries) = fast_entries(&path, &only_t, len, &mut fast) {
                *times = fast;
                let density = times.rows as f64 / (len - data_start).max(1) as f64;
                return Ok(StreamIndex {
                    path,
                    fast: Some(full),
                    optional,
                    head_end: data_start,
                    len,
                    density,
                    entries,
                });
            }
        }
        exact_index::<S>(path, times)
    }
}

/// Blocks parsed at once by [`fast_entries`] (at most): 16 MB of CSV, whose stamps are 2 MB.
const BATCH: usize = 64;

/// Block by block through the range parser, a batch of blocks at a time: a second thread
/// parses every other batch while this one parses the others and sees every stamp in
/// order (neither waits for the other but at the end); `None` when it gives up somewhere.
fn fast_entries(
    path: &Path,
    only_t: &Layout,
    len: u64,
    times: &mut Times,
) -> Option<Vec<(u64, f64)>> {
    let starts: Vec<u64> = (only_t.data_start..len).step_by(BLOCK as usize).collect();
    let stamps = |a: u64| -> Option<Vec<f64>> {
        let mut s = Stamps(Vec::new());
        scan::scan_range(path, only_t, a, (a + BLOCK).min(len), &mut s).ok()?;
        Some(s.0)
    };
    let batch = |b: &[u64]| b.iter().map(|&a| stamps(a)).collect::<Option<Vec<_>>>();
    // A file of one batch or less is still cut in two, one half for each thread.
    let size = starts.len().div_ceil(2).clamp(1, BATCH);
    let batches: Vec<&[u64]> = starts.chunks(size).collect();
    let mut entries = Vec::new();
    std::thread::scope(|sc| {
        // Two batches ahead at most: the stamps waiting stay a few MB.
        let (tx, rx) = std::sync::mpsc::sync_channel(2);
        let odd = batches.iter().skip(1).step_by(2);
        sc.spawn(move || {
            for b in odd {
                let parsed = batch(b);
                let gave_up = parsed.is_none();
                if tx.send(parsed).is_err() || gave_up {
                    return;
                }
            }
        });
        for (i, b) in batches.iter().enumerate() {
            let parsed = match i % 2 {
                0 => batch(b),
                _ => rx.recv().ok().flatten(),
            }?;
            for (&a, block) in b.iter().zip(parsed) {
                if let Some(&t) = block.first() {
                    let at = if entries.is_empty() {
                        only_t.data_start
                    } else {
                        a
                    };
                    entries.push((at, t));
                }
                block.into_iter().for_each(|t| times.see(t));
            }
        }
        Some(())
    })?;
    Some(entries)
}

/// The stamps the range parser hands over, in order.
struct Stamps(Vec<f64>);

impl RowSink for Stamps {
    #[inline]
    fn push(&mut self, r: &[f64; MAX_SLOTS]) {
        self.0.push(r[0]);
    }
}

/// The exact reader over the whole file (it is read once, whole: a file the fast path
/// gives up on costs its size in memory at opening). Every cell is checked here.
fn exact_index<S: Stream>(path: PathBuf, times: &mut Times) -> Result<StreamIndex, RecordingError> {
    super::lines::refuse_long_lines(&path)?;
    let bytes = std::fs::read(&path).map_err(|e| io_error(&path, e))?;
    let file = path.display().to_string();
    let (mut row, mut next, mut marks) = (0usize, 0usize, Vec::new());
    let cols = read_rows(&file, &bytes, None, S::REQUIRED, &[S::OPTIONAL], |start| {
        if start >= next {
            marks.push((row, start));
            next = start + BLOCK as usize;
        }
        row += 1;
    })?;
    let optional = cols.cols[S::REQUIRED.len()].is_some();
    let t = cols.cols[0].as_deref().unwrap_or_default();
    for &x in t {
        times.see(x);
    }
    let entries: Vec<(u64, f64)> = marks.iter().map(|&(r, s)| (s as u64, t[r])).collect();
    let len = bytes.len() as u64;
    let head_end = entries.first().map_or(len, |e| e.0);
    Ok(StreamIndex {
        path,
        fast: None,
        optional,
        head_end,
        len,
        density: t.len() as f64 / (len - head_end).max(1) as f64,
        entries,
    })
}
