//! Preprocessing of a segment's window of samples (`segment::pass` drives it): outlier
//! removal, zero-phase Butterworth low-pass, and the table feedback's steady rates and
//! rest attitude.

use crate::plan::Outliers;
use crate::recording::{Manifest, TableStream};
use ratecal_physics::{Geometry, Mat3, Vec3};
use std::borrow::Cow;
use std::ops::Range;

/// How to preprocess.
#[derive(Debug, Clone, Copy)]
pub(crate) struct PrepOptions {
    /// Outlier rule.
    pub outliers: Option<Outliers>,
    /// Butterworth (order, cutoff Hz).
    pub lowpass: Option<(u32, f64)>,
}

/// The station geometry in force for each segment (station mount, then per-segment remounts).
pub(crate) fn geometries(m: &Manifest) -> Vec<Geometry> {
    let st = &m.station;
    let v = |a: [f64; 3]| Vec3::new(a[0], a[1], a[2]);
    let mat = |r: &[[f64; 3]; 3]| Mat3::from_fn(|i, j| r[i][j]);
    let mut c_pb = st
        .mount
        .as_ref()
        .map_or(Mat3::identity(), |mt| mat(&mt.rotation));
    m.segments
        .iter()
        .map(|s| {
            if let Some(mt) = &s.mount {
                c_pb = mat(&mt.rotation);
            }
            Geometry {
                outer_axis: v(st.table.outer_axis),
                inner_axis: v(st.table.inner_axis),
                c_pb,
            }
        })
        .collect()
}

/// Flags the outliers of one sensor in a window: `resid(k)` is axis `k`'s residual series
/// (outputs minus references) over the whole window; the test runs on the `core` rows, axis
/// after axis (a sample removed on one axis is out of the next axis's statistics). Rows
/// outside the core (a low-pass's margins) are judged against the core's final threshold.
pub(crate) fn flag_window(
    resid: impl Fn(usize) -> Vec<f64>,
    rule: Outliers,
    core: &Range<usize>,
    keep: &mut [bool],
) {
    for k in 0..3 {
        let r = resid(k);
        flag_outliers(&r[core.clone()], rule, &mut keep[core.clone()]);
        if core.start == 0 && core.end == r.len() {
            continue;
        }
        if let Some((m, limit)) = threshold(&r[core.clone()], rule, &keep[core.clone()]) {
            for i in (0..core.start).chain(core.end..r.len()) {
                if (r[i] - m).abs() > limit {
                    keep[i] = false;
                }
            }
        }
    }
}

/// The mean and the largest deviation from it that `rule` keeps, over the kept samples.
fn threshold(r: &[f64], rule: Outliers, keep: &[bool]) -> Option<(f64, f64)> {
    let (m, s) = super::stats::mean_std(r, keep);
    let n = keep.iter().filter(|k| **k).count();
    match rule {
        Outliers::Sigma(k) => Some((m, k * s)),
        Outliers::Grubbs(alpha) => grubbs_critical(n, alpha).map(|g| (m, g * s)),
    }
}

/// Low-passes the six outputs of a window (the outliers replaced by interpolation before
/// filtering; they stay excluded); why it could not, if it could not.
pub(crate) fn lowpass(
    outputs: &mut [Cow<[f64]>; 6],
    keep_a: &[bool],
    keep_g: &[bool],
    t: &[f64],
    order: u32,
    cutoff: f64,
) -> Result<(), String> {
    use rayon::prelude::*;
    let fs = 1.0 / super::stats::median_step(t);
    if cutoff >= fs / 2.0 {
        return Err(format!(
            "low-pass cutoff {cutoff} Hz is at or above the Nyquist frequency ({:.1} Hz); not filtered",
            fs / 2.0
        ));
    }
    let Some(sos) = butter(order, cutoff, fs) else {
        return Err(format!(
            "Butterworth order {order} at {cutoff} Hz could not be designed; not filtered"
        ));
    };
    outputs.par_iter_mut().enumerate().for_each(|(c, x)| {
        let mut v = x.to_vec();
        fill_removed(&mut v, if c < 3 { keep_a } else { keep_g });
        filtfilt_in_place(&sos, &mut v);
        *x = Cow::Owned(v);
    });
    Ok(())
}

/// The constant rates (outer, inner), deg/s, of a rate segment between `t0` and `t1`: the
/// least-squares slope of the unwrapped feedback angles against time, which the angle
/// encoders determine far better than the mean of the rate feedback (whose ripple is
/// measurement noise: 0.003 deg/s over 500 samples leaves 1e-4 deg/s, a slope over 10 s of
/// 0.5 arcsec angles 2e-6 deg/s). With fewer than three feedback samples, the mean rate.
pub(crate) fn steady_rates(tab: &TableStream, t0: f64, t1: f64) -> (f64, f64) {
    let lo = tab.t.partition_point(|&x| x < t0);
    let hi = tab.t.partition_point(|&x| x <= t1);
    let slope = |angle: &[f64], rate: &[f64]| {
        let n = hi.saturating_sub(lo);
        if n < 3 {
            return if n > 0 {
                rate[lo..hi].iter().sum::<f64>() / n as f64
            } else {
                0.0
            };
        }
        let mut a = angle[lo];
        let mut unwrapped = Vec::with_capacity(n);
        unwrapped.push(a);
        for k in lo + 1..hi {
            a += unwrap(angle[k] - angle[k - 1]);
            unwrapped.push(a);
        }
        let ts = &tab.t[lo..hi];
        let tm = ts.iter().sum::<f64>() / n as f64;
        let am = unwrapped.iter().sum::<f64>() / n as f64;
        let (mut sxx, mut sxy) = (0.0, 0.0);
        for (t, a) in ts.iter().zip(&unwrapped) {
            sxx += (t - tm) * (t - tm);
            sxy += (t - tm) * (a - am);
        }
        if sxx > 0.0 { sxy / sxx } else { 0.0 }
    };
    (
        slope(&tab.outer, &tab.outer_rate),
        slope(&tab.inner, &tab.inner_rate),
    )
}

/// The attitude (outer, inner), deg, of a static segment between `t0` and `t1`: the mean of
/// the unwrapped feedback angles. The table is at rest; the encoder's sample-to-sample
/// noise is measurement noise, which the mean averages out. `None` without feedback there.
pub(crate) fn rest_angles(tab: &TableStream, t0: f64, t1: f64) -> Option<(f64, f64)> {
    let lo = tab.t.partition_point(|&x| x < t0);
    let hi = tab.t.partition_point(|&x| x <= t1);
    if hi <= lo {
        return None;
    }
    let mean = |angle: &[f64]| {
        let a0 = angle[lo];
        let (mut a, mut sum) = (a0, a0);
        for k in lo + 1..hi {
            a += unwrap(angle[k] - angle[k - 1]);
            sum += a;
        }
        sum / (hi - lo) as f64
    };
    Some((mean(&tab.outer), mean(&tab.inner)))
}

/// Shortest signed angle step, deg (feedback may wrap at 360).
pub(crate) fn unwrap(d: f64) -> f64 {
    d - 360.0 * (d / 360.0).round()
}

/// Angular acceleration (deg/s^2) at table sample `j` by a central difference over about
/// 0.1 s of feedback rates: the table reports rates, not accelerations.
pub(crate) fn rate_derivative(t: &[f64], r: &[f64], j: usize) -> f64 {
    let h = 5;
    let lo = j.saturating_sub(h);
    let hi = (j + 1 + h).min(t.len() - 1);
    if t[hi] > t[lo] {
        (r[hi] - r[lo]) / (t[hi] - t[lo])
    } else {
        0.0
    }
}

/// Flags outliers of one residual series (clears `keep`), within the segment.
pub(crate) fn flag_outliers(r: &[f64], rule: Outliers, keep: &mut [bool]) {
    match rule {
        Outliers::Sigma(k) => {
            for _ in 0..5 {
                let (m, s) = super::stats::mean_std(r, keep);
                let mut changed = false;
                for i in 0..r.len() {
                    if keep[i] && (r[i] - m).abs() > k * s {
                        keep[i] = false;
                        changed = true;
                    }
                }
                if !changed {
                    break;
                }
            }
        }
        Outliers::Grubbs(alpha) => {
            for _ in 0..1000 {
                let n = keep.iter().filter(|k| **k).count();
                if n < 7 {
                    break;
                }
                let m = super::stats::mean(r, keep);
                let s = super::stats::std(r, keep);
                let Some((imax, dev)) = (0..r.len())
                    .filter(|&i| keep[i])
                    .map(|i| (i, (r[i] - m).abs()))
                    .max_by(|a, b| a.1.total_cmp(&b.1))
                else {
                    break;
                };
                let Some(g_crit) = grubbs_critical(n, alpha) else {
                    break;
                };
                if s > 0.0 && dev / s > g_crit {
                    keep[imax] = false;
                } else {
                    break;
                }
            }
        }
    }
}

/// Grubbs' two-sided critical value for `n` samples at significance `alpha`.
fn grubbs_critical(n: usize, alpha: f64) -> Option<f64> {
    use statrs::distribution::{ContinuousCDF, StudentsT};
    let nf = n as f64;
    let dist = StudentsT::new(0.0, 1.0, nf - 2.0).ok()?;
    let tq = dist.inverse_cdf(1.0 - alpha / (2.0 * nf));
    Some((nf - 1.0) / nf.sqrt() * (tq * tq / (nf - 2.0 + tq * tq)).sqrt())
}

fn fill_removed(x: &mut [f64], keep: &[bool]) {
    let n = x.len();
    let mut i = 0;
    while i < n {
        if keep[i] {
            i += 1;
            continue;
        }
        let start = i;
        while i < n && !keep[i] {
            i += 1;
        }
        let left = start.checked_sub(1).map(|l| x[l]);
        let right = (i < n).then(|| x[i]);
        for (k, v) in x[start..i].iter_mut().enumerate() {
            *v = match (left, right) {
                (Some(l), Some(r)) => l + (r - l) * (k + 1) as f64 / (i - start + 1) as f64,
                (Some(l), None) => l,
                (None, Some(r)) => r,
                (None, None) => *v,
            };
        }
    }
}

fn butter(order: u32, cutoff: f64, fs: f64) -> Option<iir_filters::sos::Sos> {
    use iir_filters::filter_design::{FilterType, butter};
    let zpk = butter(order, FilterType::LowPass(cutoff), fs).ok()?;
    iir_filters::sos::zpk2sos(&zpk, None).ok()
}

/// Zero-phase filtering: forward then backward, each pass started in the steady state of
/// its first sample (subtracting it is exact for a unity-DC-gain low-pass), so the edges
/// do not ring.
pub(crate) fn filtfilt_in_place(sos: &iir_filters::sos::Sos, y: &mut [f64]) {
    use iir_filters::filter::{DirectForm2Transposed, Filter};
    if y.is_empty() {
        return;
    }
    let pass = |x: &mut [f64]| {
        let x0 = x[0];
        let mut f = DirectForm2Transposed::new(sos);
        for v in x.iter_mut() {
            *v = x0 + f.filter(*v - x0);
        }
    };
    pass(y);
    y.reverse();
    pass(y);
    y.reverse();
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn three_sigma_removes_a_spike() {
        let mut r: Vec<f64> = (0..200)
            .map(|i| ((i * 37 % 17) as f64 - 8.0) * 0.1)
            .collect();
        r[50] = 40.0;
        let mut keep = vec![true; r.len()];
        flag_outliers(&r, Outliers::Sigma(3.0), &mut keep);
        assert!(!keep[50]);
        assert_eq!(keep.iter().filter(|k| !**k).count(), 1);
        let mut keep = vec![true; r.len()];
        flag_outliers(&r, Outliers::Grubbs(0.05), &mut keep);
        assert!(!keep[50]);
        assert_eq!(keep.iter().filter(|k| !**k).count(), 1);
    }

    #[test]
    fn filtfilt_has_no_phase_lag_on_a_slow_sine() {
        let fs = 100.0;
        let sos = butter(4, 5.0, fs).unwrap();
        let x: Vec<f64> = (0..2000)
            .map(|i| (2.0 * std::f64::consts::PI * 0.5 * i as f64 / fs).sin())
            .collect();
        let mut y = x.clone();
        filtfilt_in_place(&sos, &mut y);
        // A 0.5 Hz sine passes a 5 Hz low-pass with gain ~1 and, forward-backward, zero lag.
        let err = x[200..1800]
            .iter()
            .zip(&y[200..1800])
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(err < 1e-3, "{err}");
    }
}
