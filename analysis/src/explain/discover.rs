//! Discovery: when the registry's selection stops and a leftover is significant, forward
//! selection over the probe library (docs/explain.md, "discovered") names its form.
//!
//! Each round screens every probe beside the model with a white-noise fit, gives the
//! strongest of each sensor the honest covariance, and tests each of a probe's channel
//! columns alone. The threshold is Bonferroni over every live column of the whole library
//! (not per term), so the false discoveries are controlled over everything searched. Of a
//! probe only its significant channels are kept; the probe must lower the misfit of the
//! held-out segments, which no fit saw. The winner (the highest information-criterion
//! score) joins the model, which is refitted jointly with everything found before.

use super::data::Data;
use super::model::{Terms, fit};
use super::probe::{Form, Probe};
use super::select::{Step, holdout_score, p_value, score, wald};
use crate::fit::joint::{Fit, channel};
use ratecal_physics::effects::Sensor;

/// Most terms discovered in one recording.
const MOST: usize = 6;
/// Probes per sensor given the honest test after the white-noise screen.
const SHORTLIST: usize = 6;

/// One discovered term: a probe restricted to the channels where it is significant.
pub(crate) struct Discovery {
    /// The accepted step (its effect the probe's layout index).
    pub step: Step,
    /// The probe.
    pub probe: &'static Probe,
    /// Global columns kept (one per channel).
    pub columns: Vec<usize>,
    /// For a decay: the time constant refined between the grid's neighbours, with its
    /// standard uncertainty, and the amplitude of each kept column there (value, u).
    pub tau: Option<Refined>,
}

/// A decay's time constant between the grid points.
pub(crate) struct Refined {
    /// Time constant, s.
    pub tau_s: f64,
    /// Its standard uncertainty, s.
    pub u_s: f64,
    /// Per kept column: the amplitude at `tau_s` and its u, interpolated in `ln tau`.
    pub amplitudes: Vec<(f64, f64)>,
}

/// Columns of the library that some segment excites: the number of tests the threshold
/// corrects for.
pub(crate) fn live_columns(data: &Data) -> usize {
    let lay = &data.layout;
    data.probes
        .iter()
        .flat_map(|&(e, _)| lay.columns_of(e))
        .filter(|&g| data.excitation.iter().any(|x| x[g] > 0.0))
        .count()
        .max(1)
}

/// A probe tried beside the model.
struct Try {
    e: usize,
    keep: Vec<usize>,
    drop: Vec<usize>,
    fit: Fit,
    chi2: f64,
    hold: f64,
}

/// The significant columns of probe `e` beside `terms`, the refit with only those, and
/// its held-out misfit; `None` when no column passes `a` (the per-test threshold).
fn try_probe(data: &Data, terms: &Terms, e: usize, a: f64, base: &Fit) -> Option<Try> {
    let work = data.working();
    let mut t = terms.clone();
    t.effects.push(e);
    let (f, _) = fit(data, &t, &work, &work);
    let (keep, drop): (Vec<usize>, Vec<usize>) = data
        .layout
        .columns_of(e)
        .partition(|&g| f.estimated.contains(&g) && p_value(wald(&f, &[g]).0, 1) < a);
    if keep.is_empty() {
        return None;
    }
    t.skip.extend(drop.iter().copied());
    let (f, _) = fit(data, &t, &work, &work);
    let (chi2, _) = wald(&f, &keep);
    let hold = holdout_score(data, &f, base);
    Some(Try {
        e,
        keep,
        drop,
        fit: f,
        chi2,
        hold,
    })
}

/// Forward selection over the probe library from `terms` (the registry's final model),
/// which grows by what is found; `alpha` is the family-wise threshold over the library.
pub(crate) fn discover(data: &Data, terms: &mut Terms, alpha: f64) -> Vec<Discovery> {
    use rayon::prelude::*;
    let work = data.working();
    let n: usize = work.iter().map(|&i| 6 * data.accs[i].n).sum();
    let m = live_columns(data) as f64;
    let a = alpha / m;
    let mut out: Vec<Discovery> = Vec::new();
    while out.len() < MOST {
        let (base, _) = fit(data, terms, &work, &work);
        let base_hold = holdout_score(data, &base, &base);
        let short = super::probe::screen(data, terms, &work, SHORTLIST);
        let tries: Vec<Try> = short
            .par_iter()
            .filter_map(|&e| try_probe(data, terms, e, a, &base))
            .filter(|t| data.held.is_empty() || t.hold < base_hold)
            .collect();
        let Some(best) = tries.into_iter().max_by(|x, y| {
            score(x.chi2, x.keep.len(), n).total_cmp(&score(y.chi2, y.keep.len(), n))
        }) else {
            break;
        };
        let probe = data.probe(best.e).expect("a probe");
        terms.effects.push(best.e);
        terms.skip.extend(best.drop.iter().copied());
        let tau = match probe.form {
            Form::Decay { .. } => refine_tau(data, terms, &best, probe),
            _ => None,
        };
        let dof = best.keep.len();
        out.push(Discovery {
            step: Step {
                effect: best.e,
                before: base,
                after: best.fit,
                chi2: best.chi2,
                dof,
                // Corrected for every column of the library.
                p: (p_value(best.chi2, dof) * m).min(1.0),
                alpha,
                alternatives: Vec::new(),
            },
            probe,
            columns: best.keep,
            tau,
        });
    }
    out
}

/// A decay found at a grid time constant: the same channels tried with each of the
/// sensor's decays in place of it; the Wald statistic's parabola in `ln tau` through the
/// best and its neighbours gives the time constant (its vertex) and its uncertainty (where
/// the statistic has dropped by one).
fn refine_tau(data: &Data, terms: &Terms, best: &Try, probe: &Probe) -> Option<Refined> {
    let work = data.working();
    let lay = &data.layout;
    let mut grid: Vec<(f64, usize)> = data
        .probes
        .iter()
        .filter(|(_, p)| p.sensor == probe.sensor)
        .filter_map(|&(e, p)| match p.form {
            Form::Decay { tau, .. } => Some((tau, e)),
            _ => None,
        })
        .collect();
    grid.sort_by(|a, b| a.0.total_cmp(&b.0));
    let k = grid.iter().position(|g| g.1 == best.e)?;
    if k == 0 || k + 1 >= grid.len() {
        return None;
    }
    let axes: Vec<usize> = best.keep.iter().map(|&g| local_axis(data, g)).collect();
    // Statistic and amplitudes with decay `e` in place of the best one.
    let with = |e: usize| -> (f64, Vec<(f64, f64)>) {
        let mut t = terms.clone();
        t.effects.retain(|&x| x != best.e);
        t.skip.retain(|g| !lay.columns_of(best.e).contains(g));
        t.effects.push(e);
        let keep: Vec<usize> = lay
            .columns_of(e)
            .filter(|&g| axes.contains(&local_axis(data, g)))
            .collect();
        t.skip
            .extend(lay.columns_of(e).filter(|g| !keep.contains(g)));
        let (f, _) = fit(data, &t, &work, &work);
        let amps = keep.iter().map(|&g| (f.theta[g], f.u(g))).collect();
        (wald(&f, &keep).0, amps)
    };
    let pts: Vec<(f64, f64, Vec<(f64, f64)>)> = [grid[k - 1], grid[k], grid[k + 1]]
        .iter()
        .map(|&(tau, e)| {
            let (c, a) = with(e);
            (tau.ln(), c, a)
        })
        .collect();
    // Parabola through three points: c(x) = p2 x^2 + p1 x + p0.
    let (x0, x1, x2) = (pts[0].0, pts[1].0, pts[2].0);
    let (y0, y1, y2) = (pts[0].1, pts[1].1, pts[2].1);
    let d = (x0 - x1) * (x0 - x2) * (x1 - x2);
    let p2 = (x2 * (y1 - y0) + x1 * (y0 - y2) + x0 * (y2 - y1)) / d;
    let p1 = (x2 * x2 * (y0 - y1) + x1 * x1 * (y2 - y0) + x0 * x0 * (y1 - y2)) / d;
    if p2 >= 0.0 {
        return None;
    }
    let xv = (-p1 / (2.0 * p2)).clamp(x0, x2);
    let sx = (-1.0 / p2).sqrt();
    // Amplitudes interpolated linearly in ln tau between the two grid points around xv.
    let (lo, hi) = if xv <= x1 { (0, 1) } else { (1, 2) };
    let w = (xv - pts[lo].0) / (pts[hi].0 - pts[lo].0);
    let amplitudes = (0..axes.len())
        .map(|j| {
            let (a0, u0) = pts[lo].2[j];
            let (a1, u1) = pts[hi].2[j];
            (a0 + w * (a1 - a0), u0 + w * (u1 - u0))
        })
        .collect();
    let tau_s = xv.exp();
    Some(Refined {
        tau_s,
        u_s: tau_s * sx,
        amplitudes,
    })
}

/// The axis (0..3) of a probe column's channel.
pub(crate) fn local_axis(data: &Data, g: usize) -> usize {
    data.layout.param(g).channel.map_or(0, |(_, ax)| ax)
}

/// The output channel index (0..6) of a probe column.
pub(crate) fn channel_of(data: &Data, g: usize) -> usize {
    match data.layout.param(g).channel {
        Some((Sensor::Accel, ax)) => ax,
        Some((Sensor::Gyro, ax)) => 3 + ax,
        None => 0,
    }
}

/// The discovered effect's id: `discovered_` and, per kept channel, its name and the
/// form there (`discovered_ax_fx_fz`); channels with the same form share it.
pub(crate) fn name(data: &Data, d: &Discovery) -> String {
    let parts: Vec<(String, String)> = d
        .columns
        .iter()
        .map(|&g| {
            let c = channel_of(data, g);
            let (_, ax) = channel(c);
            (
                crate::fit::joint::CHANNELS[c].to_string(),
                d.probe.form.slug(d.probe.sensor, ax),
            )
        })
        .collect();
    let same = parts.windows(2).all(|w| w[0].1 == w[1].1);
    let mut id = String::from("discovered");
    if same {
        for (c, _) in &parts {
            id.push('_');
            id.push_str(c);
        }
        id.push('_');
        id.push_str(&parts[0].1);
    } else {
        for (c, s) in &parts {
            id.push('_');
            id.push_str(c);
            id.push('_');
            id.push_str(s);
        }
    }
    id.replace(['.', '-'], "_")
}
