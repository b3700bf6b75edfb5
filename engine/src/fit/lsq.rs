//! Linear least squares by normal equations (the systems are small: up to 4 unknowns,
//! many samples), with the covariance and an observability test.

use nalgebra::{DMatrix, DVector};

/// Accumulated normal equations of `y = A x`.
#[derive(Debug, Clone)]
pub(crate) struct Normal {
    ata: DMatrix<f64>,
    aty: DVector<f64>,
    yty: f64,
    n: usize,
}

/// A solved least-squares problem.
#[derive(Debug, Clone)]
pub(crate) struct Solution {
    /// Estimates.
    pub x: DVector<f64>,
    /// `(A^T A)^-1`.
    pub inv: DMatrix<f64>,
    /// Residual variance `|y - A x|^2 / (n - p)`.
    pub sigma2: f64,
}

impl Normal {
    /// Empty system with `p` unknowns.
    pub(crate) fn new(p: usize) -> Self {
        Normal {
            ata: DMatrix::zeros(p, p),
            aty: DVector::zeros(p),
            yty: 0.0,
            n: 0,
        }
    }

    /// Adds one observation row.
    pub(crate) fn add(&mut self, row: &[f64], y: f64) {
        let p = row.len();
        for i in 0..p {
            for j in 0..p {
                self.ata[(i, j)] += row[i] * row[j];
            }
            self.aty[i] += row[i] * y;
        }
        self.yty += y * y;
        self.n += 1;
    }

    /// Columns whose RMS is below `rel` times the largest column's: the motion did not
    /// excite them.
    pub(crate) fn weak_columns(&self, rel: f64) -> Vec<usize> {
        let p = self.aty.len();
        let rms: Vec<f64> = (0..p)
            .map(|i| (self.ata[(i, i)] / self.n.max(1) as f64).sqrt())
            .collect();
        let max = rms.iter().copied().fold(0.0, f64::max);
        (0..p).filter(|&i| rms[i] <= rel * max).collect()
    }

    /// Solves with only the columns `cols`; `None` when they are (numerically) dependent.
    pub(crate) fn solve(&self, cols: &[usize]) -> Option<Solution> {
        let p = cols.len();
        if self.n <= p {
            return None;
        }
        let ata = DMatrix::from_fn(p, p, |i, j| self.ata[(cols[i], cols[j])]);
        let aty = DVector::from_fn(p, |i, _| self.aty[cols[i]]);
        // Equilibrate so the condition number measures dependence, not units.
        let d = DVector::from_fn(p, |i, _| 1.0 / ata[(i, i)].sqrt().max(1e-300));
        let scaled = DMatrix::from_fn(p, p, |i, j| ata[(i, j)] * d[i] * d[j]);
        let eig = scaled.clone().symmetric_eigen();
        let (lo, hi) = eig
            .eigenvalues
            .iter()
            .fold((f64::MAX, 0.0f64), |(l, h), &e| (l.min(e), h.max(e)));
        if lo.is_nan() || lo <= hi * 1e-12 {
            return None;
        }
        let sinv = scaled.try_inverse()?;
        let inv = DMatrix::from_fn(p, p, |i, j| sinv[(i, j)] * d[i] * d[j]);
        let x = &inv * &aty;
        // |y - Ax|^2 = y'y - 2 x'A'y + x'A'A x
        let rss = (self.yty - 2.0 * x.dot(&aty) + x.dot(&(&ata * &x))).max(0.0);
        Some(Solution {
            x,
            inv,
            sigma2: rss / (self.n - p) as f64,
        })
    }
}

impl Solution {
    /// Standard uncertainty of estimate `i`, the covariance scaled by the residual
    /// variance and by a noise-correlation factor.
    pub(crate) fn u(&self, i: usize, inflation: f64) -> f64 {
        (self.sigma2 * inflation * self.inv[(i, i)]).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_fit_matches_closed_form() {
        let xs = [0.0, 1.0, 2.0, 3.0, 4.0];
        let ys = [1.1, 2.9, 5.2, 7.1, 8.8];
        let mut ne = Normal::new(2);
        for (x, y) in xs.iter().zip(ys) {
            ne.add(&[*x, 1.0], y);
        }
        let s = ne.solve(&[0, 1]).unwrap();
        // closed form: slope = Sxy/Sxx with Sxx = 10, Sxy = 19.6
        assert!((s.x[0] - 1.96).abs() < 1e-12);
        assert!((s.x[1] - (5.02 - 1.96 * 2.0)).abs() < 1e-12);
        let rss: f64 = xs
            .iter()
            .zip(ys)
            .map(|(x, y)| (y - s.x[0] * x - s.x[1]).powi(2))
            .sum();
        assert!((s.sigma2 - rss / 3.0).abs() < 1e-12);
        assert!((s.u(0, 1.0) - (rss / 3.0 / 10.0).sqrt()).abs() < 1e-12);
    }

    #[test]
    fn dependent_columns_are_refused() {
        let mut ne = Normal::new(2);
        for x in [1.0, 2.0, 3.0] {
            ne.add(&[x, 2.0 * x], x);
        }
        assert!(ne.solve(&[0, 1]).is_none());
    }
}
