//! Least squares kept as a triangle: rows are folded into an upper-triangular factor by
//! Householder reflections, a block at a time, so a design matrix of any length is never
//! held whole and the normal equations are never formed.
//!
//! A column that has kept its first value in every row so far (at rest, every regressor
//! that follows only the attitude) is not folded: it is that value times a column of
//! ones, which is folded once for all of them. The column joins the fold, with the history
//! the ones column holds for it, at the first row where it changes. A static hour's rows
//! then cost the square of the columns that follow time or temperature, not of all of
//! them.

use nalgebra::DMatrix;

/// Rows folded per QR: few enough that a fold's columns (a static hour has about twenty
/// moving) stay in the first-level cache while each reflection sweeps them.
const BLOCK: usize = 64;

/// The triangular factor `R` of `[X y]` (the last column is the observation): `R^T R =
/// [X y]^T [X y]`, so any least-squares question about the rows can be answered from it.
/// Rows are written straight below `R` into one column-major stack, folded every
/// [`BLOCK`] rows.
#[derive(Debug, Clone)]
pub(crate) struct Tri {
    cols: usize,
    /// The stack's first column is the ones column, then the caller's columns that have
    /// changed, in the order they changed: `R` in the first `cols + 1` rows, then the
    /// pending rows.
    stack: DMatrix<f64>,
    /// Stack columns in use (the ones column included).
    active: usize,
    /// Per caller column, its stack column once it has changed.
    pos: Vec<Option<usize>>,
    /// `(caller column, stack column)` of the columns that have changed.
    moving: Vec<(usize, usize)>,
    /// Caller columns that have kept their first value so far.
    still: Vec<usize>,
    /// The first row.
    first: Vec<f64>,
    rows: usize,
    /// Rows folded in so far.
    pub n: usize,
}

impl Tri {
    /// An empty factor of `cols` columns (regressors and the observation).
    pub(crate) fn new(cols: usize) -> Self {
        let k = cols + 1;
        Tri {
            cols,
            stack: DMatrix::zeros(k + BLOCK, k),
            active: 1,
            pos: vec![None; cols],
            moving: Vec::with_capacity(cols),
            still: (0..cols).collect(),
            first: Vec::new(),
            rows: 0,
            n: 0,
        }
    }

    /// Adds one row (regressors then the observation).
    #[cfg(test)]
    pub(crate) fn push(&mut self, row: &[f64]) {
        self.push_changed(row, None);
    }

    /// Adds one row (regressors then the observation), of which only the columns
    /// `changed` (ascending) may differ from the previous row's (`None`: any).
    pub(crate) fn push_changed(&mut self, row: &[f64], changed: Option<&[usize]>) {
        debug_assert_eq!(row.len(), self.cols);
        if self.n == 0 {
            self.first = row.to_vec();
        } else if !self.still.is_empty() {
            // Bits, not values: a NaN that stays is constant, and -0 is not 0.
            let first = &self.first;
            let pos = &self.pos;
            let differs = |l: &usize| row[*l].to_bits() != first[*l].to_bits();
            // A column that is still and unchanged since the previous row is still.
            let now: Vec<usize> = match changed {
                Some(cols) => (cols.iter())
                    .filter(|l| pos[**l].is_none() && differs(l))
                    .copied()
                    .collect(),
                None => self.still.iter().filter(|l| differs(l)).copied().collect(),
            };
            if !now.is_empty() {
                self.still.retain(|l| !now.contains(l));
                for l in now {
                    self.start_moving(l);
                }
            }
        }
        let k = self.cols + 1;
        let i = k + self.rows;
        let ld = self.stack.nrows();
        let a = self.stack.as_mut_slice();
        a[i] = 1.0;
        for &(l, p) in &self.moving {
            a[p * ld + i] = row[l];
        }
        self.rows += 1;
        self.n += 1;
        if self.rows == BLOCK {
            self.flush();
        }
    }

    /// Caller column `l` changes: it joins the fold as its first value times the ones
    /// column, in the factor and in the pending rows.
    fn start_moving(&mut self, l: usize) {
        let (k, p, c) = (self.cols + 1, self.active, self.first[l]);
        self.active += 1;
        self.pos[l] = Some(p);
        self.moving.push((l, p));
        // The ones column of an upper-triangular factor is its corner alone.
        self.stack[(0, p)] = c * self.stack[(0, 0)];
        for i in 0..self.rows {
            self.stack[(k + i, p)] = c;
        }
    }

    fn flush(&mut self) {
        if self.rows == 0 {
            return;
        }
        fold(&mut self.stack, self.active, self.cols + 1, self.rows);
        self.rows = 0;
    }

    /// The factor, every pending row folded in.
    pub(crate) fn finish(mut self) -> DMatrix<f64> {
        self.flush();
        let c = self.cols;
        if self.n == 0 {
            return DMatrix::zeros(c, c);
        }
        // The caller's columns from the fold's: a constant one is its value times the
        // ones column. One QR of a square matrix puts them back in the caller's order.
        let a = self.active;
        let full = DMatrix::from_fn(a, c, |i, l| match self.pos[l] {
            Some(p) => self.stack[(i, p)],
            None => self.first[l] * self.stack[(i, 0)],
        });
        triangle(full, c)
    }
}

/// Folds the `rows` rows that start at row `k` of `stack` into the upper-triangular `R`
/// of its first `cols` columns (its first `cols` rows; zero down to row `k`) by
/// Householder reflections, in place. A reflection of column `j` involves `R`'s row `j`
/// and the new rows only (the rest of the column is zero), so a fold costs `2 rows cols^2`
/// flops, and the stack is never copied. The rows below `R` are left as scratch.
///
/// Each reflection is LAPACK's (`dlarfg`/`dlarf`): `H = I - tau u u^T` with `u = [1; x /
/// v0]` and `tau` in `[1, 2]`, so no step divides by a square of the column's size. A
/// column of tiny values (a decay long gone, 1e-150) would otherwise underflow `|v|^2` to a
/// subnormal or zero and make its `2 / |v|^2` infinite: every later column of the factor,
/// and every fit that uses it, would be NaN.
fn fold(stack: &mut DMatrix<f64>, cols: usize, k: usize, rows: usize) {
    let r = rows;
    let ld = stack.nrows();
    let a = stack.as_mut_slice();
    for j in 0..cols {
        let (head, tail) = a.split_at_mut((j + 1) * ld);
        let cj = &mut head[j * ld..];
        let x0 = cj[j];
        let x = &mut cj[k..k + r];
        let Some(norm) = column_norm(x0, x) else {
            continue;
        };
        let alpha = if x0 > 0.0 { -norm } else { norm };
        // |v0| is between |alpha| and 2 |alpha|: x / v0 stays within [-1, 1].
        let v0 = x0 - alpha;
        let tau = -v0 / alpha;
        let inv = 1.0 / v0;
        for xi in x.iter_mut() {
            *xi *= inv;
        }
        cj[j] = alpha;
        let u = &cj[k..k + r];
        for cl in tail.chunks_exact_mut(ld).take(cols - j - 1) {
            let f = tau * (cl[j] + dot(u, &cl[k..k + r]));
            cl[j] -= f;
            for (ui, ai) in u.iter().zip(&mut cl[k..k + r]) {
                *ai -= f * ui;
            }
        }
    }
}

/// `|[x0; x]|` when `x` has something to fold (`None` when it is all zeros, or so small
/// that the column is zero to within what a double holds), computed without underflow
/// or overflow.
fn column_norm(x0: f64, x: &[f64]) -> Option<f64> {
    let sigma = dot(x, x);
    let norm = if sigma > 1e-200 && sigma < 1e200 {
        (x0 * x0 + sigma).sqrt()
    } else if sigma.is_nan() {
        f64::NAN
    } else {
        // Scaled by the largest entry: nothing squared leaves the range of a double.
        let amax = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if amax == 0.0 {
            return None;
        }
        let amax = amax.max(x0.abs());
        let s = (x0 / amax).powi(2) + x.iter().map(|v| (v / amax).powi(2)).sum::<f64>();
        amax * s.sqrt()
    };
    // A column below the smallest normal double folds nothing a fit could see (a NaN
    // goes on, so that it shows in the fit).
    (norm >= f64::MIN_POSITIVE || norm.is_nan()).then_some(norm)
}

/// `a . b` in sixteen running sums: one running sum is a chain of dependent additions, and
/// the baseline x86-64 target has two doubles to a vector register, so it takes eight
/// independent chains to keep the adder busy while each addition's latency passes (the
/// dot products of the reflections are most of a fold).
fn dot(a: &[f64], b: &[f64]) -> f64 {
    const L: usize = 16;
    let mut s = [0.0f64; L];
    let (ca, cb) = (a.chunks_exact(L), b.chunks_exact(L));
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
    let mut w = L;
    while w > 1 {
        w /= 2;
        for i in 0..w {
            s[i] += s[i + w];
        }
    }
    s[0] + tail
}

/// The `cols x cols` upper-triangular factor of a stack of rows: the rows folded into a
/// zero factor, by the same reflections as every other fold.
pub(crate) fn triangle(m: DMatrix<f64>, cols: usize) -> DMatrix<f64> {
    debug_assert_eq!(m.ncols(), cols);
    let rows = m.nrows();
    let mut stack = DMatrix::zeros(cols + rows, cols);
    stack.view_mut((cols, 0), (rows, cols)).copy_from(&m);
    fold(&mut stack, cols, cols, rows);
    stack.rows(0, cols).into_owned()
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
        let (r, q) = (t.finish(), a.qr().r());
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

    #[test]
    fn columns_of_tiny_values_fold_without_nan() {
        // A decay long gone (1e-160) beside ordinary columns: its squares are subnormal,
        // and `2 / |v|^2` would be infinite.
        let mut t = Tri::new(4);
        let mut rows = Vec::new();
        for i in 0..600 {
            let x = i as f64 * 0.01;
            let row = [1.0, 1e-160 * (1.0 + x), 1e-170 * x.cos(), 0.3 + x];
            t.push(&row);
            rows.extend_from_slice(&row);
        }
        let r = t.finish();
        assert!(r.iter().all(|v| v.is_finite()), "{r}");
        // Columns 0 and 3 are as a full QR gives them.
        let a = DMatrix::from_row_slice(600, 4, &rows);
        let g = a.transpose() * &a;
        let h = r.transpose() * &r;
        for (i, j) in [(0, 0), (0, 3), (3, 3)] {
            assert!(
                (g[(i, j)] - h[(i, j)]).abs() < 1e-12 * g[(i, j)].abs(),
                "{i} {j}"
            );
        }
        // The tiny column keeps its length (compared scaled up, out of the subnormals).
        let want = (0..600)
            .map(|i| (1.0 + i as f64 * 0.01).powi(2))
            .sum::<f64>()
            .sqrt();
        let got = (r.column(1) * 1e160).norm();
        assert!((got / want - 1.0).abs() < 1e-12, "{got} {want}");
    }

    #[test]
    fn an_all_zero_column_stays_zero() {
        let mut t = Tri::new(3);
        for i in 0..300 {
            t.push(&[1.0, 0.0, i as f64]);
        }
        let r = t.finish();
        assert!(r.iter().all(|v| v.is_finite()));
        assert_eq!(r.column(1).norm(), 0.0);
    }

    #[test]
    fn columns_that_start_moving_late_are_folded_with_their_history() {
        // Constant throughout, constant until row 300 (past a fold), until row 3, always
        // moving, and the observation.
        let mut t = Tri::new(5);
        let mut rows = Vec::new();
        for i in 0..700 {
            let x = i as f64 * 0.01;
            let late = if i < 300 { 2.5 } else { 2.5 + (x * 3.0).sin() };
            let early = if i < 3 { -1.0 } else { x * x };
            let row = [
                0.7,
                late,
                early,
                x.cos(),
                1.0 + 0.3 * x + 0.01 * (x * 13.0).sin(),
            ];
            t.push(&row);
            rows.extend_from_slice(&row);
        }
        let a = DMatrix::from_row_slice(700, 5, &rows);
        let r = t.finish();
        let (g, h) = (a.transpose() * &a, r.transpose() * &r);
        assert!((&g - &h).norm() < 1e-12 * g.norm(), "{g} {h}");
        for i in 0..5 {
            for j in 0..i {
                assert_eq!(r[(i, j)], 0.0);
            }
        }
    }

    #[test]
    fn no_rows_give_a_zero_factor() {
        assert_eq!(Tri::new(4).finish(), DMatrix::zeros(4, 4));
    }
}
