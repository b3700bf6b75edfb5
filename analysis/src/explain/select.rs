//! Forward selection over the registry's catalogue: at each step every remaining
//! candidate is added to the whole model, which is refitted; the most significant one
//! (Wald test with the honest covariance) is kept when it passes the threshold and lowers
//! the residual on the held-out segments. Selection stops when none does.

use super::data::Data;
use super::model::{Terms, fit};
use crate::fit::joint::{Fit, seg_rss};
use nalgebra::DMatrix;
use statrs::distribution::{ChiSquared, ContinuousCDF};

/// One accepted step.
pub(crate) struct Step {
    /// Layout index of the effect.
    pub effect: usize,
    /// The model before and after.
    pub before: Fit,
    /// After.
    pub after: Fit,
    /// Wald statistic, dof, p-value, threshold.
    pub chi2: f64,
    /// Degrees of freedom.
    pub dof: usize,
    /// p-value.
    pub p: f64,
    /// Threshold.
    pub alpha: f64,
}

/// A candidate tried at one step: effect, fit, unobservable columns, Wald statistic,
/// degrees of freedom, p-value, held-out misfit.
type Tried = (usize, Fit, Vec<usize>, f64, usize, f64, f64);

/// Wald statistic of the estimated columns of an effect, with its degrees of freedom.
pub(crate) fn wald(fit: &Fit, cols: &[usize]) -> (f64, usize) {
    let est: Vec<usize> = cols
        .iter()
        .copied()
        .filter(|g| fit.estimated.contains(g))
        .collect();
    let k = est.len();
    if k == 0 {
        return (0.0, 0);
    }
    let cov = DMatrix::from_fn(k, k, |i, j| fit.cov[(est[i], est[j])]);
    let th = nalgebra::DVector::from_fn(k, |i, _| fit.theta[est[i]]);
    // Pseudo-inverse: a direction the covariance cannot resolve adds nothing.
    let Ok(pinv) = cov.clone().pseudo_inverse(1e-12 * cov.norm()) else {
        return (0.0, 0);
    };
    ((th.transpose() * pinv * &th)[(0, 0)], k)
}

/// Upper-tail probability of a chi-square statistic.
pub(crate) fn p_value(chi2: f64, dof: usize) -> f64 {
    if dof == 0 {
        return 1.0;
    }
    ChiSquared::new(dof as f64).map_or(1.0, |d| d.sf(chi2))
}

/// The drop of the Bayesian information criterion an effect brings: its statistic less
/// `ln(n)` per parameter. Among significant candidates the one that explains most per
/// parameter wins, so a general term (nine g-sensitivities) does not take the place of
/// the physics it contains (the Earth's rate, two parameters).
fn score(chi2: f64, dof: usize, n: usize) -> f64 {
    chi2 - dof as f64 * (n.max(2) as f64).ln()
}

/// Held-out misfit in units of each channel's noise under `base`.
pub(crate) fn holdout_score(data: &Data, fit: &Fit, base: &Fit) -> f64 {
    let mut s = 0.0;
    for &i in &data.held {
        for c in 0..6 {
            let sig = base.noise[c].sigma;
            if sig > 0.0 {
                s += seg_rss(&data.accs[i], &data.layout, c, &fit.theta) / (sig * sig);
            }
        }
    }
    s
}

/// Runs the selection from `start` over the working segments. `alpha` is the family-wise
/// threshold of one step (Bonferroni over the candidates left); `without` are ids left out
/// of the candidates. Returns the steps and the
/// last p-value of every candidate not taken.
pub(crate) fn forward(
    data: &Data,
    start: &Terms,
    alpha: f64,
    without: &[String],
) -> (Vec<Step>, std::collections::BTreeMap<String, f64>) {
    let work = data.working();
    let lay = &data.layout;
    let mut terms = start.clone();
    let mut candidates: Vec<usize> = (0..lay.effects.len())
        .filter(|e| {
            !lay.effects[*e].nominal()
                && !without.iter().any(|w| w == lay.effects[*e].id())
                && !terms.effects.contains(e)
                && !terms.fixed.iter().any(|f| f.0 == *e)
        })
        .collect();
    let n: usize = work.iter().map(|&i| 6 * data.accs[i].n).sum();
    let mut steps = Vec::new();
    let mut last_p = std::collections::BTreeMap::new();
    loop {
        let (base, _) = fit(data, &terms, &work, &work);
        let base_hold = holdout_score(data, &base, &base);
        let a = alpha / candidates.len().max(1) as f64;
        let tried: Vec<Tried> = {
            use rayon::prelude::*;
            candidates
                .par_iter()
                .map(|&e| {
                    let mut t = terms.clone();
                    t.effects.push(e);
                    let (f, un) = fit(data, &t, &work, &work);
                    let cols: Vec<usize> = lay.columns_of(e).collect();
                    let (chi2, dof) = wald(&f, &cols);
                    let p = p_value(chi2, dof);
                    let hold = holdout_score(data, &f, &base);
                    (e, f, un, chi2, dof, p, hold)
                })
                .collect()
        };
        let mut best: Option<usize> = None;
        for (k, c) in tried.iter().enumerate() {
            last_p.insert(lay.effects[c.0].id().to_string(), c.5);
            let held_ok = data.held.is_empty() || c.6 < base_hold;
            if c.4 > 0 && c.5 < a && held_ok {
                let better =
                    best.is_none_or(|b| score(c.3, c.4, n) > score(tried[b].3, tried[b].4, n));
                if better {
                    best = Some(k);
                }
            }
        }
        let Some(mut b) = best else { break };
        // Occam: a significant candidate with fewer parameters that the winner contains
        // (fitted together, some of its columns are not separable from the winner's) is
        // the physics; the winner only mimics it with more freedom.
        let mut simpler: Vec<usize> = (0..tried.len())
            .filter(|&k| {
                let c = &tried[k];
                c.4 > 0 && c.4 < tried[b].4 && c.5 < a && (data.held.is_empty() || c.6 < base_hold)
            })
            .collect();
        simpler.sort_by_key(|&k| tried[k].4);
        for k in simpler {
            let mut t = terms.clone();
            t.effects.push(tried[b].0);
            t.effects.push(tried[k].0);
            let (_, un) = fit(data, &t, &work, &work);
            if lay
                .columns_of(tried[k].0)
                .any(|g| un.contains(&g) && !tried[k].2.contains(&g))
            {
                b = k;
                break;
            }
        }
        let (e, f, _, chi2, dof, p, _) = tried.into_iter().nth(b).expect("chosen");
        last_p.remove(lay.effects[e].id());
        terms.effects.push(e);
        candidates.retain(|x| *x != e);
        steps.push(Step {
            effect: e,
            before: base,
            after: f,
            chi2,
            dof,
            p,
            alpha: a,
        });
        if candidates.is_empty() {
            break;
        }
    }
    (steps, last_p)
}
