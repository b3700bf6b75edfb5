//! Preprocessing of one segment: synchronisation of the table feedback onto the IMU
//! stamps (linear interpolation), references through the physics kinematics, outlier
//! removal within the segment, zero-phase Butterworth low-pass.

use crate::plan::Outliers;
use crate::recording::{Recording, Segment, SegmentKind};
use crate::results::SyncReport;
use ratecal_physics::{AxisMotion, DEG, Geometry, Mat3, Site, TableState, Vec3};
use std::borrow::Cow;

/// One segment's IMU samples with their references, ready for the fits. The samples are
/// the recording's own (borrowed); only a filtered channel is a copy.
#[derive(Debug, Clone)]
pub(crate) struct SegData<'a> {
    /// Segment id.
    pub id: String,
    /// Kind.
    pub kind: SegmentKind,
    /// IMU stamps.
    pub t: &'a [f64],
    /// Accelerometer outputs per axis, m/s^2 (filtered if asked).
    pub accel: [Cow<'a, [f64]>; 3],
    /// Gyro outputs per axis, deg/s (filtered if asked).
    pub gyro: [Cow<'a, [f64]>; 3],
    /// Specific-force reference at the IMU reference point, body axes, m/s^2.
    pub f_ref: [Vec<f64>; 3],
    /// Inertial-rate reference (table motion and Earth rate), body axes, deg/s.
    pub w_ref: [Vec<f64>; 3],
    /// Accelerometer samples kept after outlier removal.
    pub keep_a: Vec<bool>,
    /// Gyro samples kept.
    pub keep_g: Vec<bool>,
    /// Mean feedback angles (outer, inner), deg.
    pub mean_angles_deg: (f64, f64),
}

impl SegData<'_> {
    /// Samples removed from either sensor.
    pub(crate) fn outliers(&self) -> usize {
        self.keep_a
            .iter()
            .zip(&self.keep_g)
            .filter(|(a, g)| !**a || !**g)
            .count()
    }
}

/// How to preprocess.
#[derive(Debug, Clone, Copy)]
pub(crate) struct PrepOptions {
    /// Outlier rule.
    pub outliers: Option<Outliers>,
    /// Butterworth (order, cutoff Hz).
    pub lowpass: Option<(u32, f64)>,
}

/// The station geometry in force for each segment (station mount, then per-segment remounts).
pub(crate) fn geometries(rec: &Recording) -> Vec<Geometry> {
    let st = &rec.manifest.station;
    let v = |a: [f64; 3]| Vec3::new(a[0], a[1], a[2]);
    let m = |r: &[[f64; 3]; 3]| Mat3::from_fn(|i, j| r[i][j]);
    let mut c_pb = st
        .mount
        .as_ref()
        .map_or(Mat3::identity(), |mt| m(&mt.rotation));
    rec.manifest
        .segments
        .iter()
        .map(|s| {
            if let Some(mt) = &s.mount {
                c_pb = m(&mt.rotation);
            }
            Geometry {
                outer_axis: v(st.table.outer_axis),
                inner_axis: v(st.table.inner_axis),
                c_pb,
            }
        })
        .collect()
}

/// Builds a segment's data; `warnings` collects what could not be done as asked.
pub(crate) fn prepare<'a>(
    rec: &'a Recording,
    seg: &Segment,
    geo: &Geometry,
    opts: PrepOptions,
    sync: &mut SyncReport,
    warnings: &mut Vec<String>,
) -> SegData<'a> {
    let imu = &rec.imu;
    let a = imu.t.partition_point(|&t| t < seg.t_start);
    let b = imu.t.partition_point(|&t| t <= seg.t_end);
    let t = &imu.t[a..b];
    let n = t.len();
    let accel = std::array::from_fn(|k| Cow::Borrowed(&imu.accel[k][a..b]));
    let gyro = std::array::from_fn(|k| Cow::Borrowed(&imu.gyro[k][a..b]));
    let rest = (seg.kind == SegmentKind::Static)
        .then(|| rest_angles(rec, seg.t_start, seg.t_end))
        .flatten();
    // The references of a long segment are computed in two halves side by side.
    let mut f_ref: [Vec<f64>; 3] = std::array::from_fn(|_| vec![0.0; n]);
    let mut w_ref: [Vec<f64>; 3] = std::array::from_fn(|_| vec![0.0; n]);
    let refs = {
        let [f0, f1, f2] = &mut f_ref;
        let [w0, w1, w2] = &mut w_ref;
        if n >= PARALLEL_MIN {
            // Each half fills its own part of the same arrays.
            let h = n / 2;
            let (f0, f0b) = f0.split_at_mut(h);
            let (f1, f1b) = f1.split_at_mut(h);
            let (f2, f2b) = f2.split_at_mut(h);
            let (w0, w0b) = w0.split_at_mut(h);
            let (w1, w1b) = w1.split_at_mut(h);
            let (w2, w2b) = w2.split_at_mut(h);
            let (mut a, b) = rayon::join(
                || {
                    references(
                        rec,
                        seg.kind,
                        rest,
                        geo,
                        &t[..h],
                        [f0, f1, f2],
                        [w0, w1, w2],
                    )
                },
                || {
                    references(
                        rec,
                        seg.kind,
                        rest,
                        geo,
                        &t[h..],
                        [f0b, f1b, f2b],
                        [w0b, w1b, w2b],
                    )
                },
            );
            a.merge(&b);
            a
        } else {
            references(rec, seg.kind, rest, geo, t, [f0, f1, f2], [w0, w1, w2])
        }
    };
    sync.max_gap_s = sync.max_gap_s.max(refs.sync.max_gap_s);
    sync.max_sync_error_s = sync.max_sync_error_s.max(refs.sync.max_sync_error_s);
    sync.max_angle_error_deg = sync.max_angle_error_deg.max(refs.sync.max_angle_error_deg);
    let (so, si) = refs.angle_sums;
    let mut d = SegData {
        id: seg.id.clone(),
        kind: seg.kind,
        t,
        accel,
        gyro,
        f_ref,
        w_ref,
        keep_a: vec![true; n],
        keep_g: vec![true; n],
        mean_angles_deg: (so / n as f64, si / n as f64),
    };
    if let Some(rule) = opts.outliers {
        // Each sensor's three channels in turn (a sample removed on one axis is out of
        // the next axis's statistics); the two sensors side by side.
        let chain = |out: &[Cow<[f64]>; 3], refs: &[Vec<f64>; 3], keep: &mut Vec<bool>| {
            let mut r = Vec::with_capacity(n);
            for k in 0..3 {
                r.clear();
                r.extend(out[k].iter().zip(&refs[k]).map(|(o, r)| o - r));
                flag_outliers(&r, rule, keep);
            }
        };
        let (mut keep_a, mut keep_g) =
            (std::mem::take(&mut d.keep_a), std::mem::take(&mut d.keep_g));
        rayon::join(
            || chain(&d.accel, &d.f_ref, &mut keep_a),
            || chain(&d.gyro, &d.w_ref, &mut keep_g),
        );
        (d.keep_a, d.keep_g) = (keep_a, keep_g);
    }
    if let Some((order, cutoff)) = opts.lowpass {
        let fs = 1.0 / super::stats::median_step(d.t);
        if cutoff >= fs / 2.0 {
            warnings.push(format!(
                "segment {}: low-pass cutoff {cutoff} Hz is at or above the Nyquist frequency ({:.1} Hz); not filtered",
                d.id,
                fs / 2.0
            ));
        } else if let Some(sos) = butter(order, cutoff, fs) {
            use rayon::prelude::*;
            // Outliers are replaced by interpolation before filtering, and stay excluded.
            let (keep_a, keep_g) = (&d.keep_a, &d.keep_g);
            d.accel
                .par_iter_mut()
                .map(|x| (x, keep_a))
                .chain(d.gyro.par_iter_mut().map(|x| (x, keep_g)))
                .for_each(|(x, keep)| {
                    let mut v = x.to_vec();
                    fill_removed(&mut v, keep);
                    filtfilt_in_place(&sos, &mut v);
                    *x = Cow::Owned(v);
                });
        } else {
            warnings.push(format!("segment {}: Butterworth order {order} at {cutoff} Hz could not be designed; not filtered", d.id));
        }
    }
    d
}

/// Segments at least this long are split over threads.
const PARALLEL_MIN: usize = 20_000;

/// What the synchronisation of a run of IMU stamps saw.
struct Refs {
    sync: SyncReport,
    /// Sums of the interpolated feedback angles (outer, inner), deg.
    angle_sums: (f64, f64),
}

impl Refs {
    fn merge(&mut self, o: &Refs) {
        self.sync.max_gap_s = self.sync.max_gap_s.max(o.sync.max_gap_s);
        self.sync.max_sync_error_s = self.sync.max_sync_error_s.max(o.sync.max_sync_error_s);
        self.sync.max_angle_error_deg = self
            .sync
            .max_angle_error_deg
            .max(o.sync.max_angle_error_deg);
        self.angle_sums.0 += o.angle_sums.0;
        self.angle_sums.1 += o.angle_sums.1;
    }
}

/// Table feedback interpolated onto the stamps `t`, and the references through the
/// kinematics of ratecal_physics, written into `f_ref` and `w_ref` (as long as `t`).
fn references(
    rec: &Recording,
    kind: SegmentKind,
    rest: Option<(f64, f64)>,
    geo: &Geometry,
    t: &[f64],
    f_ref: [&mut [f64]; 3],
    w_ref: [&mut [f64]; 3],
) -> Refs {
    let site: Site = rec.manifest.station.site;
    let mut sync = SyncReport::default();
    let (mut so, mut si) = (0.0, 0.0);
    let tab = &rec.table;
    if t.is_empty() {
        return Refs {
            sync,
            angle_sums: (so, si),
        };
    }
    // The step `j`..`j + 1` holding t[0]; the last step for a stamp at or past the last
    // feedback sample (a segment may end half a step after the table stream).
    let mut j = tab
        .t
        .partition_point(|&x| x <= t[0])
        .saturating_sub(1)
        .min(tab.t.len().saturating_sub(2));
    // Table state at feedback sample `j` plus a fraction `w` of the step to `j + 1`,
    // through the kinematics of ratecal_physics: (specific force m/s^2, rate deg/s).
    // A static segment is at rest and a rate segment turns at its mean feedback rate: the
    // feedback's rate ripple is the table's measurement noise, not motion the IMU felt (it
    // would otherwise leak into the gyro residuals and their noise figures).
    let steady = match kind {
        SegmentKind::Static => Some((0.0, 0.0)),
        SegmentKind::Rate => Some(steady_rates(rec, t[0], t[t.len() - 1])),
        SegmentKind::Oscillation => None,
    };
    let refs_at = |j: usize, w: f64| -> (Vec3, Vec3) {
        let j = j.min(tab.t.len() - 2);
        let lerp = |x: &[f64]| x[j] + w * (x[j + 1] - x[j]);
        let lerp_angle = |x: &[f64]| x[j] + w * unwrap(x[j + 1] - x[j]);
        let mut state = TableState {
            outer: AxisMotion {
                angle: lerp_angle(&tab.outer) * DEG,
                rate: lerp(&tab.outer_rate) * DEG,
                accel: rate_derivative(&tab.t, &tab.outer_rate, j) * DEG,
            },
            inner: AxisMotion {
                angle: lerp_angle(&tab.inner) * DEG,
                rate: lerp(&tab.inner_rate) * DEG,
                accel: rate_derivative(&tab.t, &tab.inner_rate, j) * DEG,
            },
        };
        if let Some((ro, ri)) = steady {
            state.outer.rate = ro * DEG;
            state.inner.rate = ri * DEG;
            state.outer.accel = 0.0;
            state.inner.accel = 0.0;
        }
        let snap = state.snapshot(geo, &site);
        (snap.f_b(&Vec3::zeros()), snap.w_ib() / DEG)
    };
    let rest_refs = rest.map(|(o, i)| {
        let still = |angle: f64| AxisMotion {
            angle: angle * DEG,
            rate: 0.0,
            accel: 0.0,
        };
        let snap = TableState {
            outer: still(o),
            inner: still(i),
        }
        .snapshot(geo, &site);
        (snap.f_b(&Vec3::zeros()), snap.w_ib() / DEG)
    });
    for (i, &ti) in t.iter().enumerate() {
        while j + 2 < tab.t.len() && tab.t[j + 1] <= ti {
            j += 1;
        }
        let (t0, t1) = (tab.t[j], tab.t[j + 1]);
        let w = ((ti - t0) / (t1 - t0)).clamp(0.0, 1.0);
        let gap = t1 - t0;
        sync.max_gap_s = sync.max_gap_s.max(gap);
        sync.max_sync_error_s = sync
            .max_sync_error_s
            .max((ti - t0).abs().min((t1 - ti).abs()));
        let acc_o = rate_derivative(&tab.t, &tab.outer_rate, j);
        let acc_i = rate_derivative(&tab.t, &tab.inner_rate, j);
        let max_acc = acc_o.abs().max(acc_i.abs());
        sync.max_angle_error_deg = sync.max_angle_error_deg.max(gap * gap / 8.0 * max_acc);
        so += tab.outer[j] + w * unwrap(tab.outer[j + 1] - tab.outer[j]);
        si += tab.inner[j] + w * unwrap(tab.inner[j + 1] - tab.inner[j]);
        let (f, wi) = match rest_refs {
            // At rest: one attitude for the whole segment (its mean feedback angles).
            Some(r) => r,
            None => refs_at(j, w),
        };
        for k in 0..3 {
            f_ref[k][i] = f[k];
            w_ref[k][i] = wi[k];
        }
    }
    Refs {
        sync,
        angle_sums: (so, si),
    }
}

/// The constant rates (outer, inner), deg/s, of a rate segment between `t0` and `t1`: the
/// least-squares slope of the unwrapped feedback angles against time, which the angle
/// encoders determine far better than the mean of the rate feedback (whose ripple is
/// measurement noise: 0.003 deg/s over 500 samples leaves 1e-4 deg/s, a slope over 10 s of
/// 0.5 arcsec angles 2e-6 deg/s). With fewer than three feedback samples, the mean rate.
pub(crate) fn steady_rates(rec: &Recording, t0: f64, t1: f64) -> (f64, f64) {
    let tab = &rec.table;
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
pub(crate) fn rest_angles(rec: &Recording, t0: f64, t1: f64) -> Option<(f64, f64)> {
    let tab = &rec.table;
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
fn rate_derivative(t: &[f64], r: &[f64], j: usize) -> f64 {
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
            use statrs::distribution::{ContinuousCDF, StudentsT};
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
                let nf = n as f64;
                let Ok(dist) = StudentsT::new(0.0, 1.0, nf - 2.0) else {
                    break;
                };
                let tq = dist.inverse_cdf(1.0 - alpha / (2.0 * nf));
                let g_crit = (nf - 1.0) / nf.sqrt() * (tq * tq / (nf - 2.0 + tq * tq)).sqrt();
                if s > 0.0 && dev / s > g_crit {
                    keep[imax] = false;
                } else {
                    break;
                }
            }
        }
    }
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
