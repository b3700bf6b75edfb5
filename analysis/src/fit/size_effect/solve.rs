//! One weighted least-squares over every cycle: the six coordinates and, per cycle, the
//! instrumental part of the acceleration error. That part is a constant the swaying's period
//! does not change (biases, scale errors, misalignments seen through the sway: the paper's
//! cancellation, possible with two periods or more) plus the tilt error `g x dtheta(t)`,
//! which grows at one rate while at rest and another while swaying. The stretches at rest
//! measure the tilt directly (the velocity's slope there), so the tilt that accumulates
//! between the two periods' spans is subtracted instead of being taken for size effect.

use super::{COORDS, SegmentDrift, drifts::RestDrift};
use nalgebra::{DMatrix, DVector};

/// The instrumental terms of one cycle.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CycleTerms {
    /// The period-independent part while swaying, East and North, m/s^2, with u; `None` when
    /// the cycle swayed at one period (it cannot be told from the size effect).
    pub constant: Option<[(f64, f64); 2]>,
    /// Growth of the tilt error (times g) while swaying and while at rest, m/s^3.
    pub growth_sway: [f64; 2],
    /// Growth at rest, m/s^3 (`None` without a stretch at rest).
    pub growth_rest: Option<[f64; 2]>,
    /// Tilt error times g at the cycle's start, m/s^2 (`None` without a stretch at rest).
    pub tilt0: Option<[f64; 2]>,
}

impl CycleTerms {
    /// The tilt error times g after `elapsed` (at rest, moving) seconds, m/s^2.
    pub fn tilt(&self, elapsed: [f64; 2]) -> [f64; 2] {
        std::array::from_fn(|c| {
            self.tilt0.map_or(0.0, |t| t[c])
                + self.growth_rest.map_or(0.0, |g| g[c] * elapsed[0])
                + self.growth_sway[c] * elapsed[1]
        })
    }
}

/// The size-effect estimate.
#[derive(Debug, Clone, Default)]
pub struct SizeEffect {
    /// `(value, u)` of each coordinate in metres, order of `COORDS`; `None` if unobservable.
    pub coords_m: [Option<(f64, f64)>; 6],
    /// Why each unobservable coordinate is (order of `COORDS`; empty when observable).
    pub unobservable: [String; 6],
    /// The segments' drifts and regressors.
    pub drifts: Vec<SegmentDrift>,
    /// The stretches at rest that measured the tilt.
    pub rests: Vec<RestDrift>,
    /// The instrumental terms of each cycle (index = `SegmentDrift::group`).
    pub cycles: Vec<CycleTerms>,
    /// Segments left out, and why.
    pub left_out: Vec<super::LeftOut>,
    /// The static segment each cycle aligned on (index = `SegmentDrift::group`).
    pub cycle_align: Vec<String>,
    /// What was left out or could not be cancelled.
    pub warnings: Vec<String>,
}

/// Columns of one cycle's instrumental terms in the design matrix.
#[derive(Clone, Copy, Default)]
struct Cols {
    constant: Option<usize>,
    tilt0: Option<usize>,
    rest: Option<usize>,
    sway: usize,
}

const AXES: [&str; 3] = ["X", "Y", "Z"];

/// The body axis a cycle must hold up to excite `r_ij`: the third one.
pub(crate) fn needed_axis(m: usize) -> &'static str {
    let (i, j, _) = COORDS[m];
    AXES[3 - i - j]
}

/// Solves for the coordinates.
pub(crate) fn solve(drifts: Vec<SegmentDrift>, rests: Vec<RestDrift>, est: &mut SizeEffect) {
    // Stretches at rest of a cycle none of whose segments could be used say nothing.
    let rests = rests
        .into_iter()
        .filter(|r| drifts.iter().any(|d| d.group == r.group))
        .collect();
    est.drifts = drifts;
    est.rests = rests;
    let (drifts, rests) = (&est.drifts, &est.rests);
    let n_groups = drifts.iter().map(|d| d.group + 1).max().unwrap_or(0);
    let mut cols = vec![Cols::default(); n_groups];
    let mut p = 6;
    for (g, col) in cols.iter_mut().enumerate() {
        let mut periods: Vec<f64> = drifts
            .iter()
            .filter(|d| d.group == g)
            .map(|d| d.period_s)
            .collect();
        if periods.is_empty() {
            continue;
        }
        periods.sort_by(f64::total_cmp);
        periods.dedup_by(|a, b| (*a - *b).abs() < 1e-3 * b.abs());
        let mut take = |n: usize| {
            let c = p;
            p += n;
            c
        };
        if periods.len() >= 2 {
            col.constant = Some(take(2));
        } else if let Some(d) = drifts.iter().find(|d| d.group == g) {
            est.warnings.push(format!(
                "size effect: the cycle of {} swayed at one period only: its instrumental errors are not cancelled",
                d.id
            ));
        }
        if rests.iter().any(|r| r.group == g) {
            col.tilt0 = Some(take(2));
            col.rest = Some(take(2));
        }
        col.sway = take(2);
    }
    if drifts.is_empty() {
        est.warnings
            .push("size effect: no oscillation segment could be used".into());
        for m in 0..6 {
            est.unobservable[m] = format!(
                "no usable swaying cycle; it needs one about a vertical axis with {} up",
                needed_axis(m)
            );
        }
        return;
    }
    let rows = drifts.len() * 4 + rests.len() * 4;
    let mut a = DMatrix::<f64>::zeros(rows, p);
    let mut y = DVector::<f64>::zeros(rows);
    let tilt_cols = |a: &mut DMatrix<f64>, r: usize, c: usize, col: &Cols, el: [f64; 2], w| {
        if let (Some(t0), Some(rest)) = (col.tilt0, col.rest) {
            a[(r, t0 + c)] = w;
            a[(r, rest + c)] = el[0] * w;
        }
        a[(r, col.sway + c)] = el[1] * w;
    };
    for (k, d) in drifts.iter().enumerate() {
        let col = cols[d.group];
        for c in 0..2 {
            let r = 4 * k + c;
            let w = 1.0 / d.u_mps2[c].max(1e-9);
            for m in 0..6 {
                a[(r, m)] = d.h[c][m] * w;
            }
            if let Some(b) = col.constant {
                a[(r, b + c)] = w;
            }
            tilt_cols(&mut a, r, c, &col, d.elapsed_s, w);
            y[r] = d.drift_mps2[c] * w;
            let (trend, u) = d.trend[c];
            let w2 = 1.0 / u.max(1e-12);
            for m in 0..6 {
                a[(r + 2, m)] = d.h_trend[c][m] * w2;
            }
            a[(r + 2, col.sway + c)] = w2;
            y[r + 2] = trend * w2;
        }
    }
    for (k, rest) in rests.iter().enumerate() {
        let col = cols[rest.group];
        for c in 0..2 {
            let r = 4 * (drifts.len() + k) + c;
            let w = 1.0 / rest.slope[c].1.max(1e-12);
            tilt_cols(&mut a, r, c, &col, rest.elapsed_s, w);
            y[r] = rest.slope[c].0 * w;
            let w2 = 1.0 / rest.trend[c].1.max(1e-14);
            if let Some(rc) = col.rest {
                a[(r + 2, rc + c)] = w2;
            }
            y[r + 2] = rest.trend[c].0 * w2;
        }
    }
    // Coordinates no cycle excites are unobservable; so are those only seen through the
    // small tilt of a cycle whose main coordinates share their signature (X tilted 3 deg
    // couples rxz and rzx into ryz at 5 %): the weakest goes first until the rest separate.
    let norms: Vec<f64> = (0..6)
        .map(|m| drifts.iter().map(|d| d.h[0][m].hypot(d.h[1][m])).sum())
        .collect();
    let max = norms.iter().copied().fold(0.0, f64::max);
    let mut coords: Vec<usize> = (0..6).filter(|&m| norms[m] > 1e-6 * max).collect();
    for m in 0..6 {
        if !coords.contains(&m) {
            est.unobservable[m] = format!(
                "no usable swaying cycle excites it: it needs one about a vertical axis with {} up",
                needed_axis(m)
            );
        }
    }
    let instr: Vec<usize> = (6..p).collect();
    let (x, cov, keep, shifts) = loop {
        let keep: Vec<usize> = coords.iter().chain(&instr).copied().collect();
        let ak = a.select_columns(&keep);
        // Bounded: nalgebra's plain `svd` iterates without limit on a matrix it cannot
        // converge on.
        let Some(svd) = ak.clone().try_svd(true, true, f64::EPSILON, 10_000) else {
            est.warnings
                .push("size effect: the least-squares decomposition did not converge".into());
            return;
        };
        let sv = &svd.singular_values;
        let smax = sv.max();
        let tol = 1e-9 * smax;
        let v_t = svd.v_t.as_ref().expect("asked for V");
        // Coordinates in the null space cannot be told apart from something else.
        let mut tangled: Vec<usize> = Vec::new();
        for (q, s) in sv.iter().enumerate() {
            if *s <= tol || s.is_nan() {
                for (kq, &m) in keep.iter().enumerate() {
                    if m < 6 && v_t[(q, kq)].abs() > 1e-3 && !tangled.contains(&m) {
                        tangled.push(m);
                    }
                }
            }
        }
        if let Some(&weakest) = tangled
            .iter()
            .min_by(|a, b| norms[**a].total_cmp(&norms[**b]))
        {
            coords.retain(|&m| m != weakest);
            let with: Vec<&str> = tangled
                .iter()
                .filter(|&&m| m != weakest)
                .map(|&m| COORDS[m].2)
                .collect();
            est.unobservable[weakest] = format!(
                "only seen through the tilt of a cycle whose own coordinates share its signature ({}): it needs a cycle about a vertical axis with {} up",
                with.join(", "),
                needed_axis(weakest)
            );
            continue;
        }
        let Ok(x) = svd.solve(&y, tol) else {
            est.warnings
                .push("size effect: the least-squares solution failed".into());
            return;
        };
        // Covariance from the pseudo-inverse (instrumental columns nothing separates stay
        // out of it; the coordinates are not in their null space).
        let n = keep.len();
        let mut cov = DMatrix::<f64>::zeros(n, n);
        for (q, s) in sv.iter().enumerate() {
            if *s > tol {
                let v = v_t.row(q).transpose();
                cov += &v * v.transpose() / (s * s);
            }
        }
        let used = (0..rows).filter(|&r| ak.row(r).norm() > 0.0).count();
        let rank = sv.iter().filter(|s| **s > tol).count();
        let dof = used.saturating_sub(rank);
        let scale = if dof > 0 {
            let r = &y - &ak * &x;
            (r.norm_squared() / dof as f64).max(1.0)
        } else {
            1.0
        };
        // What each coordinate left out moves the kept ones by, per metre of it.
        let shifts: Vec<(usize, DVector<f64>)> = (0..6)
            .filter(|m| !coords.contains(m) && norms[*m] > 0.0)
            .filter_map(|m| Some((m, svd.solve(&a.column(m).into_owned(), tol).ok()?)))
            .collect();
        break (x, cov * scale, keep, shifts);
    };
    let val = |col: usize| {
        keep.iter()
            .position(|&m| m == col)
            .map(|q| (x[q], cov[(q, q)].sqrt()))
    };
    for m in coords.iter().copied() {
        est.coords_m[m] = val(m);
    }
    // A coordinate left out that a kept one's cycle couples in is taken as zero there:
    // say by how much each millimetre of it moves the kept ones.
    for (m, shift) in &shifts {
        let moved: Vec<String> = keep
            .iter()
            .enumerate()
            .filter(|(q, k)| **k < 6 && shift[*q].abs() > 0.01)
            .map(|(q, &k)| format!("{} by {:+.2} mm", COORDS[k].2, shift[q]))
            .collect();
        if !moved.is_empty() {
            est.warnings.push(format!(
                "size effect: {} is not observable and is taken as 0 where a tilted cycle couples it in: each mm of it would move {}",
                COORDS[*m].2,
                moved.join(", ")
            ));
        }
    }
    est.cycles = cols
        .iter()
        .map(|col| {
            let pair = |b: usize| [val(b), val(b + 1)];
            let both = |b: usize| {
                let [e, n] = pair(b);
                Some([e?, n?])
            };
            CycleTerms {
                constant: col.constant.and_then(both),
                growth_sway: both(col.sway).map_or([0.0; 2], |v| v.map(|v| v.0)),
                growth_rest: col.rest.and_then(both).map(|v| v.map(|v| v.0)),
                tilt0: col.tilt0.and_then(both).map(|v| v.map(|v| v.0)),
            }
        })
        .collect();
}
