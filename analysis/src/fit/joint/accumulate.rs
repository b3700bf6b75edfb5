//! A segment's samples folded into the joint fit as they stream past: every effect's
//! regressors from the kinematic signals at each stamp, and per output channel the
//! triangular factor of `[X y]` plus one-second block sums.

use super::rest::{Positions, Rest, stack};
use super::tri::Tri;
use super::{Layout, channel};
use nalgebra::{DMatrix, DVector};
use ratecal_physics::effects::{Partials, Signals};

/// Length of the blocks kept for the noise analysis, s.
pub(crate) const BLOCK_S: f64 = 1.0;

/// Sums over one block of samples of one segment.
#[derive(Debug, Clone)]
pub(crate) struct Block {
    /// Mean stamp, s.
    pub t: f64,
    /// The end of the block's second on its segment's grid, s.
    pub end: f64,
    /// Samples.
    pub n: usize,
    /// Per channel, the sum of each of its regressors.
    pub sx: [Vec<f64>; 6],
    /// Per channel, the sum of the observations.
    pub sy: [f64; 6],
}

impl Block {
    /// Adds the samples of `b`, the rest of the same second.
    fn join(&mut self, b: Block) {
        let n = (self.n + b.n) as f64;
        self.t = (self.t * self.n as f64 + b.t * b.n as f64) / n;
        self.n += b.n;
        for c in 0..6 {
            for (s, x) in self.sx[c].iter_mut().zip(&b.sx[c]) {
                *s += x;
            }
            self.sy[c] += b.sy[c];
        }
    }
}

/// What a segment contributes to any fit.
#[derive(Debug, Clone)]
pub(crate) struct SegAcc {
    /// Index of the segment in the manifest.
    pub seg: usize,
    /// Per channel, the factor of `[X y]` over the channel's columns.
    pub r: [DMatrix<f64>; 6],
    /// One-second blocks in time order.
    pub blocks: Vec<Block>,
    /// Samples.
    pub n: usize,
    /// The blocks' sums laid out per channel as columns ([`SegAcc::block_sums`]), built on
    /// first use; whatever changes `blocks` calls [`SegAcc::blocks_changed`].
    columns: std::sync::OnceLock<Box<[BlockColumns; 6]>>,
}

/// One channel's block sums, column by column: a fit reads a few columns over every block
/// hundreds of times, which the per-block vectors make a cache miss a block.
#[derive(Debug, Clone)]
struct BlockColumns {
    /// Blocks x the channel's columns: the sums of each regressor.
    sx: DMatrix<f64>,
    /// Per block, the sum of the observations.
    sy: Vec<f64>,
}

impl SegAcc {
    /// An accumulation of these blocks alone (no factor): for tests of what reads blocks.
    #[cfg(test)]
    pub(crate) fn of_blocks(seg: usize, blocks: Vec<Block>) -> SegAcc {
        SegAcc {
            seg,
            r: Default::default(),
            n: blocks.iter().map(|b| b.n).sum(),
            blocks,
            columns: Default::default(),
        }
    }

    /// Per block of channel `c`, the sum of its residuals under the channel's coefficients
    /// `nonzero` (`(column within the channel, coefficient)`, the zero ones left out).
    pub(crate) fn block_sums(&self, c: usize, nonzero: &[(usize, f64)]) -> Vec<f64> {
        let cols = self.columns(c);
        let mut s = cols.sy.clone();
        let n = s.len();
        // Column-major: a column is a slice (no strided iterator in the loop).
        let sx = cols.sx.as_slice();
        for &(k, th) in nonzero {
            for (s, x) in s.iter_mut().zip(&sx[k * n..(k + 1) * n]) {
                *s -= x * th;
            }
        }
        s
    }

    /// Blocks x channel `c`'s columns: the sums of each regressor over each block.
    pub(crate) fn block_regressors(&self, c: usize) -> &DMatrix<f64> {
        &self.columns(c).sx
    }

    fn columns(&self, c: usize) -> &BlockColumns {
        let cols = &self.columns.get_or_init(|| Box::new(self.lay_out()))[c];
        debug_assert_eq!(cols.sy.len(), self.blocks.len());
        cols
    }

    fn lay_out(&self) -> [BlockColumns; 6] {
        std::array::from_fn(|c| {
            let p = self.blocks.first().map_or(0, |b| b.sx[c].len());
            BlockColumns {
                sx: DMatrix::from_fn(self.blocks.len(), p, |i, k| self.blocks[i].sx[c][k]),
                sy: self.blocks.iter().map(|b| b.sy[c]).collect(),
            }
        })
    }

    /// The blocks were changed: the columns are laid out again on next use.
    pub(crate) fn blocks_changed(&mut self) {
        self.columns = Default::default();
    }

    /// Adds the accumulation of a later piece of the same segment: the factors stacked and
    /// triangulated again, the blocks and counts joined.
    /// A block the two pieces share (one second cut by the pieces' boundary, both on one
    /// grid) is joined again.
    pub(crate) fn merge(&mut self, later: SegAcc) {
        self.blocks_changed();
        for (c, r) in later.r.into_iter().enumerate() {
            self.r[c] = stack(&self.r[c], &r);
        }
        let mut blocks = later.blocks.into_iter().peekable();
        if let (Some(a), Some(b)) = (self.blocks.last_mut(), blocks.peek())
            && a.end == b.end
        {
            a.join(blocks.next().expect("peeked"));
        }
        self.blocks.extend(blocks);
        self.n += later.n;
    }
}

/// Folds one segment's samples into the factors and block sums of every channel, a sample
/// at a time, so a segment of any length streams through.
///
/// At rest only the terms that read the time or the temperature change from sample to
/// sample: only their columns are evaluated, written into each channel's row and added
/// to the block sums; the other columns' sums are their value times the samples they held
/// it for, added when the motion changes or the block ends.
pub(crate) struct Accumulator<'l> {
    seg: usize,
    layout: &'l Layout,
    tris: Vec<Tri>,
    parts: Vec<Partials>,
    /// Per channel, the current row: its columns, then the observation.
    rows: [Vec<f64>; 6],
    blocks: Vec<Block>,
    cur: Block,
    block_end: f64,
    /// The signals `parts` were last filled from, time and temperature left out.
    filled: Option<Signals>,
    /// The effects whose regressors change at rest, with their columns.
    varying: Vec<(&'l dyn ratecal_physics::Effect, std::ops::Range<usize>)>,
    /// Per channel, the positions in its row that change at rest (the observation's
    /// included, last), ascending.
    moving: [Vec<usize>; 6],
    /// Per channel, the positions that keep their value at rest.
    resting: [Vec<usize>; 6],
    /// Per channel, `(position, layout column)` of the regressors that change at rest.
    fetch: [Vec<(usize, usize)>; 6],
    /// Samples since the resting columns' values were last added to the block sums.
    pending: usize,
    /// Per sensor, the rows at rest folded once for its three channels ([`Rest`]).
    rest: [Rest; 2],
    /// Samples folded.
    n: usize,
    /// Whether the first sample's block is found on the grid from `block_end` on (a later
    /// piece of a segment), not taken to be the first.
    align: bool,
}

impl<'l> Accumulator<'l> {
    /// An empty accumulation of segment `seg`, whose blocks start at `t_start`.
    pub(crate) fn new(seg: usize, t_start: f64, layout: &'l Layout) -> Self {
        let ncol = layout.cols.len();
        let varying: Vec<usize> = (0..layout.effects.len())
            .filter(|&e| layout.effects[e].varies_at_rest())
            .collect();
        let varies = |g: usize| varying.contains(&layout.cols[g].effect);
        let positions = |c: usize, want: bool| -> Vec<usize> {
            let cols = &layout.by_channel[c];
            let mut v: Vec<usize> = (0..cols.len())
                .filter(|&k| varies(cols[k]) == want)
                .collect();
            if want {
                v.push(cols.len());
            }
            v
        };
        let moving: [Vec<usize>; 6] = std::array::from_fn(|c| positions(c, true));
        // The regressors among them (the observation, last, is not fetched).
        let fetch = std::array::from_fn(|c| {
            let k = &moving[c][..moving[c].len() - 1];
            k.iter().map(|&k| (k, layout.by_channel[c][k])).collect()
        });
        Accumulator {
            seg,
            layout,
            tris: (0..6)
                .map(|c| Tri::new(layout.by_channel[c].len() + 1))
                .collect(),
            parts: vec![Partials::default(); ncol],
            rows: std::array::from_fn(|c| vec![0.0; layout.by_channel[c].len() + 1]),
            blocks: Vec::new(),
            cur: Self::new_block(layout),
            block_end: t_start + BLOCK_S,
            filled: None,
            fetch,
            moving,
            resting: std::array::from_fn(|c| positions(c, false)),
            varying: (varying.iter())
                .map(|&e| (layout.effects[e], layout.columns_of(e)))
                .collect(),
            pending: 0,
            rest: Default::default(),
            n: 0,
            align: false,
        }
    }

    /// The samples to come are a later piece of the segment: their blocks lie on the grid
    /// of its start, as in one pass over the whole segment.
    pub(crate) fn continue_grid(&mut self) {
        self.align = true;
    }

    fn new_block(layout: &Layout) -> Block {
        Block {
            t: 0.0,
            end: f64::NAN,
            n: 0,
            sx: std::array::from_fn(|c| vec![0.0; layout.by_channel[c].len()]),
            sy: [0.0; 6],
        }
    }

    /// Adds the resting columns' values for the samples that held them to the block sums.
    fn settle(&mut self) {
        if self.pending == 0 {
            return;
        }
        let n = self.pending as f64;
        for c in 0..6 {
            for &k in &self.resting[c] {
                self.cur.sx[c][k] += self.rows[c][k] * n;
            }
        }
        self.pending = 0;
    }

    /// Writes channel `c`'s columns into its row from `parts`, every one of them, and adds
    /// them to the block's sums.
    fn write_row(&mut self, c: usize) {
        let (sensor, ax) = channel(c);
        let cols = &self.layout.by_channel[c];
        let (row, sx) = (&mut self.rows[c], &mut self.cur.sx[c]);
        for (k, &g) in cols.iter().enumerate() {
            row[k] = self.parts[g].of(sensor)[ax];
            sx[k] += row[k];
        }
    }

    /// At rest: writes channel `c`'s columns that change at rest into its row from
    /// `parts`, and adds them to the block's sums.
    fn write_moving(&mut self, c: usize) {
        let (sensor, ax) = channel(c);
        let (row, sx) = (&mut self.rows[c], &mut self.cur.sx[c]);
        for &(k, g) in &self.fetch[c] {
            let v = self.parts[g].of(sensor)[ax];
            row[k] = v;
            sx[k] += v;
        }
    }

    /// Adds the sample stamped `t` (`sig` at that instant) with these outputs; a sample
    /// with a non-finite output (a saturated channel) is left out.
    pub(crate) fn push(&mut self, sig: &Signals, t: f64, acc: [f64; 3], gyr: [f64; 3]) {
        let layout = self.layout;
        let out = observed(sig, acc, gyr);
        if out.iter().any(|v| !v.is_finite()) {
            return;
        }
        if self.align {
            // The grid's seconds one by one, as the pass over the whole segment steps
            // them when no second is empty.
            while t > self.block_end {
                self.block_end += BLOCK_S;
            }
            self.align = false;
        }
        if t > self.block_end && self.cur.n > 0 {
            self.settle();
            self.cur.t /= self.cur.n as f64;
            self.cur.end = self.block_end;
            let full = std::mem::replace(&mut self.cur, Self::new_block(layout));
            self.blocks.push(full);
            self.block_end += BLOCK_S * ((t - self.block_end) / BLOCK_S).ceil().max(1.0);
        }
        // At rest only the terms that read the time or the temperature change.
        let mut motion = *sig;
        (motion.t_s, motion.dtemp_c) = (0.0, 0.0);
        let at_rest = self.filled == Some(motion);
        if at_rest {
            for (fx, cols) in &self.varying {
                fx.regressors(sig, &mut self.parts[cols.clone()]);
            }
        } else {
            self.settle();
            for (e, fx) in layout.effects.iter().enumerate() {
                fx.regressors(sig, &mut self.parts[layout.columns_of(e)]);
            }
            self.filled = Some(motion);
        }
        for c in 0..6 {
            match at_rest {
                true => self.write_moving(c),
                false => self.write_row(c),
            }
            let last = self.rows[c].len() - 1;
            self.rows[c][last] = out[c];
            self.cur.sy[c] += out[c];
        }
        for s in 0..2 {
            let ch = 3 * s..3 * s + 3;
            let at = Positions::sensor(&self.moving, &self.resting, s);
            let shared = match at_rest {
                true => self.rest[s].take(&self.rows[ch.clone()], &at),
                false => {
                    self.rest[s].interrupt(&at);
                    false
                }
            };
            if !shared {
                for c in ch {
                    let changed = at_rest.then_some(self.moving[c].as_slice());
                    self.tris[c].push_changed(&self.rows[c], changed);
                }
            }
        }
        // The resting columns were added whole for a sample that changed the motion.
        self.pending += usize::from(at_rest);
        self.cur.t += t;
        self.cur.n += 1;
        self.n += 1;
    }

    /// The segment's contribution.
    pub(crate) fn finish(mut self) -> SegAcc {
        self.settle();
        if self.cur.n > 0 {
            self.cur.t /= self.cur.n as f64;
            self.cur.end = self.block_end;
            self.blocks.push(self.cur);
        }
        for s in 0..2 {
            self.rest[s].interrupt(&Positions::sensor(&self.moving, &self.resting, s));
        }
        let rest = &self.rest;
        let mut it = self.tris.into_iter().enumerate().map(|(c, t)| {
            let r = t.finish();
            match rest[c / 3].factor(c % 3) {
                Some(f) => stack(&r, f),
                None => r,
            }
        });
        SegAcc {
            seg: self.seg,
            r: std::array::from_fn(|_| it.next().expect("six channels")),
            blocks: self.blocks,
            n: self.n,
            columns: Default::default(),
        }
    }
}

/// The outputs less what ideal sensors read (the specific force, m/s^2, and the inertial
/// rate, deg/s): the observation each channel's row ends with.
fn observed(sig: &Signals, acc: [f64; 3], gyr: [f64; 3]) -> [f64; 6] {
    let (f, w) = (sig.f_b, sig.w_b_dps());
    [
        acc[0] - f.x,
        acc[1] - f.y,
        acc[2] - f.z,
        gyr[0] - w.x,
        gyr[1] - w.y,
        gyr[2] - w.z,
    ]
}

/// Residual sum of squares of channel `c` of a segment for global coefficients `theta`
/// (zero for columns outside the model): `|R [theta_c; -1]|^2`.
pub(crate) fn seg_rss(acc: &SegAcc, layout: &Layout, c: usize, theta: &DVector<f64>) -> f64 {
    let cols = &layout.by_channel[c];
    let mut v = DVector::zeros(cols.len() + 1);
    for (k, &g) in cols.iter().enumerate() {
        v[k] = theta[g];
    }
    v[cols.len()] = -1.0;
    (&acc.r[c] * v).norm_squared()
}

#[cfg(test)]
mod tests {
    use super::*;
    use ratecal_physics::effects::Signals;
    use ratecal_physics::{Geometry, REGISTRY, Site, TableState};

    /// Rows at rest at one attitude, then at another, each with the time and temperature
    /// moving: the columns that keep their value at rest are summed once per stretch
    /// and left out of the factor's comparisons, which must change nothing but rounding.
    #[test]
    fn resting_columns_sum_and_fold_as_the_rows_do() {
        let layout = Layout::new(REGISTRY.to_vec());
        let site = Site {
            latitude_deg: 50.0,
            gravity_mps2: 9.81,
        };
        let geo = Geometry::seed();
        let rest = |o: f64, i: f64| {
            Signals::new(
                &TableState::at_rest_deg(o, i).snapshot(&geo, &site),
                &site,
                0.0,
            )
        };
        let (a, b) = (rest(0.0, 0.0), rest(90.0, 30.0));
        let mut acc = Accumulator::new(0, 0.0, &layout);
        let mut rows: [Vec<Vec<f64>>; 6] = Default::default();
        let mut parts = vec![Partials::default(); layout.cols.len()];
        for i in 0..700 {
            let t = i as f64 * 0.01;
            let mut s = if i < 430 { a } else { b }.at(t);
            s.dtemp_c = 0.3 * (t * 1.7).sin();
            let (fa, fg) = ([0.01, -0.02, 9.8 + 1e-3 * t], [0.3, 0.1 * t, -0.2]);
            acc.push(&s, t, fa, fg);
            for (e, fx) in layout.effects.iter().enumerate() {
                fx.regressors(&s, &mut parts[layout.columns_of(e)]);
            }
            let out = observed(&s, fa, fg);
            for (c, r) in rows.iter_mut().enumerate() {
                let (sensor, ax) = channel(c);
                let mut row: Vec<f64> = (layout.by_channel[c].iter())
                    .map(|&g| parts[g].of(sensor)[ax])
                    .collect();
                row.push(out[c]);
                r.push(row);
            }
        }
        let got = acc.finish();
        assert_eq!(got.blocks.len(), 7);
        assert_eq!(got.blocks.iter().map(|b| b.n).sum::<usize>(), 700);
        for (c, r) in rows.iter().enumerate() {
            let p = r[0].len();
            let x = DMatrix::from_fn(r.len(), p, |i, k| r[i][k]);
            let (g, h) = (x.transpose() * &x, got.r[c].transpose() * &got.r[c]);
            assert!((&g - &h).norm() <= 1e-12 * g.norm(), "channel {c}");
            let mut from = 0;
            for (j, blk) in got.blocks.iter().enumerate() {
                let rows_in = &r[from..from + blk.n];
                from += blk.n;
                for k in 0..p - 1 {
                    let want: f64 = rows_in.iter().map(|row| row[k]).sum();
                    let tol = 1e-12 * rows_in.iter().map(|row| row[k].abs()).sum::<f64>();
                    assert!((blk.sx[c][k] - want).abs() <= tol, "{c} {j} {k}");
                }
            }
        }
    }
}
