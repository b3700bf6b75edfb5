//! Change points anywhere in time (docs/explain.md, "Change points"): a bias that jumps
//! inside a segment, which the library's steps (tried only between segments) miss or put
//! at the wrong gap.
//!
//! Everything is read from the final model's residual per one-second block (exact: a block
//! keeps the sums of its regressors and observations). At every block boundary of every
//! segment and channel the mean residual of up to [`WINDOW`] blocks after is compared with
//! the mean before; the test's variance is the white noise's (with its correlation, `phi`)
//! plus the wandering bias's (`q`: the difference of two adjacent window means of a random
//! walk has variance `q * 2L/3`), so a Gauss-Markov wander is not a step. The threshold is
//! Bonferroni over every position tried and every column of the library. A change point is
//! located by the profile of the misfit of a two-level fit of its segment over every
//! boundary (weights `exp(-chi2/2)`), which gives its instant's standard uncertainty.

use super::data::Data;
use crate::fit::joint::Fit;

/// Blocks (s) each side of a boundary in the window test.
const WINDOW: usize = 60;
/// Fewest blocks each side of a boundary.
const LEAST: usize = 5;
/// Most change points reported in one recording.
const MOST: usize = 4;

/// A bias change point found inside a segment.
#[derive(Debug, Clone)]
pub(crate) struct ChangePoint {
    /// Output channel (0..6).
    pub channel: usize,
    /// Index into `data.accs`.
    pub acc: usize,
    /// The instant (s) and its standard uncertainty.
    pub at_s: f64,
    /// Its standard uncertainty, s.
    pub u_at_s: f64,
    /// The jump (output unit: m/s^2 or deg/s) and its standard uncertainty.
    pub size: f64,
    /// Its standard uncertainty.
    pub u_size: f64,
    /// The window test's statistic, in standard errors.
    pub z: f64,
    /// Its p-value corrected for every position and library column tried.
    pub p: f64,
}

/// One block's residual: time, samples, mean residual.
type Res = (f64, f64, f64);

/// Residual mean of each block of segment `i` on channel `c` under `theta`.
fn residuals(data: &Data, fit: &Fit, i: usize, c: usize) -> Vec<Res> {
    let cols = &data.layout.by_channel[c];
    data.accs[i]
        .blocks
        .iter()
        .map(|b| {
            let mut s = b.sy[c];
            for (k, &g) in cols.iter().enumerate() {
                let th = fit.theta[g];
                if th != 0.0 {
                    s -= b.sx[c][k] * th;
                }
            }
            (b.t, b.n as f64, s / b.n.max(1) as f64)
        })
        .collect()
}

/// The windows at boundary `k` of `r` (between blocks k-1 and k): the jump of the mean,
/// the samples before and after, and the span after (s).
fn window(r: &[Res], k: usize) -> (f64, f64, f64, f64) {
    let l = WINDOW.min(k).min(r.len() - k);
    let mean = |s: &[Res]| {
        let n: f64 = s.iter().map(|x| x.1).sum();
        (s.iter().map(|x| x.1 * x.2).sum::<f64>() / n, n)
    };
    let (m1, n1) = mean(&r[k - l..k]);
    let (m2, n2) = mean(&r[k..k + l]);
    let span = r[k + l - 1].0 - r[k].0 + 1.0;
    (m2 - m1, n1, n2, span)
}

/// The window statistic at boundary `k`: (z, jump), white noise `white` per sample and
/// wander `q` per second.
fn window_z(r: &[Res], k: usize, white: f64, q: f64) -> (f64, f64) {
    let (d, n1, n2, span) = window(r, k);
    let var = white * (1.0 / n1 + 1.0 / n2) + q * 2.0 * span / 3.0;
    (if var > 0.0 { d / var.sqrt() } else { 0.0 }, d)
}

/// Two-sided normal tail probability of `z` standard errors (chi-square of one degree).
fn tail(z: f64) -> f64 {
    super::stats::p_value(z * z, 1)
}

/// The profile of a two-level fit of `r` over its boundaries: the instant (between the
/// blocks' stamps) and its u, the jump and its u.
fn locate(r: &[Res], white: f64) -> (f64, f64, f64, f64) {
    let total_n: f64 = r.iter().map(|x| x.1).sum();
    let total_s: f64 = r.iter().map(|x| x.1 * x.2).sum();
    let mut chi: Vec<(f64, f64, f64, f64)> = Vec::new(); // (instant, chi2, jump, u jump)
    let (mut n1, mut s1) = (0.0, 0.0);
    for k in 1..r.len() {
        n1 += r[k - 1].1;
        s1 += r[k - 1].1 * r[k - 1].2;
        let (n2, s2) = (total_n - n1, total_s - s1);
        if n1 <= 0.0 || n2 <= 0.0 {
            continue;
        }
        // The sum of squares explained by two levels over one: n1 n2 / N (m2 - m1)^2.
        let d = s2 / n2 - s1 / n1;
        let explained = n1 * n2 / total_n * d * d / white;
        let instant = 0.5 * (r[k - 1].0 + r[k].0);
        chi.push((
            instant,
            -explained,
            d,
            (white * (1.0 / n1 + 1.0 / n2)).sqrt(),
        ));
    }
    let best = chi
        .iter()
        .copied()
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap_or((r[0].0, 0.0, 0.0, 0.0));
    let w: Vec<f64> = chi.iter().map(|c| (-(c.1 - best.1) / 2.0).exp()).collect();
    let sw: f64 = w.iter().sum();
    let mean: f64 = chi.iter().zip(&w).map(|(c, w)| c.0 * w).sum::<f64>() / sw;
    let var: f64 = chi
        .iter()
        .zip(&w)
        .map(|(c, w)| (c.0 - mean).powi(2) * w)
        .sum::<f64>()
        / sw;
    // At least the block's own resolution: the instant is known to a block.
    let u = var.sqrt().max(1.0 / 12f64.sqrt());
    (best.0, u, best.2, best.3)
}

/// Fewest pairs at a lag a channel needs for its own wander estimate ([`wander`]).
const FEWEST_PAIRS: usize = 10;
/// Blocks in one group of the wander estimate.
const GROUP: usize = 10;

/// The wandering bias's intensity on channel `c`, robust to the steps being looked for:
/// ten-second group means compared at lags of 20, 40 and 60 s, each lag's variance from
/// the median squared difference (a step moves only the few pairs that straddle it; the
/// fit's estimate `q`, which a step inflates, is the fallback where the recording has too
/// few pairs). For a random walk two group means `l` apart differ with variance
/// `q (l - G/3)` beyond the white noise's share.
fn wander(rs: &[Vec<Res>], white: f64, q: f64) -> f64 {
    let groups: Vec<Vec<Res>> = rs
        .iter()
        .map(|r| {
            r.chunks_exact(GROUP)
                .map(|c| {
                    let n: f64 = c.iter().map(|x| x.1).sum();
                    let t = c.iter().map(|x| x.0 * x.1).sum::<f64>() / n;
                    (t, n, c.iter().map(|x| x.1 * x.2).sum::<f64>() / n)
                })
                .collect()
        })
        .collect();
    let mut per_lag = Vec::new();
    for lag in [2usize, 4, 6] {
        let (mut d2, mut white_part, mut factor) = (Vec::new(), 0.0, 0.0);
        for g in &groups {
            for w in g.windows(lag + 1) {
                let (a, b) = (w[0], w[lag]);
                d2.push((b.2 - a.2).powi(2));
                white_part += white * (1.0 / a.1 + 1.0 / b.1);
                factor += (b.0 - a.0) - GROUP as f64 / 3.0;
            }
        }
        if d2.len() < FEWEST_PAIRS {
            continue;
        }
        let n = d2.len() as f64;
        d2.sort_by(f64::total_cmp);
        // The median of a chi-square of one degree is 0.4549 of its mean.
        let excess = d2[d2.len() / 2] / 0.4549 - white_part / n;
        per_lag.push((excess / (factor / n)).max(0.0));
    }
    if per_lag.is_empty() {
        return q;
    }
    per_lag.sort_by(f64::total_cmp);
    per_lag[per_lag.len() / 2]
}

/// Every change point the final model `fit` leaves, strongest first; `library` is the
/// number of library columns the discovery tested (they share the threshold).
pub(crate) fn scan(data: &Data, fit: &Fit, alpha: f64, library: usize) -> Vec<ChangePoint> {
    let mut tried: Vec<(usize, usize, Vec<Res>, usize, f64)> = Vec::new();
    let mut positions = 0usize;
    for c in 0..6 {
        let nz = &fit.noise[c];
        let white = nz.sigma * nz.sigma * nz.phi;
        let rs: Vec<Vec<Res>> = (0..data.accs.len())
            .map(|i| residuals(data, fit, i, c))
            .collect();
        let q = wander(&rs, white, nz.q);
        for (i, r) in rs.into_iter().enumerate() {
            if r.len() < 2 * LEAST {
                continue;
            }
            let (mut best_k, mut best_z) = (0, 0.0f64);
            for k in LEAST..=r.len() - LEAST {
                positions += 1;
                let (z, _) = window_z(&r, k, white, q);
                if z.abs() > best_z.abs() {
                    (best_k, best_z) = (k, z);
                }
            }
            tried.push((i, c, r, best_k, best_z));
        }
    }
    let m = (positions + library).max(1) as f64;
    let mut out: Vec<ChangePoint> = tried
        .into_iter()
        .filter(|t| tail(t.4) * m < alpha)
        .map(|(i, c, r, _, z)| {
            let nz = &fit.noise[c];
            let (at_s, u_at_s, size, u_size) = locate(&r, nz.sigma * nz.sigma * nz.phi);
            ChangePoint {
                channel: c,
                acc: i,
                at_s,
                u_at_s,
                size,
                u_size,
                z,
                p: (tail(z) * m).min(1.0),
            }
        })
        .collect();
    out.sort_by(|a, b| b.z.abs().total_cmp(&a.z.abs()));
    out.truncate(MOST);
    out
}
