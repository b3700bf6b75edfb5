//! Small statistics shared by the fits: mean, standard deviation, trend, and the
//! batch-means inflation that keeps uncertainties honest under correlated noise.

/// Mean of the kept samples.
pub(crate) fn mean(x: &[f64], keep: &[bool]) -> f64 {
    let (s, n) = x
        .iter()
        .zip(keep)
        .filter(|p| *p.1)
        .fold((0.0, 0usize), |(s, n), (v, _)| (s + v, n + 1));
    if n == 0 { f64::NAN } else { s / n as f64 }
}

/// Mean and sample standard deviation of the kept samples in one pass (shifted by the
/// first sample, so the sums do not lose precision on large offsets).
pub(crate) fn mean_std(x: &[f64], keep: &[bool]) -> (f64, f64) {
    let Some(shift) = x.iter().zip(keep).find(|p| *p.1).map(|p| *p.0) else {
        return (f64::NAN, 0.0);
    };
    // Four running sums of each, a select rather than a branch (a left-out sample adds
    // zero, whatever it holds): the compiler keeps them in vector registers.
    let (mut s, mut ss, mut n) = ([0.0f64; 4], [0.0f64; 4], 0usize);
    let (cx, ck) = (x.chunks_exact(4), keep.chunks_exact(4));
    let (mut ts, mut tss, mut tn) = (0.0, 0.0, 0usize);
    for (v, k) in cx.remainder().iter().zip(ck.remainder()) {
        if *k {
            let d = v - shift;
            (ts, tss, tn) = (ts + d, tss + d * d, tn + 1);
        }
    }
    for (v, k) in cx.zip(ck) {
        for l in 0..4 {
            let d = if k[l] { v[l] - shift } else { 0.0 };
            s[l] += d;
            ss[l] += d * d;
        }
        n += k.iter().filter(|k| **k).count();
    }
    let s = (s[0] + s[1]) + (s[2] + s[3]) + ts;
    let ss = (ss[0] + ss[1]) + (ss[2] + ss[3]) + tss;
    let n = n + tn;
    let nf = n as f64;
    let var = if n < 2 {
        0.0
    } else {
        ((ss - s * s / nf) / (nf - 1.0)).max(0.0)
    };
    (shift + s / nf, var.sqrt())
}

/// Sample standard deviation of the kept samples.
pub(crate) fn std(x: &[f64], keep: &[bool]) -> f64 {
    let m = mean(x, keep);
    let (s, n) = x
        .iter()
        .zip(keep)
        .filter(|p| *p.1)
        .fold((0.0, 0usize), |(s, n), (v, _)| (s + (v - m).powi(2), n + 1));
    if n < 2 {
        0.0
    } else {
        (s / (n - 1) as f64).sqrt()
    }
}

/// Mean, standard deviation and least-squares slope (per unit of `t`) of the kept samples.
pub(crate) fn mean_std_slope(t: &[f64], x: &[f64], keep: &[bool]) -> (f64, f64, f64) {
    let m = mean(x, keep);
    let tm = mean(t, keep);
    let (mut sxx, mut sxy) = (0.0, 0.0);
    for i in 0..x.len() {
        if keep[i] {
            sxx += (t[i] - tm).powi(2);
            sxy += (t[i] - tm) * (x[i] - m);
        }
    }
    let slope = if sxx > 0.0 { sxy / sxx } else { 0.0 };
    (m, std(x, keep), slope)
}

/// Pools the variance of batch means of residual series against their white-noise
/// variance: the factor by which the variance of a mean exceeds `sigma^2 / n`. 1 for
/// white noise; larger for low-pass filtered data or a wandering bias.
#[derive(Debug, Default, Clone, Copy)]
pub(crate) struct Inflation {
    batch_ss: f64,
    white_ss: f64,
}

impl Inflation {
    /// Adds one segment's residuals (kept samples only), cut into about 10 batches.
    pub(crate) fn add(&mut self, r: &[f64], keep: &[bool]) {
        let kept: Vec<f64> = r.iter().zip(keep).filter(|p| *p.1).map(|p| *p.0).collect();
        let n = kept.len();
        if n < 40 {
            return;
        }
        let nb = 10;
        let len = n / nb;
        let m = kept[..nb * len].iter().sum::<f64>() / (nb * len) as f64;
        let var = kept.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (n - 1) as f64;
        let mut ss = 0.0;
        for b in 0..nb {
            let bm = kept[b * len..(b + 1) * len].iter().sum::<f64>() / len as f64;
            ss += len as f64 * (bm - m).powi(2);
        }
        self.batch_ss += ss;
        self.white_ss += var * (nb - 1) as f64;
    }

    /// Adds another stretch's sums (as [`Inflation::add`] of it would).
    pub(crate) fn merge(&mut self, other: &Inflation) {
        self.batch_ss += other.batch_ss;
        self.white_ss += other.white_ss;
    }

    /// The variance factor, never below 1.
    pub(crate) fn factor(&self) -> f64 {
        if self.white_ss > 0.0 {
            (self.batch_ss / self.white_ss).max(1.0)
        } else {
            1.0
        }
    }
}

/// Median step of a time series.
pub(crate) fn median_step(t: &[f64]) -> f64 {
    if t.len() < 2 {
        return f64::NAN;
    }
    let stride = (t.len() / 2001).max(1);
    let mut d: Vec<f64> = t.windows(2).step_by(stride).map(|w| w[1] - w[0]).collect();
    d.sort_by(f64::total_cmp);
    d[d.len() / 2]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slope_of_a_line() {
        let t: Vec<f64> = (0..10).map(f64::from).collect();
        let x: Vec<f64> = t.iter().map(|v| 2.0 + 0.5 * v).collect();
        let keep = vec![true; 10];
        let (m, _, s) = mean_std_slope(&t, &x, &keep);
        assert!((m - 4.25).abs() < 1e-12 && (s - 0.5).abs() < 1e-12);
    }

    /// The lane sums against the two-pass mean and deviation, with samples left out (a
    /// NaN among them must not leak) and lengths around the lane width.
    #[test]
    fn mean_std_agrees_with_two_passes_and_ignores_what_is_left_out() {
        for n in [0usize, 1, 2, 3, 4, 5, 7, 64, 1001] {
            let x: Vec<f64> = (0..n)
                .map(|i| {
                    if i % 13 == 5 {
                        f64::NAN
                    } else {
                        1e4 + (i as f64 * 0.37).sin()
                    }
                })
                .collect();
            let keep: Vec<bool> = (0..n).map(|i| i % 13 != 5 && i % 7 != 3).collect();
            let (m, s) = mean_std(&x, &keep);
            if keep.iter().all(|k| !k) {
                assert!(m.is_nan() && s == 0.0);
                continue;
            }
            let (wm, ws) = (mean(&x, &keep), std(&x, &keep));
            assert!((m - wm).abs() <= 1e-12 * wm.abs(), "{n}: {m} {wm}");
            assert!((s - ws).abs() <= 1e-9 * ws.max(1e-300), "{n}: {s} {ws}");
        }
    }
}
