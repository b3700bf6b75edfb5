//! The Allan series out of core: a 1 kHz hour at rest is 87 MB of gyro samples (174 MB at
//! 2 kHz), so with a scratch file handed in ([`super::super::Scratch`]) the series lives
//! there and the analysis holds a few MB of it at a time, whatever the recording's length.
//!
//! - Each window's kept samples are written as soon as the window has passed, at the next
//!   free stretch of the file (the windows pass side by side and finish in any order); the
//!   series keeps where each of its chunks went, in series order.
//! - The curves read each axis back once, in series order, and integrate it (the same
//!   running sum as in memory) into a ring as long as two blocks and the farthest offset
//!   `2m` of the sizes up to [`SLIDE`] blocks: their sums are taken as the angles come
//!   (`stream.rs`). At most 2^20 + 2^17 values an axis are held (9 MB).
//! - Larger sizes (only beyond a 1 kHz hour: a 2 kHz hour's largest) need angles further
//!   apart than that: the angles are then also written to the file, and those sizes
//!   sweep `k` in blocks of [`BLOCK`], reading `theta` at `k`, `k + m` and `k + 2m` with
//!   positioned reads ([`OnFile`]; one `File` shared by the tasks).
//!
//! Every sum adds the same terms in the same order as in memory, so the curves are the
//! same to the bit. A failed write leaves the rest of the series in memory; a failed read
//! is returned.

use super::{Theta, add_run};
use std::fs::File;
use std::io;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

/// Samples of `k` a sweep reads at once, at least (512 KB a range).
pub(super) const BLOCK: usize = 1 << 16;
/// Values moved between the file and memory per read or write (512 KB).
const STEP: usize = 1 << 16;

/// A scratch file the series is written to, shared by the windows that pass side by side
/// and by the curves' tasks.
#[derive(Debug)]
pub(crate) struct Spill {
    file: File,
    /// The first byte no stretch has taken.
    end: AtomicU64,
    /// Whether a write has failed: nothing more is written.
    failed: AtomicBool,
}

impl Spill {
    /// A spill into `file` (empty: it is written from its start).
    pub(crate) fn new(file: File) -> Spill {
        Spill {
            file,
            end: AtomicU64::new(0),
            failed: AtomicBool::new(false),
        }
    }

    /// Writes `v` at a stretch of its own and says where, or `None` when a write has
    /// failed (this one or one before: the rest of the series stays in memory).
    pub(super) fn write(&self, v: &[f64]) -> Option<u64> {
        if self.failed.load(Ordering::Relaxed) {
            return None;
        }
        let at = self.reserve(v.len());
        match self.write_at(v, at, &mut Vec::new()) {
            Ok(()) => Some(at),
            Err(_) => {
                self.failed.store(true, Ordering::Relaxed);
                None
            }
        }
    }

    /// Takes a stretch of `n` values: its first byte.
    fn reserve(&self, n: usize) -> u64 {
        self.end.fetch_add(8 * n as u64, Ordering::Relaxed)
    }

    /// Writes `v` from byte `at`, through `bytes`.
    fn write_at(&self, v: &[f64], at: u64, bytes: &mut Vec<u8>) -> io::Result<()> {
        for (i, piece) in v.chunks(STEP).enumerate() {
            bytes.resize(8 * piece.len(), 0);
            for (b, x) in bytes.as_chunks_mut::<8>().0.iter_mut().zip(piece) {
                *b = x.to_le_bytes();
            }
            write_all_at(&self.file, bytes, at + (8 * i * STEP) as u64)?;
        }
        Ok(())
    }

    /// Reads `out.len()` values from byte `at`, through `bytes`.
    pub(super) fn read_at(&self, out: &mut [f64], at: u64, bytes: &mut Vec<u8>) -> io::Result<()> {
        for (i, piece) in out.chunks_mut(STEP).enumerate() {
            bytes.resize(8 * piece.len(), 0);
            read_exact_at(&self.file, bytes, at + (8 * i * STEP) as u64)?;
            for (x, b) in piece.iter_mut().zip(bytes.as_chunks::<8>().0) {
                *x = f64::from_le_bytes(*b);
            }
        }
        Ok(())
    }
}

/// One axis's angles in the scratch file: `len` values from byte `at`, value `i` the angle
/// `theta[i + 1]`.
#[derive(Debug, Clone, Copy)]
pub(super) struct Angles {
    at: u64,
    len: usize,
}

impl Angles {
    /// A stretch of the file for `len` angles.
    pub(super) fn reserve(spill: &Spill, len: usize) -> Angles {
        Angles {
            at: spill.reserve(len),
            len,
        }
    }

    /// Writes the angles from value `i` on, through `bytes`.
    pub(super) fn write(
        &self,
        spill: &Spill,
        i: usize,
        v: &[f64],
        bytes: &mut Vec<u8>,
    ) -> io::Result<()> {
        spill.write_at(v, self.at + 8 * i as u64, bytes)
    }
}

/// How far (in blocks) the offsets of the sizes whose angles are kept in memory while
/// they are needed may reach (the stream's ring, a sweep's sliding window): farther
/// offsets are read on their own.
pub(super) const SLIDE: usize = 16;

/// An axis's angles read from the scratch file in blocks of `block` samples of `k`.
pub(super) struct OnFile<'a> {
    pub spill: &'a Spill,
    pub angles: Angles,
    pub block: usize,
}

impl OnFile<'_> {
    /// [`Theta::sweep`] with a window of the angles `c[k - 1 ..]` as long as a block and
    /// the farthest offset read (`reach`) that slides along the series: each angle is read
    /// once, and what the next block reads again is moved, not read (the blocks are at
    /// least `reach` long, so no more is moved than read).
    fn slide<const N: usize>(
        &self,
        ms: [usize; N],
        s: &mut [f64; N],
        mut k: usize,
        end: usize,
        reach: usize,
    ) -> io::Result<()> {
        let block = self.block.max(reach);
        let (mut buf, mut bytes) = (Vec::new(), Vec::new());
        // The values at the start of `buf` that are already `c[k - 1 ..]`.
        let mut held = 0;
        while k < end {
            let run = (end - k).min(block);
            buf.resize(reach + run, 0.0);
            let at = self.angles.at + 8 * (k - 1 + held) as u64;
            self.spill.read_at(&mut buf[held..], at, &mut bytes)?;
            let from = |o: usize| &buf[o..o + run];
            add_run(from(0), ms.map(from), ms.map(|m| from(2 * m)), s);
            k += run;
            if k < end {
                buf.copy_within(run.., 0);
                held = reach;
            }
        }
        Ok(())
    }
}

impl Theta for OnFile<'_> {
    type Error = io::Error;

    fn len(&self) -> usize {
        self.angles.len
    }

    fn at(&self, i: usize) -> io::Result<f64> {
        let mut v = [0.0];
        let at = self.angles.at + 8 * i as u64;
        self.spill.read_at(&mut v, at, &mut Vec::new())?;
        Ok(v[0])
    }

    fn sweep<const N: usize>(
        &self,
        ms: [usize; N],
        s: &mut [f64; N],
        mut k: usize,
        end: usize,
    ) -> io::Result<()> {
        // The offsets from `k - 1` each block reads at.
        let mut offsets: Vec<usize> = std::iter::once(0)
            .chain(ms)
            .chain(ms.map(|m| 2 * m))
            .collect();
        offsets.sort_unstable();
        offsets.dedup();
        let reach = offsets[offsets.len() - 1];
        if reach <= SLIDE * self.block {
            return self.slide(ms, s, k, end, reach);
        }
        // Offsets this far apart are more than a block apart: a range each.
        let (mut buf, mut bytes) = (Vec::new(), Vec::new());
        while k < end {
            let run = (end - k).min(self.block);
            buf.resize(offsets.len() * run, 0.0);
            for (range, &o) in buf.chunks_exact_mut(run).zip(&offsets) {
                let at = self.angles.at + 8 * (k - 1 + o) as u64;
                self.spill.read_at(range, at, &mut bytes)?;
            }
            let from = |o: usize| {
                let i = offsets.binary_search(&o).expect("an offset read");
                &buf[i * run..][..run]
            };
            add_run(from(0), ms.map(from), ms.map(|m| from(2 * m)), s);
            k += run;
        }
        Ok(())
    }
}

/// `buf` written at byte `at` of `f`, without moving a shared cursor (the tasks share `f`).
#[cfg(unix)]
fn write_all_at(f: &File, buf: &[u8], at: u64) -> io::Result<()> {
    std::os::unix::fs::FileExt::write_all_at(f, buf, at)
}

/// `buf` filled from byte `at` of `f`, without moving a shared cursor.
#[cfg(unix)]
fn read_exact_at(f: &File, buf: &mut [u8], at: u64) -> io::Result<()> {
    std::os::unix::fs::FileExt::read_exact_at(f, buf, at)
}

/// As on unix: Windows' positioned IO moves the cursor, which no read here relies on.
#[cfg(windows)]
fn write_all_at(f: &File, mut buf: &[u8], mut at: u64) -> io::Result<()> {
    use std::os::windows::fs::FileExt;
    while !buf.is_empty() {
        match f.seek_write(buf, at)? {
            0 => return Err(io::ErrorKind::WriteZero.into()),
            n => (buf, at) = (&buf[n..], at + n as u64),
        }
    }
    Ok(())
}

/// As on unix: Windows' positioned IO moves the cursor, which no read here relies on.
#[cfg(windows)]
fn read_exact_at(f: &File, mut buf: &mut [u8], mut at: u64) -> io::Result<()> {
    use std::os::windows::fs::FileExt;
    while !buf.is_empty() {
        match f.seek_read(buf, at)? {
            0 => return Err(io::ErrorKind::UnexpectedEof.into()),
            n => (buf, at) = (&mut std::mem::take(&mut buf)[n..], at + n as u64),
        }
    }
    Ok(())
}
