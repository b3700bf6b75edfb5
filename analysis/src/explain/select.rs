//! Forward selection over the registry's catalogue: at each step every remaining
//! candidate is added to the whole model, which is refitted; the most significant one
//! (Wald test with the honest covariance) is kept when it passes the threshold and lowers
//! the residual on the held-out segments. Selection stops when none does.
//!
//! Here too is the screen that ranks the probe library beside a model ([`screen`]): it
//! fits models, so it sits above the probes and the accumulation rather than with them.

use super::data::Data;
use super::model::{Terms, fit, fit_with, misfit};
use super::stats::{p_value, score, wald};
use crate::fit::joint::{Fit, WanderRule};
use ratecal_physics::effects::Sensor;

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
    /// Layout indices of candidates that explain the same as well (a tie).
    pub alternatives: Vec<usize>,
}

/// A candidate tried at one step: effect, fit, unobservable columns, Wald statistic,
/// degrees of freedom, p-value, held-out misfit.
type Tried = (usize, Fit, Vec<usize>, f64, usize, f64, f64);

/// Held-out misfit in units of each channel's noise under `base`.
pub(crate) fn holdout_score(data: &Data, fit: &Fit, base: &Fit) -> f64 {
    (0..6)
        .filter(|&c| base.noise[c].sigma > 0.0)
        .map(|c| misfit(data, fit, c, &data.held, base.noise[c].sigma))
        .sum()
}

/// Whether every estimated parameter of effect `e` in `fit` is inside its plausible range.
fn plausible(data: &Data, fit: &Fit, e: usize) -> Result<(), String> {
    let lay = &data.layout;
    for g in lay.columns_of(e) {
        if !fit.estimated.contains(&g) {
            continue;
        }
        let p = lay.param(g);
        let max = super::plausible::max_abs(p);
        if let Some(max) = max
            && fit.theta[g].abs() > max
        {
            return Err(format!(
                "{} = {:.4} {} is outside what a real part shows (|{}| <= {} {})",
                p.name, fit.theta[g], p.unit, p.name, max, p.unit
            ));
        }
    }
    Ok(())
}

/// Why a significant candidate was not adopted.
#[derive(Debug, Clone)]
pub(crate) struct Refused {
    /// Its id.
    pub effect: String,
    /// In words.
    pub reason: String,
}

/// The score and fit of one probe added to a model.
struct ProbeTry {
    probe: usize,
    chi2: f64,
    dof: usize,
    score: f64,
}

/// Probes most worth a full test beside `terms` over `segs`: each probe not in `terms`
/// fitted with a white-noise covariance (cheap), its Wald statistic per sensor, the `keep`
/// strongest of each sensor kept, strongest first.
pub(crate) fn screen(data: &Data, terms: &Terms, segs: &[usize], keep: usize) -> Vec<usize> {
    use rayon::prelude::*;
    let lay = &data.layout;
    let mut scored: Vec<(usize, Sensor, f64)> = data
        .probes
        .par_iter()
        .filter(|(e, _)| !terms.effects.contains(e) && !terms.skips_all(lay, *e))
        .map(|&(e, p)| {
            let mut t = terms.clone();
            t.effects.push(e);
            let (f, _) = fit_with(data, &t, segs, segs, WanderRule::WhiteOnly);
            let cols: Vec<usize> = lay.columns_of(e).collect();
            (e, p.sensor, wald(&f, &cols).0)
        })
        .collect();
    scored.sort_by(|a, b| b.2.total_cmp(&a.2));
    let mut out = Vec::new();
    for sensor in [Sensor::Accel, Sensor::Gyro] {
        out.extend(
            scored
                .iter()
                .filter(|s| s.1 == sensor)
                .take(keep)
                .map(|s| s.0),
        );
    }
    out
}

/// Every probe added alone to `terms`, most explaining first.
fn try_probes(data: &Data, terms: &Terms, work: &[usize], n: usize) -> Vec<ProbeTry> {
    use rayon::prelude::*;
    let lay = &data.layout;
    // A white-noise screen first: only the strongest probes get the honest covariance.
    let short = screen(data, terms, work, 4);
    let mut out: Vec<ProbeTry> = short
        .par_iter()
        .map(|&e| {
            let mut t = terms.clone();
            t.effects.push(e);
            let (f, _) = fit(data, &t, work, work);
            let cols: Vec<usize> = lay.columns_of(e).collect();
            let (chi2, dof) = wald(&f, &cols);
            ProbeTry {
                probe: e,
                chi2,
                dof,
                score: score(chi2, dof, n),
            }
        })
        .collect();
    out.sort_by(|a, b| b.score.total_cmp(&a.score));
    out
}

/// Whether candidate `e` only mimics what the probes explain better: beside them the
/// candidate is no longer significant, while beside the candidate one of them still is.
fn mimics(data: &Data, terms: &Terms, e: usize, probes: &[usize], a: f64, a_probe: f64) -> bool {
    let lay = &data.layout;
    let work = data.working();
    let mut t = terms.clone();
    t.effects.push(e);
    t.effects.extend_from_slice(probes);
    let (f, _) = fit(data, &t, &work, &work);
    let ce: Vec<usize> = lay.columns_of(e).collect();
    let (c1, d1) = wald(&f, &ce);
    // Jointly: rival probes are often near copies of one another (a square and an
    // absolute value on +-1 g attitudes), and each alone loses its significance to the
    // others.
    let cp: Vec<usize> = probes.iter().flat_map(|&p| lay.columns_of(p)).collect();
    let (c2, d2) = wald(&f, &cp);
    let probe_left = p_value(c2, d2) < a_probe;
    if std::env::var_os("RATECAL_EXPLAIN_DEBUG").is_some() {
        let ids: Vec<&str> = probes.iter().map(|&p| lay.effects[p].id()).collect();
        eprintln!(
            "mimic? {} beside {ids:?}: chi2 {c1:.1} dof {d1} p {:.2e} (a {a:.1e}); a probe left: {probe_left}",
            lay.effects[e].id(),
            p_value(c1, d1)
        );
    }
    p_value(c1, d1) >= a && probe_left
}

/// Why the winner `e` (fitted in `fit_e`) is not to be reported, if it is not: physics held
/// to physics (a fit outside the plausible range is not that effect), and a probe that
/// explains what the winner explains, and more, takes precedence (the strongest probes on
/// its sensors, tried together).
fn refusal(
    data: &Data,
    terms: &Terms,
    n: usize,
    e: usize,
    fit_e: &Fit,
    a: f64,
    alpha: f64,
) -> Option<String> {
    if let Err(why) = plausible(data, fit_e, e) {
        return Some(why);
    }
    // The Earth's rate is physics every recording holds, at a known value: probes do not
    // replace it (a rate that only mimics it is caught by its free scale, earth::Held).
    if e == data.earth {
        return None;
    }
    let lay = &data.layout;
    let work = data.working();
    let probes = try_probes(data, terms, &work, n);
    let a_probe = alpha / data.probes.len().max(1) as f64;
    let sensors = lay.effects[e].sensors();
    let rivals: Vec<usize> = probes
        .iter()
        .filter(|pt| {
            pt.dof > 0
                && p_value(pt.chi2, pt.dof) < a_probe
                && lay.effects[pt.probe]
                    .sensors()
                    .iter()
                    .any(|s| sensors.contains(s))
        })
        .take(3)
        .map(|pt| pt.probe)
        .collect();
    if rivals.is_empty() || !mimics(data, terms, e, &rivals, a, a_probe) {
        return None;
    }
    let strongest = rivals[0];
    let expr = data
        .probe(strongest)
        .map(|q| q.expression(0))
        .unwrap_or_default();
    Some(format!(
        "a form outside the registry ({expr}, on the {}) explains the same residual and more",
        lay.effects[strongest].sensors()[0].name()
    ))
}

/// The result of the selection.
pub(crate) struct Selection {
    /// Accepted steps, in order.
    pub steps: Vec<Step>,
    /// The last p-value of every candidate not taken.
    pub last_p: std::collections::BTreeMap<String, f64>,
    /// Significant candidates refused, and why.
    pub refused: Vec<Refused>,
}

/// Runs the selection from `start` over the working segments. `alpha` is the family-wise
/// threshold of one step (Bonferroni over the candidates left); `without` are ids left out
/// of the candidates.
///
/// A significant candidate is refused when its fit lands outside the physically plausible
/// range, or when a probe (a form outside the registry) explains what it explains and more
/// ([`mimics`]): the leftover is then for the tests of what remains unexplained, never
/// credited to the wrong physics. Candidates whose score ties the winner's are reported
/// with it as alternatives.
pub(crate) fn forward(data: &Data, start: &Terms, alpha: f64, without: &[String]) -> Selection {
    let work = data.working();
    let lay = &data.layout;
    let mut terms = start.clone();
    let mut candidates: Vec<usize> = data
        .candidates
        .iter()
        .copied()
        .filter(|e| {
            !without.iter().any(|w| w == lay.effects[*e].id())
                && !terms.effects.contains(e)
                && !terms.skips_all(lay, *e)
                && !terms
                    .fixed
                    .iter()
                    .any(|f| lay.effects[f.0].id() == lay.effects[*e].id())
        })
        .collect();
    let n: usize = work.iter().map(|&i| 6 * data.accs[i].n).sum();
    let mut steps = Vec::new();
    let mut last_p = std::collections::BTreeMap::new();
    let mut refused = Vec::new();
    let mut base_cache: Option<(Fit, f64)> = None;
    loop {
        let (base, base_hold) = match base_cache.take() {
            Some(b) => b,
            None => {
                let (base, _) = fit(data, &terms, &work, &work);
                let h = holdout_score(data, &base, &base);
                (base, h)
            }
        };
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
        let ok = |c: &Tried| c.4 > 0 && c.5 < a && (data.held.is_empty() || c.6 < base_hold);
        if std::env::var_os("RATECAL_EXPLAIN_DEBUG").is_some() {
            for c in &tried {
                eprintln!(
                    "step {}: {} chi2 {:.1} dof {} p {:.2e} hold {:.1} (base {:.1}) score {:.1}",
                    steps.len(),
                    lay.effects[c.0].id(),
                    c.3,
                    c.4,
                    c.5,
                    c.6,
                    base_hold,
                    score(c.3, c.4, n)
                );
            }
        }
        let mut best: Option<usize> = None;
        for (k, c) in tried.iter().enumerate() {
            last_p.insert(lay.effects[c.0].id().to_string(), c.5);
            if ok(c) {
                let better =
                    best.is_none_or(|b| score(c.3, c.4, n) > score(tried[b].3, tried[b].4, n));
                if better {
                    best = Some(k);
                }
            }
        }
        let Some(mut b) = best else { break };
        // The Earth's rate is physics every recording holds, held at its known value: when
        // it is significant it goes first, so that nothing else takes its credit.
        if let Some(k) = tried.iter().position(|c| c.0 == data.earth && ok(c)) {
            b = k;
        }
        // Occam: a significant candidate with fewer parameters that the winner contains
        // (fitted together, some of its columns are not separable from the winner's) is
        // the physics; the winner only mimics it with more freedom.
        let mut simpler: Vec<usize> = (0..tried.len())
            .filter(|&k| tried[k].4 < tried[b].4 && ok(&tried[k]))
            .collect();
        simpler.sort_by_key(|&k| tried[k].4);
        for k in simpler {
            let mut t = terms.clone();
            t.effects.push(tried[b].0);
            t.effects.push(tried[k].0);
            let (f, un) = fit(data, &t, &work, &work);
            let lost = lay
                .columns_of(tried[k].0)
                .any(|g| un.contains(&g) && !tried[k].2.contains(&g));
            // Or nested in effect: beside the simpler one, the winner adds nothing.
            let cols: Vec<usize> = lay.columns_of(tried[b].0).collect();
            let (chi2, dof) = wald(&f, &cols);
            if lost || p_value(chi2, dof) >= a {
                b = k;
                break;
            }
        }
        let e = tried[b].0;
        let id = lay.effects[e].id().to_string();
        if let Some(reason) = refusal(data, &terms, n, e, &tried[b].1, a, alpha) {
            refused.push(Refused { effect: id, reason });
            candidates.retain(|x| *x != e);
            base_cache = Some((base, base_hold));
            if candidates.is_empty() {
                break;
            }
            continue;
        }
        // Candidates the criterion cannot tell from the winner are one finding with it:
        // scores within a tie, and neither significant beside the other.
        let sb = score(tried[b].3, tried[b].4, n);
        let alternatives: Vec<usize> = tried
            .iter()
            .enumerate()
            .filter(|&(k, c)| k != b && ok(c) && (score(c.3, c.4, n) - sb).abs() <= TIE)
            .map(|(_, c)| c.0)
            .filter(|&c| {
                let mut t = terms.clone();
                t.effects.push(e);
                t.effects.push(c);
                let (f, _) = fit(data, &t, &work, &work);
                let insignificant = |x: usize| {
                    let cols: Vec<usize> = lay.columns_of(x).collect();
                    let (chi2, dof) = wald(&f, &cols);
                    p_value(chi2, dof) >= a
                };
                insignificant(c) && insignificant(e)
            })
            .collect();
        let (e, f, _, chi2, dof, p, _) = tried.into_iter().nth(b).expect("chosen");
        last_p.remove(lay.effects[e].id());
        for c in &alternatives {
            last_p.remove(lay.effects[*c].id());
        }
        terms.effects.push(e);
        candidates.retain(|x| *x != e && !alternatives.contains(x));
        steps.push(Step {
            effect: e,
            before: base,
            after: f,
            chi2,
            dof,
            p,
            alpha: a,
            alternatives,
        });
        if candidates.is_empty() {
            break;
        }
    }
    Selection {
        steps,
        last_p,
        refused,
    }
}

/// Scores closer than this (a difference of the information criterion) are a tie: the
/// data do not prefer one effect over the other.
const TIE: f64 = 2.0;
