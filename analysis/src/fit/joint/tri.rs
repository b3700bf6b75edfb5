//! Least squares kept as a triangle: rows are folded into an upper-triangular factor by
//! Householder QR (nalgebra), a block at a time, so a design matrix of any length is never
//! held whole and the normal equations are never formed.

use nalgebra::DMatrix;

/// Rows folded per QR.
const BLOCK: usize = 256;

/// The triangular factor `R` of `[X y]` (the last column is the observation): `R^T R =
/// [X y]^T [X y]`, so any least-squares question about the rows can be answered from it.
/// Rows are written straight below `R` into one column-major stack, folded every
/// [`BLOCK`] rows.
#[derive(Debug, Clone)]
pub(crate) struct Tri {
    cols: usize,
    /// `R` in the first `cols` rows, then the pending rows.
    stack: DMatrix<f64>,
    rows: usize,
    /// Rows folded in so far.
    pub n: usize,
}

impl Tri {
    /// An empty factor of `cols` columns (regressors and the observation).
    pub(crate) fn new(cols: usize) -> Self {
        Tri {
            cols,
            stack: DMatrix::zeros(cols + BLOCK, cols),
            rows: 0,
            n: 0,
        }
    }

    /// Adds one row (regressors then the observation).
    pub(crate) fn push(&mut self, row: &[f64]) {
        debug_assert_eq!(row.len(), self.cols);
        let i = self.cols + self.rows;
        for (j, v) in row.iter().enumerate() {
            self.stack[(i, j)] = *v;
        }
        self.rows += 1;
        self.n += 1;
        if self.rows == BLOCK {
            self.flush();
        }
    }

    fn flush(&mut self) {
        if self.rows == 0 {
            return;
        }
        let c = self.cols;
        let full = std::mem::replace(&mut self.stack, DMatrix::zeros(c + BLOCK, c));
        let used = if self.rows == BLOCK {
            full
        } else {
            full.rows(0, c + self.rows).into_owned()
        };
        let r = triangle(used, c);
        self.stack.view_mut((0, 0), (c, c)).copy_from(&r);
        self.rows = 0;
    }

    /// The factor, every pending row folded in.
    pub(crate) fn finish(mut self) -> DMatrix<f64> {
        self.flush();
        let c = self.cols;
        self.stack.rows(0, c).into_owned()
    }
}

/// The `cols x cols` upper-triangular factor of a stack of rows.
pub(crate) fn triangle(m: DMatrix<f64>, cols: usize) -> DMatrix<f64> {
    let r = m.qr().r();
    let mut out = DMatrix::zeros(cols, cols);
    let k = r.nrows().min(cols);
    out.view_mut((0, 0), (k, cols)).copy_from(&r.rows(0, k));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn folded_factor_reproduces_the_gram_matrix() {
        let mut t = Tri::new(3);
        let mut rows = Vec::new();
        for i in 0..1000 {
            let x = i as f64 * 0.01;
            let row = [1.0, x, 2.0 + 0.5 * x + (x * 7.0).sin() * 0.1];
            t.push(&row);
            rows.extend_from_slice(&row);
        }
        let a = DMatrix::from_row_slice(1000, 3, &rows);
        let r = t.finish();
        let g = a.transpose() * &a;
        let h = r.transpose() * &r;
        assert!((g - h).norm() < 1e-8 * 1000.0);
    }
}
