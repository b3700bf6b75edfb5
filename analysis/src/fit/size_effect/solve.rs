//! One weighted least-squares over every segment's drift: the six coordinates, and per
//! group (one cycle at one centre and amplitude) an East and a North instrumental term that
//! does not depend on the period, growing linearly in time (a tilt drifting with the gyro
//! drifts and the alignment's heading error; each span's own curvature measures the
//! growth). With two periods in a group this is the paper's differencing; a group swayed
//! at one period only keeps its instrumental errors.

use super::SegmentDrift;
use nalgebra::{DMatrix, DVector};

/// The size-effect estimate.
#[derive(Debug, Clone, Default)]
pub struct SizeEffect {
    /// `(value, u)` of each coordinate in metres, order of `COORDS`; `None` if unobservable.
    pub coords_m: [Option<(f64, f64)>; 6],
    /// The segments' drifts and regressors.
    pub drifts: Vec<SegmentDrift>,
    /// The instrumental term of each group that has one: (group, East, North), m/s^2.
    pub instrumental: Vec<(usize, [f64; 2])>,
    /// What was left out or could not be cancelled.
    pub warnings: Vec<String>,
}

/// Solves for the coordinates.
pub(crate) fn solve(drifts: &[SegmentDrift], warnings: &mut Vec<String>) -> SizeEffect {
    let mut est = SizeEffect {
        drifts: drifts.to_vec(),
        ..Default::default()
    };
    let n_groups = drifts.iter().map(|d| d.group + 1).max().unwrap_or(0);
    // Groups with two distinct periods or more get an instrumental term.
    let mut bias_col: Vec<Option<usize>> = vec![None; n_groups];
    let mut p = 6;
    for (g, col) in bias_col.iter_mut().enumerate() {
        let mut periods: Vec<f64> = drifts
            .iter()
            .filter(|d| d.group == g)
            .map(|d| d.period_s)
            .collect();
        periods.sort_by(f64::total_cmp);
        periods.dedup_by(|a, b| (*a - *b).abs() < 1e-3 * b.abs());
        if periods.len() >= 2 {
            *col = Some(p);
            p += 4;
        } else if let Some(d) = drifts.iter().find(|d| d.group == g) {
            warnings.push(format!(
                "size effect: the cycle of {} swayed at one period only: its instrumental errors are not cancelled",
                d.id
            ));
        }
    }
    if drifts.is_empty() {
        warnings.push("size effect: no oscillation segment could be used".into());
        return est;
    }
    // The instrumental term of a group is b + j (t - t_ref), t_ref its spans' mean middle.
    let t_ref: Vec<f64> = (0..n_groups)
        .map(|g| {
            let ts: Vec<f64> = drifts
                .iter()
                .filter(|d| d.group == g)
                .map(|d| d.t_mid_s)
                .collect();
            ts.iter().sum::<f64>() / ts.len().max(1) as f64
        })
        .collect();
    let rows = drifts.len() * 4;
    let mut a = DMatrix::<f64>::zeros(rows, p);
    let mut y = DVector::<f64>::zeros(rows);
    for (k, d) in drifts.iter().enumerate() {
        for c in 0..2 {
            let r = 4 * k + c;
            let wgt = 1.0 / d.u_mps2[c].max(1e-9);
            for m in 0..6 {
                a[(r, m)] = d.h[c][m] * wgt;
            }
            y[r] = d.drift_mps2[c] * wgt;
            // The growth rows count only where a group has its instrumental term.
            if let Some(b) = bias_col[d.group] {
                a[(r, b + c)] = wgt;
                a[(r, b + 2 + c)] = (d.t_mid_s - t_ref[d.group]) * wgt;
                let (trend, u) = d.trend[c];
                let w2 = 1.0 / u.max(1e-11);
                for m in 0..6 {
                    a[(r + 2, m)] = d.h_trend[c][m] * w2;
                }
                a[(r + 2, b + 2 + c)] = w2;
                y[r + 2] = trend * w2;
            }
        }
    }
    // A coordinate no cycle excites (its regressors next to nothing) is unobservable.
    let norms: Vec<f64> = (0..6)
        .map(|m| drifts.iter().map(|d| d.h[0][m].hypot(d.h[1][m])).sum())
        .collect();
    let max = norms.iter().copied().fold(0.0, f64::max);
    let keep: Vec<usize> = (0..p)
        .filter(|&m| m >= 6 || norms[m] > 0.02 * max)
        .collect();
    let ak = a.select_columns(&keep);
    let svd = ak.clone().svd(true, true);
    let sv = &svd.singular_values;
    let (smax, smin) = (sv.max(), sv.min());
    if smin.is_nan() || smin <= 1e-9 * smax {
        warnings.push(
            "size effect: the cycles do not separate the coordinates from the instrumental terms"
                .into(),
        );
        return est;
    }
    let Ok(x) = svd.solve(&y, 1e-12 * smax) else {
        return est;
    };
    let cov = (ak.transpose() * &ak)
        .try_inverse()
        .unwrap_or_else(|| DMatrix::zeros(keep.len(), keep.len()));
    let used = (0..rows).filter(|&r| a.row(r).norm() > 0.0).count();
    let dof = used.saturating_sub(keep.len());
    let scale = if dof > 0 {
        let r = &y - &ak * &x;
        (r.norm_squared() / dof as f64).max(1.0)
    } else {
        1.0
    };
    for (q, &m) in keep.iter().enumerate() {
        if m < 6 {
            est.coords_m[m] = Some((x[q], (cov[(q, q)] * scale).sqrt()));
        }
    }
    for (g, col) in bias_col.iter().enumerate() {
        if let Some(b) = col
            && let Some(q) = keep.iter().position(|m| m == b)
        {
            est.instrumental.push((g, [x[q], x[q + 1]]));
        }
    }
    est
}
