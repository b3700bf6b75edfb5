//! A small Levenberg-Marquardt least squares with a numeric Jacobian (central differences),
//! started from the nominal model, without bounds: what the manual fits share. Its
//! covariance is `s^2 (J^T J)^-1`, `s^2` the residuals' own variance (the recording's
//! noise, hand tremor included).

use nalgebra::{DMatrix, DVector};

/// A converged fit: parameters, their covariance, residual RMS and degrees of freedom.
#[derive(Debug, Clone)]
pub(crate) struct Fitted {
    pub x: DVector<f64>,
    pub cov: DMatrix<f64>,
    pub rms: f64,
    /// Independent equations less parameters.
    #[cfg_attr(not(test), allow(dead_code))]
    pub dof: usize,
}

/// Central-difference Jacobian of `f` at `x`.
fn jacobian(f: &dyn Fn(&DVector<f64>) -> DVector<f64>, x: &DVector<f64>, m: usize) -> DMatrix<f64> {
    let mut j = DMatrix::zeros(m, x.len());
    for k in 0..x.len() {
        let h = 1e-6 * x[k].abs().max(1e-3);
        let (mut a, mut b) = (x.clone(), x.clone());
        a[k] += h;
        b[k] -= h;
        let d = (f(&a) - f(&b)) / (2.0 * h);
        j.set_column(k, &d);
    }
    j
}

/// Minimises `|f(x)|^2` from `x0`; `dof_per_row` scales the row count to independent
/// equations (a unit vector's difference has two in three rows). `None` when the normal
/// matrix is singular at the solution (the data do not determine every parameter).
pub(crate) fn solve(
    f: &dyn Fn(&DVector<f64>) -> DVector<f64>,
    x0: DVector<f64>,
    dof_per_row: f64,
) -> Option<Fitted> {
    let mut x = x0;
    let mut r = f(&x);
    let m = r.len();
    let mut cost = r.norm_squared();
    let mut lambda = 1e-3;
    for _ in 0..200 {
        let j = jacobian(f, &x, m);
        let jtj = j.transpose() * &j;
        let g = j.transpose() * &r;
        let mut improved = false;
        for _ in 0..20 {
            let mut a = jtj.clone();
            for k in 0..a.nrows() {
                a[(k, k)] += lambda * jtj[(k, k)].max(1e-12);
            }
            let Some(step) = a.cholesky().map(|c| c.solve(&(-&g))) else {
                lambda *= 10.0;
                continue;
            };
            let xn = &x + &step;
            let rn = f(&xn);
            let cn = rn.norm_squared();
            if cn.is_finite() && cn <= cost {
                let small = step.norm() <= 1e-12 * (1.0 + x.norm());
                let (dc, c0) = (cost - cn, cost);
                x = xn;
                r = rn;
                cost = cn;
                lambda = (lambda / 10.0).max(1e-12);
                improved = !(small || dc <= 1e-15 * c0.max(1e-300));
                break;
            }
            lambda *= 10.0;
        }
        if !improved {
            break;
        }
    }
    let j = jacobian(f, &x, m);
    covariance(&j, &r, x, dof_per_row)
}

/// The covariance `s^2 (J^T J)^-1` at the solution, or `None` when `J^T J` is singular.
fn covariance(
    j: &DMatrix<f64>,
    r: &DVector<f64>,
    x: DVector<f64>,
    dof_per_row: f64,
) -> Option<Fitted> {
    let n = x.len();
    let eq = (r.len() as f64 * dof_per_row).round() as usize;
    let dof = eq.saturating_sub(n);
    let inv = normal_inverse(j)?;
    let s2 = if dof > 0 {
        r.norm_squared() * dof_per_row / dof as f64
    } else {
        f64::NAN
    };
    let rms = (r.norm_squared() / r.len().max(1) as f64).sqrt();
    Some(Fitted {
        cov: inv * s2,
        x,
        rms,
        dof,
    })
}

/// `(J^T J)^-1`, or `None` when the columns are (numerically) dependent: the reciprocal
/// condition of the column-scaled normal matrix below 1e-12.
pub(crate) fn normal_inverse(j: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    let jtj = j.transpose() * j;
    let d: Vec<f64> = (0..jtj.nrows()).map(|k| jtj[(k, k)].sqrt()).collect();
    if d.iter().any(|v| v.is_nan() || *v <= 0.0 || !v.is_finite()) {
        return None;
    }
    let scaled = DMatrix::from_fn(jtj.nrows(), jtj.ncols(), |a, b| jtj[(a, b)] / (d[a] * d[b]));
    let eig = scaled.clone().symmetric_eigen();
    let (lo, hi) = eig
        .eigenvalues
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(l, h), &e| (l.min(e), h.max(e)));
    if lo.is_nan() || lo <= 1e-12 * hi {
        return None;
    }
    let inv = scaled.try_inverse()?;
    Some(DMatrix::from_fn(inv.nrows(), inv.ncols(), |a, b| {
        inv[(a, b)] / (d[a] * d[b])
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fits_a_line_with_its_covariance() {
        // y = 2 + 3 t with alternating +-0.1: the covariance is that of ordinary least squares.
        let t: Vec<f64> = (0..10).map(|k| k as f64).collect();
        let y: Vec<f64> = t
            .iter()
            .enumerate()
            .map(|(k, t)| 2.0 + 3.0 * t + if k % 2 == 0 { 0.1 } else { -0.1 })
            .collect();
        let f = |x: &DVector<f64>| DVector::from_fn(10, |k, _| x[0] + x[1] * t[k] - y[k]);
        let fit = solve(&f, DVector::from_vec(vec![0.0, 0.0]), 1.0).unwrap();
        assert!((fit.x[1] - 3.0).abs() < 0.05, "{}", fit.x);
        assert_eq!(fit.dof, 8);
        assert!(fit.cov[(1, 1)] > 0.0 && fit.cov[(1, 1)].sqrt() < 0.05);
    }

    #[test]
    fn a_parameter_the_data_do_not_see_is_refused() {
        let f = |x: &DVector<f64>| DVector::from_fn(5, |k, _| x[0] + x[1] - k as f64);
        assert!(solve(&f, DVector::from_vec(vec![0.0, 0.0]), 1.0).is_none());
    }
}
