//! A segment's samples folded into the joint fit as they stream past: every effect's
//! regressors from the kinematic signals at each stamp, and per output channel the
//! triangular factor of `[X y]` plus one-second block sums.

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
    /// Samples.
    pub n: usize,
    /// Per channel, the sum of each of its regressors.
    pub sx: [Vec<f64>; 6],
    /// Per channel, the sum of the observations.
    pub sy: [f64; 6],
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
}

impl SegAcc {
    /// Adds the accumulation of a later piece of the same segment: the factors stacked and
    /// triangulated again, the blocks and counts joined.
    pub(crate) fn merge(&mut self, later: SegAcc) {
        for (c, r) in later.r.into_iter().enumerate() {
            let w = r.ncols();
            let mut m = DMatrix::zeros(self.r[c].nrows() + r.nrows(), w);
            m.view_mut((0, 0), self.r[c].shape()).copy_from(&self.r[c]);
            m.view_mut((self.r[c].nrows(), 0), r.shape()).copy_from(&r);
            self.r[c] = super::tri::triangle(m, w);
        }
        self.blocks.extend(later.blocks);
        self.n += later.n;
    }
}

/// Folds one segment's samples into the factors and block sums of every channel, a sample
/// at a time, so a segment of any length streams through.
pub(crate) struct Accumulator<'l> {
    seg: usize,
    layout: &'l Layout,
    tris: Vec<Tri>,
    parts: Vec<Partials>,
    row: Vec<f64>,
    blocks: Vec<Block>,
    cur: Block,
    block_end: f64,
    /// The signals `parts` were last filled from, time and temperature left out.
    filled: Option<Signals>,
    /// Layout indices of the effects whose regressors change at rest.
    varying: Vec<usize>,
}

impl<'l> Accumulator<'l> {
    /// An empty accumulation of segment `seg`, whose blocks start at `t_start`.
    pub(crate) fn new(seg: usize, t_start: f64, layout: &'l Layout) -> Self {
        let ncol = layout.cols.len();
        Accumulator {
            seg,
            layout,
            tris: (0..6)
                .map(|c| Tri::new(layout.by_channel[c].len() + 1))
                .collect(),
            parts: vec![Partials::default(); ncol],
            row: Vec::with_capacity(ncol + 1),
            blocks: Vec::new(),
            cur: Self::new_block(layout),
            block_end: t_start + BLOCK_S,
            filled: None,
            varying: (0..layout.effects.len())
                .filter(|&e| layout.effects[e].varies_at_rest())
                .collect(),
        }
    }

    fn new_block(layout: &Layout) -> Block {
        Block {
            t: 0.0,
            n: 0,
            sx: std::array::from_fn(|c| vec![0.0; layout.by_channel[c].len()]),
            sy: [0.0; 6],
        }
    }

    /// Adds the sample stamped `t` (`sig` at that instant) with these outputs; a sample
    /// with a non-finite output (a saturated channel) is left out.
    pub(crate) fn push(&mut self, sig: &Signals, t: f64, acc: [f64; 3], gyr: [f64; 3]) {
        let layout = self.layout;
        let base_a = sig.f_b;
        let base_g = sig.w_b_dps();
        let out = [
            acc[0] - base_a.x,
            acc[1] - base_a.y,
            acc[2] - base_a.z,
            gyr[0] - base_g.x,
            gyr[1] - base_g.y,
            gyr[2] - base_g.z,
        ];
        if out.iter().any(|v| !v.is_finite()) {
            return;
        }
        if t > self.block_end && self.cur.n > 0 {
            self.cur.t /= self.cur.n as f64;
            let full = std::mem::replace(&mut self.cur, Self::new_block(layout));
            self.blocks.push(full);
            self.block_end += BLOCK_S * ((t - self.block_end) / BLOCK_S).ceil().max(1.0);
        }
        // At rest only the terms that read the time or the temperature change.
        let mut motion = *sig;
        (motion.t_s, motion.dtemp_c) = (0.0, 0.0);
        if self.filled == Some(motion) {
            for &e in &self.varying {
                layout.effects[e].regressors(sig, &mut self.parts[layout.columns_of(e)]);
            }
        } else {
            for (e, fx) in layout.effects.iter().enumerate() {
                fx.regressors(sig, &mut self.parts[layout.columns_of(e)]);
            }
            self.filled = Some(motion);
        }
        for c in 0..6 {
            let (sensor, ax) = channel(c);
            self.row.clear();
            for &g in &layout.by_channel[c] {
                self.row.push(self.parts[g].of(sensor)[ax]);
            }
            self.row.push(out[c]);
            self.tris[c].push(&self.row);
            for (k, v) in self.row[..self.row.len() - 1].iter().enumerate() {
                self.cur.sx[c][k] += v;
            }
            self.cur.sy[c] += out[c];
        }
        self.cur.t += t;
        self.cur.n += 1;
    }

    /// The segment's contribution.
    pub(crate) fn finish(mut self) -> SegAcc {
        if self.cur.n > 0 {
            self.cur.t /= self.cur.n as f64;
            self.blocks.push(self.cur);
        }
        let n = self.tris[0].n;
        let mut it = self.tris.into_iter().map(Tri::finish);
        SegAcc {
            seg: self.seg,
            r: std::array::from_fn(|_| it.next().expect("six channels")),
            blocks: self.blocks,
            n,
        }
    }
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
