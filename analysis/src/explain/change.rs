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

/// Blocks (s) each side of a boundary in the window tests: a long window sees a small
/// step through white noise, a short one sees a step through a wander that the step itself
/// inflated (the fit's `q` counts the jump as wander).
const WINDOWS: [usize; 3] = [5, 20, 60];
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
    let nonzero: Vec<(usize, f64)> = (data.layout.by_channel[c].iter().enumerate())
        .map(|(k, &g)| (k, fit.theta[g]))
        .filter(|&(_, th)| th != 0.0)
        .collect();
    let acc = &data.accs[i];
    (acc.blocks.iter().zip(acc.block_sums(c, &nonzero)))
        .map(|(b, s)| (b.t, b.n as f64, s / b.n.max(1) as f64))
        .collect()
}

/// The windows at boundary `k` of `r` (between blocks k-1 and k): the jump of the mean,
/// the samples before and after, and the span after (s).
fn window(r: &[Res], k: usize, width: usize) -> (f64, f64, f64, f64) {
    let l = width.min(k).min(r.len() - k);
    let mean = |s: &[Res]| {
        let n: f64 = s.iter().map(|x| x.1).sum();
        (s.iter().map(|x| x.1 * x.2).sum::<f64>() / n, n)
    };
    let (m1, n1) = mean(&r[k - l..k]);
    let (m2, n2) = mean(&r[k..k + l]);
    let span = r[k + l - 1].0 - r[k].0 + 1.0;
    (m2 - m1, n1, n2, span)
}

/// The wandering bias's intensity per second as estimated, with the degrees of freedom of
/// that estimate (infinite when it is taken as known).
#[derive(Debug, Clone, Copy)]
struct Wander {
    q: f64,
    dof: f64,
}

/// The window statistic at boundary `k`: (z, its degrees of freedom), white noise `white`
/// per sample and the wander `w`. The white share of the variance is known (the fit has
/// hundreds of thousands of samples behind it); the wander's share is estimated from a few
/// dozen group differences, so the statistic is Student's t with the Satterthwaite degrees
/// of freedom of the sum: a large wander estimated from little data does not make a
/// Gauss-Markov excursion a step.
fn window_z(r: &[Res], k: usize, width: usize, white: f64, w: Wander) -> (f64, f64) {
    let (d, n1, n2, span) = window(r, k, width);
    let var_white = white * (1.0 / n1 + 1.0 / n2);
    let var_q = w.q * 2.0 * span / 3.0;
    let var = var_white + var_q;
    if var <= 0.0 {
        return (0.0, f64::INFINITY);
    }
    let dof = if var_q > 0.0 && w.dof.is_finite() {
        var * var / (var_q * var_q / w.dof)
    } else {
        f64::INFINITY
    };
    (d / var.sqrt(), dof)
}

/// The two-sided normal quantile of `alpha`: the fewest standard errors a single test at
/// `alpha` needs.
fn normal_quantile(alpha: f64) -> f64 {
    use statrs::distribution::{ContinuousCDF, Normal};
    Normal::standard().inverse_cdf(1.0 - (alpha / 2.0).clamp(1e-300, 0.5))
}

/// Two-sided tail probability of `z` standard errors: Student's t of `dof` degrees (the
/// normal beyond a thousand).
fn tail(z: f64, dof: f64) -> f64 {
    use statrs::distribution::{ContinuousCDF, StudentsT};
    if dof < 1e3
        && let Ok(t) = StudentsT::new(0.0, 1.0, dof.max(1.0))
    {
        return (2.0 * t.sf(z.abs())).min(1.0);
    }
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
///
/// Its degrees of freedom: differences at the shortest lag two groups apart that share no
/// group are independent, a third of the groups' count, and the median of a chi-square of
/// one degree keeps about half of the mean's efficiency.
fn wander(rs: &[Vec<Res>], white: f64, q: f64) -> Wander {
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
        return Wander {
            q,
            dof: f64::INFINITY,
        };
    }
    per_lag.sort_by(f64::total_cmp);
    let groups: usize = groups.iter().map(|g| g.len().saturating_sub(2)).sum();
    Wander {
        q: per_lag[per_lag.len() / 2],
        dof: (groups as f64 / 6.0).max(1.0),
    }
}

/// Every change point the final model `fit` leaves, strongest first; `library` is the
/// number of library columns the discovery tested (they share the threshold).
pub(crate) fn scan(data: &Data, fit: &Fit, alpha: f64, library: usize) -> Vec<ChangePoint> {
    // (segment, channel, residuals, z and p at the boundary of least p).
    let mut tried: Vec<(usize, usize, Vec<Res>, f64, f64)> = Vec::new();
    let mut positions = 0usize;
    let least_z = normal_quantile(alpha);
    let debug = std::env::var_os("RATECAL_EXPLAIN_DEBUG").is_some();
    for c in 0..6 {
        let nz = &fit.noise[c];
        let white = nz.sigma * nz.sigma * nz.phi;
        let rs: Vec<Vec<Res>> = (0..data.accs.len())
            .map(|i| residuals(data, fit, i, c))
            .collect();
        // The fit's wander (every lag, mean squares) unless the robust estimate says more:
        // a step inflates the fit's, which the short windows see through; the robust one,
        // from few pairs with white noise dominating, can fall far below the truth.
        let robust = wander(&rs, white, nz.q);
        let q = if nz.q >= robust.q {
            Wander {
                q: nz.q,
                dof: f64::INFINITY,
            }
        } else {
            robust
        };
        for (i, r) in rs.into_iter().enumerate() {
            if r.len() < 2 * LEAST {
                continue;
            }
            let (mut best_z, mut best_p) = (0.0f64, 1.0f64);
            for k in LEAST..=r.len() - LEAST {
                let room = k.min(r.len() - k);
                for (j, &width) in WINDOWS.iter().enumerate() {
                    // A wider window that the segment's edge cuts to the last one's width
                    // is the same test again.
                    if j > 0 && room <= WINDOWS[j - 1] {
                        break;
                    }
                    positions += 1;
                    let (z, dof) = window_z(&r, k, width, white, q);
                    // Where even the normal tail exceeds alpha before any correction, the
                    // position cannot be a change point: not worth the t's cost.
                    if z.abs() < least_z {
                        continue;
                    }
                    let p = tail(z, dof);
                    if p < best_p {
                        (best_z, best_p) = (z, p);
                    }
                }
            }
            if debug && best_p < 1e-3 {
                eprintln!(
                    "change: ch {c} seg {i} q {:.3e} (fit {:.3e}) dof {:.1} white {white:.3e} z {best_z:.2} p {best_p:.2e}",
                    q.q, nz.q, q.dof
                );
            }
            tried.push((i, c, r, best_z, best_p));
        }
    }
    let m = (positions + library).max(1) as f64;
    let mut out: Vec<ChangePoint> = tried
        .into_iter()
        .filter(|t| t.4 * m < alpha)
        .map(|(i, c, r, z, p)| {
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
                p: (p * m).min(1.0),
            }
        })
        .collect();
    out.sort_by(|a, b| b.z.abs().total_cmp(&a.z.abs()));
    out.truncate(MOST);
    out
}
