//! A model under test: registry effects fitted, some held at known values, over a set of
//! segments per sensor; and how much each segment excites each column.

use super::{Fit, FitRequest, Layout, SegAcc, WanderRule, solve};
use ratecal_physics::effects::{EarthRate, Sensor};

/// Effects (layout indices) and fixed values of a model.
#[derive(Debug, Clone, Default)]
pub(crate) struct Terms {
    /// Fitted effects.
    pub effects: Vec<usize>,
    /// Effects held at values.
    pub fixed: Vec<(usize, Vec<f64>)>,
    /// Columns of fitted effects left out on purpose (a procedure's gyro scale fit that
    /// names only some axes).
    pub skip: Vec<usize>,
}

impl Terms {
    /// Whether every column of layout effect `e` is skipped: a candidate the recording
    /// cannot determine, never fitted.
    pub(crate) fn skips_all(&self, layout: &Layout, e: usize) -> bool {
        layout.columns_of(e).all(|g| self.skip.contains(&g))
    }

    /// The ids, fitted then fixed (`earth_rate (fixed)`).
    pub(crate) fn names(&self, layout: &Layout) -> Vec<String> {
        self.effects
            .iter()
            .map(|&e| layout.effects[e].id().to_string())
            .chain(
                self.fixed
                    .iter()
                    .map(|(e, _)| format!("{} (fixed)", layout.effects[*e].id())),
            )
            .collect()
    }
}

/// Column RMS of a segment's regressors: how much each column varies there.
pub(crate) fn excitation(layout: &Layout, acc: &SegAcc) -> Vec<f64> {
    let mut ex = vec![0.0f64; layout.cols.len()];
    for c in 0..6 {
        let r = &acc.r[c];
        for (k, &g) in layout.by_channel[c].iter().enumerate() {
            let rms = r.column(k).norm() / (acc.n.max(1) as f64).sqrt();
            ex[g] = ex[g].max(rms);
        }
    }
    ex
}

/// Whether segment `i` excites any column of layout effect `e` to at least a thousandth of
/// the most any segment does: the segments an added effect widens a fit to.
pub(crate) fn excites(layout: &Layout, excitation: &[Vec<f64>], e: usize, i: usize) -> bool {
    let cols: Vec<usize> = layout.columns_of(e).collect();
    let most = |i: usize| cols.iter().map(|&g| excitation[i][g]).fold(0.0, f64::max);
    let top = (0..excitation.len()).map(most).fold(0.0, f64::max);
    top > 0.0 && most(i) > 1e-3 * top
}

/// Fits terms over segments (indices into `accs`) for each sensor. Columns of an effect
/// that these segments barely excite (below a thousandth of the effect's most excited
/// column) are left out as unobservable, as are skipped ones.
pub(crate) fn fit_terms(
    layout: &Layout,
    accs: &[SegAcc],
    excitation: &[Vec<f64>],
    terms: &Terms,
    accel: &[usize],
    gyro: &[usize],
) -> (Fit, Vec<usize>) {
    fit_terms_merged(
        layout,
        accs,
        excitation,
        terms,
        accel,
        gyro,
        None,
        WanderRule::Estimated,
    )
}

/// [`fit_terms`] with the channels' factors over these segments already merged
/// ([`super::solve::merge`]); `wander` says how the covariance takes the wandering bias.
#[allow(clippy::too_many_arguments)]
pub(crate) fn fit_terms_merged(
    layout: &Layout,
    accs: &[SegAcc],
    excitation: &[Vec<f64>],
    terms: &Terms,
    accel: &[usize],
    gyro: &[usize],
    merged: Option<&super::Pooled>,
    wander: WanderRule,
) -> (Fit, Vec<usize>) {
    let mut cols = Vec::new();
    let mut weak = Vec::new();
    for &e in &terms.effects {
        let range = layout.columns_of(e);
        let sensors = layout.effects[e].sensors();
        let ex: Vec<f64> = range
            .clone()
            .map(|g| {
                let mut m = 0.0f64;
                for (s, segs) in [(Sensor::Accel, accel), (Sensor::Gyro, gyro)] {
                    if sensors.contains(&s) {
                        for &i in segs {
                            m = m.max(excitation[i][g]);
                        }
                    }
                }
                m
            })
            .collect();
        let top = ex.iter().copied().fold(0.0, f64::max);
        for (k, g) in range.enumerate() {
            if terms.skip.contains(&g) {
                continue;
            }
            if ex[k] > 1e-3 * top && top > 0.0 {
                cols.push(g);
            } else {
                weak.push(g);
            }
        }
    }
    let mut fixed = Vec::new();
    for (e, v) in &terms.fixed {
        for (k, g) in layout.columns_of(*e).enumerate() {
            fixed.push((g, v[k]));
        }
    }
    let req = FitRequest {
        layout,
        cols,
        fixed,
        accel: accel.iter().map(|&i| &accs[i]).collect(),
        gyro: gyro.iter().map(|&i| &accs[i]).collect(),
        merged,
        wander,
    };
    let f = solve(&req);
    let mut unobs = f.unobservable.clone();
    unobs.extend(weak);
    unobs.sort_unstable();
    (f, unobs)
}

/// The latitude (deg, with its u) that a fit's Earth-rate components give, when the layout
/// effect `e` is `earth_rate` and both components were estimated.
pub(crate) fn latitude_of(layout: &Layout, fit: &Fit, e: usize) -> Option<(f64, f64)> {
    if layout.effects[e].id() != "earth_rate" {
        return None;
    }
    let r = layout.columns_of(e);
    let (n, u) = (r.start, r.start + 1);
    if !(fit.estimated.contains(&n) && fit.estimated.contains(&u)) {
        return None;
    }
    let c = &fit.cov;
    Some(EarthRate::latitude_deg(
        fit.theta[n],
        fit.theta[u],
        [[c[(n, n)], c[(n, u)]], [c[(u, n)], c[(u, u)]]],
    ))
}
