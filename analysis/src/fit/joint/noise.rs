//! The noise of a fit's residuals, judged the way physics.md asks: white noise (with the
//! correlation a low-pass filter leaves, from one-second block means) and a wandering
//! bias (a random walk, from the growth of ten-second block-mean differences), so that
//! slowly varying regressors are judged against the low-frequency noise.

use super::accumulate::SegAcc;
use nalgebra::DMatrix;

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

/// The walk's Gram over channel `c`'s columns `ks` (read its lower triangle): the sum over
/// the gaps between blocks, in time order, of the gap times the outer product of the
/// regressor sums after it. The suffix sums are laid out one gap to a column and the sum
/// is one matrix product, so a Gram over all of a channel's columns (every model's Gram
/// is a part of it) costs what a product of that size does.
pub(crate) fn walk_lower(accs: &[&SegAcc], c: usize, ks: &[usize]) -> DMatrix<f64> {
    // (time, segment, block) in time order.
    let mut blocks: Vec<(f64, usize, usize)> = (accs.iter().enumerate())
        .flat_map(|(s, a)| a.blocks.iter().enumerate().map(move |(i, b)| (b.t, s, i)))
        .collect();
    blocks.sort_by(|a, b| a.0.total_cmp(&b.0));
    let sums: Vec<&DMatrix<f64>> = accs.iter().map(|a| a.block_regressors(c)).collect();
    let u = ks.len();
    let mut gram = DMatrix::zeros(u, u);
    // A chunk of gaps at a time, column `j` the suffix sums after one gap (and the same
    // times the gap): the product of a chunk is added to the Gram, and the chunk's columns
    // stay few (an hour at 1 kHz has 3,600 gaps of 80 columns a channel).
    let mut after = DMatrix::zeros(u, WALK_CHUNK);
    let mut weighed = DMatrix::zeros(u, WALK_CHUNK);
    let mut suffix = vec![0.0; u];
    let mut j = 0;
    // Walk backwards: suffix sums of the regressors after each gap.
    for w in (1..blocks.len()).rev() {
        let (t, s, b) = blocks[w];
        let gap = t - blocks[w - 1].0;
        for (i, &k) in ks.iter().enumerate() {
            suffix[i] += sums[s][(b, k)];
            after[(i, j)] = suffix[i];
            weighed[(i, j)] = gap * suffix[i];
        }
        j += 1;
        if j == WALK_CHUNK || w == 1 {
            let (a, g) = (after.columns(0, j), weighed.columns(0, j));
            gram.gemm(1.0, &a, &g.transpose(), 1.0);
            j = 0;
        }
    }
    gram
}

/// Gaps per product of the walk's Gram ([`walk_lower`]).
const WALK_CHUNK: usize = 512;

/// A `p x p` symmetric matrix from the lower triangle `lower`: `at` pairs a row of
/// `lower` with a model column.
pub(crate) fn scatter_lower(lower: &DMatrix<f64>, at: &[(usize, usize)], p: usize) -> DMatrix<f64> {
    let mut m = DMatrix::zeros(p, p);
    for &(i, li) in at {
        for &(j, lj) in at {
            // One triangle for both: the product is symmetric only up to rounding.
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::joint::accumulate::Block;

    /// Blocks of one segment at times `t`, channel 3's five regressor sums drawn from `f`.
    fn segment(seg: usize, t: impl Iterator<Item = f64>, f: impl Fn(f64, usize) -> f64) -> SegAcc {
        let blocks = t
            .map(|t| {
                let mut sx: [Vec<f64>; 6] = Default::default();
                sx[3] = (0..5).map(|k| f(t, k)).collect();
                Block {
                    t,
                    end: t.ceil(),
                    n: 100,
                    sx,
                    sy: [0.0; 6],
                }
            })
            .collect();
        SegAcc::of_blocks(seg, blocks)
    }

    #[test]
    fn the_walk_gram_is_the_textbook_sum_over_the_gaps_in_time_order() {
        // Two segments whose blocks interleave in time, over more gaps than a chunk.
        let a = segment(0, (0..900).map(|i| 0.5 + i as f64), |t, k| {
            (t * 0.01 * (k + 1) as f64).sin() * 10f64.powi(k as i32)
        });
        let b = segment(1, (0..400).map(|i| 0.25 + 2.0 * i as f64), |t, k| {
            1.0 + t * k as f64 - 3.0 * (k == 4) as u8 as f64
        });
        let accs = [&a, &b];
        // The textbook: every block in time order, the suffix sums after each gap.
        let mut all: Vec<(f64, Vec<f64>)> = (accs.iter())
            .flat_map(|s| s.blocks.iter().map(|b| (b.t, b.sx[3].clone())))
            .collect();
        all.sort_by(|x, y| x.0.total_cmp(&y.0));
        let ks = [0, 2, 4];
        let mut want = DMatrix::<f64>::zeros(3, 3);
        for w in 1..all.len() {
            let s: Vec<f64> = ks
                .iter()
                .map(|&k| all[w..].iter().map(|b| b.1[k]).sum())
                .collect();
            let gap = all[w].0 - all[w - 1].0;
            for i in 0..3 {
                for j in 0..3 {
                    want[(i, j)] += gap * s[i] * s[j];
                }
            }
        }
        let got = walk_lower(&accs, 3, &ks);
        for i in 0..3 {
            for j in 0..=i {
                let tol = 1e-12 * (want[(i, i)] * want[(j, j)]).sqrt();
                assert!(
                    (got[(i, j)] - want[(i, j)]).abs() <= tol,
                    "{i} {j}: {got} {want}"
                );
            }
        }
        // A Gram over all five columns holds the three columns' (what a pooled fit reads).
        let full = walk_lower(&accs, 3, &[0, 1, 2, 3, 4]);
        let part = scatter_lower(&full, &[(0, 0), (2, 1), (4, 2)], 3);
        let small = scatter_lower(&got, &[(0, 0), (1, 1), (2, 2)], 3);
        assert!(
            (&part - &small).norm() <= 1e-12 * small.norm(),
            "{part} {small}"
        );
        assert_eq!(part, part.transpose());
    }
}
