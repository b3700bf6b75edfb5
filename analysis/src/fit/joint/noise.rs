//! The noise of a fit's residuals, judged the way physics.md asks: white noise (with the
//! correlation a low-pass filter leaves, from one-second block means) and a wandering
//! bias (a random walk, from the growth of ten-second block-mean differences), so that
//! slowly varying regressors are judged against the low-frequency noise.

use super::accumulate::SegAcc;
use nalgebra::{DMatrix, DVector};

/// The noise model of one channel.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct ChannelNoise {
    /// Residual standard deviation per sample.
    pub sigma: f64,
    /// Variance of a mean of n samples is `sigma^2 * phi / n` for white-like noise.
    pub phi: f64,
    /// Random-walk intensity of the residual, (unit^2) per second.
    pub q: f64,
}

/// Lags of the wander's pairs, in ten-second groups (10 s to about 3 min): the longer lags
/// carry the wander the segments' spacing exposes the fit to.
const LAGS: [usize; 5] = [1, 2, 4, 8, 16];

/// Standard errors added to the wander's estimate: a recording with one static of a few
/// minutes tells the wander only roughly, and a test judged against an estimate that came
/// out low would see slow forms in it (a wander that returns, Gauss-Markov, most of all).
const WANDER_SE: f64 = 1.0;

/// The wander's intensity from its pairs `(d^2 - white, lag)`: the pooled estimate plus
/// [`WANDER_SE`] of its standard error (from the pairs' scatter about it).
fn wander_of(pairs: &[(f64, f64)]) -> f64 {
    let (n, d) = pairs
        .iter()
        .fold((0.0, 0.0), |(n, d), p| (n + p.0, d + p.1));
    if d <= 0.0 {
        return 0.0;
    }
    let q = n / d;
    let scatter: f64 = pairs.iter().map(|p| (p.0 - q * p.1).powi(2)).sum();
    (q + WANDER_SE * scatter.sqrt() / d).max(0.0)
}

/// One-second blocks from which a segment's own white level is taken for its wander.
const OWN_WHITE_BLOCKS: usize = 60;

/// Estimates the noise of channel `c` over the fitted segments; the wander only when
/// `wander` (a white-noise covariance has no use for it).
pub(crate) fn estimate(
    accs: &[&SegAcc],
    c: usize,
    theta_c: &[f64],
    sigma: f64,
    wander: bool,
) -> ChannelNoise {
    // White-equivalent variance of a sample from adjacent one-second blocks.
    let (mut num, mut den) = (0.0, 0.0);
    // Random walk from ten-second groups.
    let mut groups: Vec<(f64, f64, usize, f64)> = Vec::new(); // (span in blocks, t, n, mean)
    // Pairs of groups, with their segment's own white level (None: the channel's).
    let mut pairs = Vec::new();
    let nonzero: Vec<(usize, f64)> = theta_c
        .iter()
        .enumerate()
        .filter(|(_, th)| **th != 0.0)
        .map(|(k, th)| (k, *th))
        .collect();
    for acc in accs {
        let sums = acc.block_sums(c, &nonzero);
        let means: Vec<(f64, usize, f64)> = (acc.blocks.iter().zip(sums))
            .map(|(b, s)| (b.t, b.n, s / b.n as f64))
            .collect();
        let (mut seg_num, mut seg_den) = (0.0, 0.0);
        for w in means.windows(2) {
            let (n1, n2) = (w[0].1 as f64, w[1].1 as f64);
            seg_num += (w[1].2 - w[0].2).powi(2);
            seg_den += 1.0 / n1 + 1.0 / n2;
        }
        num += seg_num;
        den += seg_den;
        if !wander {
            continue;
        }
        // The white level the segment's own block means show (a long segment's is
        // precise), so that a misfit of the motion elsewhere, which raises the channel's,
        // does not hide the wander here.
        let own = (means.len() >= OWN_WHITE_BLOCKS).then(|| (seg_num / seg_den).max(sigma * sigma));
        groups.clear();
        for chunk in means.chunks(10) {
            let n: usize = chunk.iter().map(|m| m.1).sum();
            let t = chunk.iter().map(|m| m.0 * m.1 as f64).sum::<f64>() / n as f64;
            let m = chunk.iter().map(|m| m.2 * m.1 as f64).sum::<f64>() / n as f64;
            let span = chunk.len() as f64;
            groups.push((span, t, n, m));
        }
        for lag in LAGS {
            for i in lag..groups.len() {
                pairs.push((groups[i - lag], groups[i], own));
            }
        }
    }
    let a = if den > 0.0 { num / den } else { sigma * sigma };
    let phi = if sigma > 0.0 {
        (a / (sigma * sigma)).max(1.0)
    } else {
        1.0
    };
    let a = sigma * sigma * phi;
    let excess: Vec<(f64, f64)> = (pairs.into_iter())
        .filter_map(|(g1, g2, own)| {
            let d2 = (g2.3 - g1.3).powi(2);
            let white = own.unwrap_or(a) * (1.0 / g1.2 as f64 + 1.0 / g2.2 as f64);
            let lag = (g2.1 - g1.1) - (g1.0 + g2.0) / 6.0;
            (lag > 0.0).then_some((d2 - white, lag))
        })
        .collect();
    ChannelNoise {
        sigma,
        phi,
        q: wander_of(&excess),
    }
}

/// `X^T Sigma_rw X / q` for a random walk starting at the first block: sums over the
/// blocks in time order of the gap times the outer product of the regressor sums after it.
pub(crate) fn random_walk_gram(
    accs: &[&SegAcc],
    c: usize,
    local: &[Option<usize>],
    p: usize,
) -> DMatrix<f64> {
    // The channel's columns in the model: the model holds few of them, so the walk is
    // summed over those alone and scattered into the model's `p x p` at the end.
    let used = used_columns(local);
    let ks: Vec<usize> = used.iter().map(|u| u.0).collect();
    let small = walk_lower(accs, c, &ks);
    let at: Vec<(usize, usize)> = (used.iter().enumerate())
        .map(|(i, &(_, l))| (i, l))
        .collect();
    scatter_lower(&small, &at, p)
}

/// `(column within the channel, model column)` of the channel's columns the model holds.
pub(crate) fn used_columns(local: &[Option<usize>]) -> Vec<(usize, usize)> {
    (local.iter().enumerate())
        .filter_map(|(k, l)| Some((k, (*l)?)))
        .collect()
}

/// The walk's Gram over channel `c`'s columns `ks`, lower triangle only: entry `(i, j)` is
/// the same sum of the same products in the same order whichever other columns are
/// asked for, so a Gram over all of a channel's columns holds every model's.
pub(crate) fn walk_lower(accs: &[&SegAcc], c: usize, ks: &[usize]) -> DMatrix<f64> {
    // (time, segment, block) in time order.
    let mut blocks: Vec<(f64, usize, usize)> = (accs.iter().enumerate())
        .flat_map(|(s, a)| a.blocks.iter().enumerate().map(move |(i, b)| (b.t, s, i)))
        .collect();
    blocks.sort_by(|a, b| a.0.total_cmp(&b.0));
    let sums: Vec<&DMatrix<f64>> = accs.iter().map(|a| a.block_regressors(c)).collect();
    let u = ks.len();
    let mut small = DMatrix::zeros(u, u);
    let mut suffix = DVector::zeros(u);
    // Walk backwards: suffix sums of the regressors after each gap.
    for w in (1..blocks.len()).rev() {
        let (t, s, b) = blocks[w];
        for (i, &k) in ks.iter().enumerate() {
            suffix[i] += sums[s][(b, k)];
        }
        let gap = t - blocks[w - 1].0;
        small.syger(gap, &suffix, &suffix, 1.0);
    }
    small
}

/// A `p x p` symmetric matrix from the lower triangle `lower`: `at` pairs a row of
/// `lower` with a model column.
pub(crate) fn scatter_lower(lower: &DMatrix<f64>, at: &[(usize, usize)], p: usize) -> DMatrix<f64> {
    let mut m = DMatrix::zeros(p, p);
    for &(i, li) in at {
        for &(j, lj) in at {
            // `syger` fills the lower triangle only.
            m[(li, lj)] = if i >= j { lower[(i, j)] } else { lower[(j, i)] };
        }
    }
    m
}

/// The honest noise of a series of block means in time order (white noise of variance
/// `sigma^2 phi / n` per block plus a bias wandering as a random walk of intensity `q`
/// from the first block) as a scalar Kalman filter: [`Whitener::apply`] maps a series to
/// its standardised innovations, which is `L^-1 v` for the Cholesky factor `L` of that
/// covariance, in O(blocks) instead of O(blocks^3).
pub(crate) struct Whitener {
    /// Per block: the Kalman gain and `1 / sqrt` of the innovation's variance.
    gains: Vec<(f64, f64)>,
}

impl Whitener {
    /// The filter for blocks at times `t` (ascending, s) of `n` samples each.
    pub(crate) fn new(t: &[f64], n: &[usize], noise: &ChannelNoise) -> Self {
        let white = (noise.sigma * noise.sigma * noise.phi).max(1e-300);
        let mut p = 0.0;
        let gains = (0..t.len())
            .map(|b| {
                if b > 0 {
                    p += noise.q * (t[b] - t[b - 1]).max(0.0);
                }
                let r = white / n[b].max(1) as f64;
                let s = p + r;
                p *= r / s;
                ((p / r).min(1.0), 1.0 / s.sqrt())
            })
            .collect();
        Whitener { gains }
    }

    /// The standardised innovations of series `v`.
    pub(crate) fn apply(&self, v: &[f64]) -> Vec<f64> {
        let mut w = 0.0;
        self.gains
            .iter()
            .zip(v)
            .map(|(&(k, inv_s), &x)| {
                let nu = x - w;
                w += k * nu;
                nu * inv_s
            })
            .collect()
    }
}
