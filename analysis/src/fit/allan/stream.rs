//! A spilled axis read back once, in series order: its rates are integrated to angles in a
//! ring that holds a window of the series (the farthest offset the near sizes read and
//! two blocks), and the sums of every cluster-size group whose offsets fit in it are taken
//! block by block as the angles come, so that those sizes need the file read once and
//! nothing written back. Sizes beyond it (a 2 kHz hour's largest) are summed afterwards
//! from the angles, written to the file as they come ([`super::spill::OnFile`]).
//!
//! Each sum adds its terms in the order of `k` as in memory (`group_sums`): the blocks go
//! in order, and within a block a size's swept part (`k < common`) comes before its own
//! tail.

use super::spill::{Angles, Spill};
use super::{Part, Theta, add_run, add_terms, first_terms, terms};
use std::io;

/// The sums of `near` (groups of cluster sizes, in order) over one axis's rates `parts`
/// sampled every `dt`, read `block` at a time, and, when `far` groups wait for them, the
/// angles written to the file.
pub(super) fn stream(
    spill: &Spill,
    parts: &[Part],
    dt: f64,
    near: &[Vec<usize>],
    far: bool,
    block: usize,
) -> io::Result<(Vec<Vec<f64>>, Option<Angles>)> {
    let n = parts.iter().map(Part::len).sum();
    let reach = near.iter().map(|g| 2 * g[g.len() - 1]).max().unwrap_or(0);
    if near.is_empty() {
        return Ok((Vec::new(), None));
    }
    let mut w = Window {
        n,
        near,
        sums: near.iter().map(|g| vec![0.0; g.len()]).collect(),
        ring: vec![0.0; reach + 2 * block],
        base: 0,
        filled: 0,
        // The last `k` any size sums at, and one.
        end: near.iter().map(|g| terms(n, g[0])).max().unwrap_or(1),
        reach,
        block,
        acc: 0.0,
        dt,
        angles: far.then(|| Angles::reserve(spill, n)),
        bytes: Vec::new(),
        spill,
    };
    let mut rates = Vec::new();
    let mut bytes = Vec::new();
    for p in parts {
        match p {
            Part::Held(v) => {
                for piece in v.chunks(block) {
                    w.add(piece)?;
                }
            }
            &Part::Spilled { at, len } => {
                for i in (0..len).step_by(block) {
                    rates.resize(block.min(len - i), 0.0);
                    spill.read_at(&mut rates, at + 8 * i as u64, &mut bytes)?;
                    w.add(&rates)?;
                }
            }
        }
    }
    while w.base + 1 < w.end {
        w.take_block();
    }
    Ok((w.sums, w.angles))
}

/// The angles `c[base .. filled]` of one axis as they come, in a ring (angle `i` at
/// `i % ring.len()`), and the sums taken so far.
struct Window<'a> {
    n: usize,
    near: &'a [Vec<usize>],
    sums: Vec<Vec<f64>>,
    ring: Vec<f64>,
    /// `k - 1` of the next block to sum: the first angle still needed.
    base: usize,
    /// Angles integrated so far.
    filled: usize,
    end: usize,
    /// The farthest offset from `k - 1` any size reads.
    reach: usize,
    block: usize,
    acc: f64,
    dt: f64,
    /// Where the angles are written, when they are.
    angles: Option<Angles>,
    bytes: Vec<u8>,
    spill: &'a Spill,
}

impl Window<'_> {
    /// The angles after these rates; every block whose angles are all in, summed.
    fn add(&mut self, mut rates: &[f64]) -> io::Result<()> {
        let r = self.ring.len();
        while !rates.is_empty() {
            let space = self.base + r - self.filled;
            let at = self.filled % r;
            let len = space.min(rates.len()).min(r - at);
            let (now, rest) = rates.split_at(len);
            // The running sum in a register: each addition waits on the one before.
            let (mut acc, dt) = (self.acc, self.dt);
            for (c, v) in self.ring[at..at + len].iter_mut().zip(now) {
                acc += v * dt;
                *c = acc;
            }
            self.acc = acc;
            if let Some(a) = self.angles {
                a.write(
                    self.spill,
                    self.filled,
                    &self.ring[at..at + len],
                    &mut self.bytes,
                )?;
            }
            self.filled += len;
            rates = rest;
            // The ring holds a block and its reach beyond at least: full, a block is due.
            while self.filled - self.base >= self.reach + self.block && self.base + 1 < self.end {
                self.take_block();
            }
        }
        Ok(())
    }

    /// Sums the block of `k` from `base + 1` (up to `block` long) and moves past it.
    fn take_block(&mut self) {
        let k0 = self.base + 1;
        let run = self.block.min(self.end - k0);
        let ring = Ring {
            ring: &self.ring,
            n: self.n,
        };
        for (s, g) in self.sums.iter_mut().zip(self.near) {
            if k0 == 1 {
                let Ok(first) = first_terms(&ring, g);
                *s = first;
            }
            let Ok(()) = add_terms(&ring, g, s, k0, k0 + run);
        }
        self.base += run;
    }
}

/// The angles in the ring, read as the whole series (`n` values) where they are held.
struct Ring<'a> {
    ring: &'a [f64],
    n: usize,
}

impl Theta for Ring<'_> {
    type Error = std::convert::Infallible;

    fn len(&self) -> usize {
        self.n
    }

    fn at(&self, i: usize) -> Result<f64, Self::Error> {
        Ok(self.ring[i % self.ring.len()])
    }

    fn sweep<const N: usize>(
        &self,
        ms: [usize; N],
        s: &mut [f64; N],
        k: usize,
        end: usize,
    ) -> Result<(), Self::Error> {
        sweep(self.ring, ms, s, k, end);
        Ok(())
    }
}

/// Adds to `s[j]` the squared second differences at cluster size `ms[j]` for `k` in
/// `[a, b)`, from the ring of the angles, a run at a time within which no read wraps.
fn sweep<const N: usize>(ring: &[f64], ms: [usize; N], s: &mut [f64; N], mut a: usize, b: usize) {
    let r = ring.len();
    while a < b {
        let offsets = std::iter::once(0).chain(ms).chain(ms.map(|m| 2 * m));
        let run = offsets.map(|o| r - (a - 1 + o) % r).fold(b - a, usize::min);
        let from = |o: usize| &ring[(a - 1 + o) % r..][..run];
        add_run(from(0), ms.map(from), ms.map(|m| from(2 * m)), s);
        a += run;
    }
}
