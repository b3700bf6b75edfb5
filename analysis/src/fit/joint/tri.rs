//! Least squares kept as a triangle: rows are folded into an upper-triangular factor by
//! Householder reflections, a block at a time, so a design matrix of any length is never
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
        fold(&mut self.stack, self.cols, self.rows);
        self.rows = 0;
    }

    /// The factor, every pending row folded in.
    pub(crate) fn finish(mut self) -> DMatrix<f64> {
        self.flush();
        let c = self.cols;
        self.stack.rows(0, c).into_owned()
    }
}

/// Folds the `rows` rows below the upper-triangular `R` (the first `cols` rows of
/// `stack`) into it by Householder reflections, in place. A reflection of column `j`
/// involves `R`'s row `j` and the new rows only (the rest of the column is zero), so a fold
/// costs `2 rows cols^2` flops, and the stack is never copied. The rows below `R` are left
/// as scratch.
fn fold(stack: &mut DMatrix<f64>, cols: usize, rows: usize) {
    let (k, r) = (cols, rows);
    let ld = stack.nrows();
    let a = stack.as_mut_slice();
    for j in 0..k {
        let (head, tail) = a.split_at_mut((j + 1) * ld);
        let cj = &mut head[j * ld..];
        let x = &cj[k..k + r];
        let sigma = dot(x, x);
        if sigma == 0.0 {
            continue;
        }
        let x0 = cj[j];
        let norm = (x0 * x0 + sigma).sqrt();
        let alpha = if x0 > 0.0 { -norm } else { norm };
        let v0 = x0 - alpha;
        // H = I - beta v v^T with v = [v0; x], beta = 2 / |v|^2.
        let beta = 2.0 / (v0 * v0 + sigma);
        cj[j] = alpha;
        let x = &cj[k..k + r];
        for cl in tail.chunks_exact_mut(ld).take(k - j - 1) {
            let f = beta * (v0 * cl[j] + dot(x, &cl[k..k + r]));
            cl[j] -= f * v0;
            for (xi, ai) in x.iter().zip(&mut cl[k..k + r]) {
                *ai -= f * xi;
            }
        }
    }
}

/// `a . b` in four running sums, which the compiler keeps in vector registers (one
/// running sum is a chain of dependent additions).
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut s = [0.0f64; 4];
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let tail: f64 = ca
        .remainder()
        .iter()
        .zip(cb.remainder())
        .map(|(x, y)| x * y)
        .sum();
    for (x, y) in ca.zip(cb) {
        for ((s, x), y) in s.iter_mut().zip(x).zip(y) {
            *s += x * y;
        }
    }
    (s[0] + s[1]) + (s[2] + s[3]) + tail
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

    #[test]
    fn folding_agrees_with_a_full_qr_up_to_row_signs() {
        let mut t = Tri::new(5);
        let mut rows = Vec::new();
        for i in 0..700 {
            let x = i as f64 * 0.013;
            let row = [1.0, x, x * x, (3.0 * x).cos(), 0.2 - x + (x * 11.0).sin()];
            t.push(&row);
            rows.extend_from_slice(&row);
        }
        let a = DMatrix::from_row_slice(700, 5, &rows);
        let (r, q) = (t.finish(), triangle(a, 5));
        for i in 0..5 {
            let s = (r[(i, i)] * q[(i, i)]).signum();
            for j in 0..5 {
                assert!(
                    (r[(i, j)] - s * q[(i, j)]).abs() < 1e-9 * q.norm(),
                    "{i} {j}"
                );
                if j < i {
                    assert_eq!(r[(i, j)], 0.0);
                }
            }
        }
    }
}
