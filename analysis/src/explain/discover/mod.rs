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

mod tau;

use super::data::Data;
use super::model::{Terms, fit, misfit};
use super::probe::{Form, Probe};
use super::select::{Refused, Step};
use super::stats::{p_value, wald};
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
    /// For a decay: the time constant from the profile of the misfit, with its standard
    /// uncertainty, and the amplitude of each kept column there (value, u).
    pub tau: Option<Refined>,
}

/// A decay's time constant from the profile of the misfit ([`tau::refine`]).
pub(crate) struct Refined {
    /// Time constant, s.
    pub tau_s: f64,
    /// Its standard uncertainty, s.
    pub u_s: f64,
    /// Per kept column: the amplitude at `tau_s` and its u (the time constant's included).
    pub amplitudes: Vec<(f64, f64)>,
}

/// Columns of the library that some segment excites and the recording determines (not
/// skipped in `terms`): the number of tests the threshold corrects for.
pub(crate) fn live_columns(data: &Data, terms: &Terms) -> usize {
    let lay = &data.layout;
    data.probes
        .iter()
        .flat_map(|&(e, _)| lay.columns_of(e))
        .filter(|g| !terms.skip.contains(g))
        .filter(|&g| data.excitation.iter().any(|x| x[g] > 0.0))
        .count()
        .max(1)
}

/// A round's winner: probe, kept and dropped columns, the fit with it, its Wald statistic.
type Accepted = (usize, Vec<usize>, Vec<usize>, Fit, f64);

/// A probe tried beside the model: each channel column's Wald statistic (is it there?)
/// and the misfit it removes (how well does it explain?).
struct Try {
    e: usize,
    /// (column, Wald chi2, drop of the channel's misfit in units of its white noise) of
    /// every estimated column.
    cols: Vec<(usize, f64, f64)>,
}

/// Misfit of the held-out segments on `channels` under `f`, in units of `base`'s noise.
fn held_misfit(data: &Data, f: &Fit, base: &Fit, channels: &[usize]) -> f64 {
    channels
        .iter()
        .map(|&c| misfit(data, f, c, &data.held, base.noise[c].sigma))
        .sum()
}

/// Probe `e` added to `terms` with all its channel columns (the channels' fits are
/// separate, so each column's statistic is the one it has alone).
fn try_probe(data: &Data, terms: &Terms, e: usize, base: &Fit) -> Try {
    let work = data.working();
    let mut t = terms.clone();
    t.effects.push(e);
    let (f, _) = fit(data, &t, &work, &work);
    let cols = data
        .layout
        .columns_of(e)
        .filter(|g| f.estimated.contains(g))
        .map(|g| {
            let c = channel_of(data, g);
            let sigma = base.noise[c].sigma;
            let drop = misfit(data, base, c, &work, sigma) - misfit(data, &f, c, &work, sigma);
            (g, wald(&f, &[g]).0, drop)
        })
        .collect();
    Try { e, cols }
}

/// Why the kept columns' fit is not physics: the first outside its plausible range.
fn implausible(data: &Data, e: usize, f: &Fit, keep: &[usize]) -> Option<String> {
    keep.iter().find_map(|&g| {
        let p = data.layout.param(g);
        let max = super::plausible::max_abs(p)?;
        let v = f.theta[g];
        (v.abs() > max).then(|| {
            format!(
                "{} = {v:.4e} {} on {} is outside what a real part shows (|value| <= {max:.4e} {})",
                data.probe(e)
                    .map(|q| q.expression(local_axis(data, g)))
                    .unwrap_or_default(),
                p.unit,
                crate::fit::joint::CHANNELS[channel_of(data, g)],
                p.unit
            )
        })
    })
}

/// Whether probe `e` is a form of the specific force alone whose kept columns the static
/// segments do not excite (below a thousandth of the most a segment does): excited only
/// while the table turns, it cannot be told from an error of the table's motion (a wobble
/// of a bearing, docs/validation.md), so it is left to `unexplained`, a lead, never an
/// IMU finding.
fn turning_only(data: &Data, e: usize, keep: &[usize]) -> bool {
    let Some(p) = data.probe(e) else { return false };
    if !p.form.of_force_alone() {
        return false;
    }
    keep.iter().any(|&g| {
        let most = |rest: bool| {
            (0..data.accs.len())
                .filter(|&i| data.at_rest[i] == rest)
                .map(|i| data.excitation[i][g])
                .fold(0.0, f64::max)
        };
        most(true) <= 1e-3 * most(false).max(most(true))
    })
}

/// A channel cannot tell two forms apart when the misfits they leave differ by less than
/// this (in units of the white noise): it then takes the form the strongest channel chose.
const TIE: f64 = 10.0;

/// Forward selection over the probe library from `terms` (the registry's final model),
/// which grows by what is found; `alpha` is the family-wise threshold over the library.
///
/// Each round takes the (probe, channel) pair that removes most misfit among the
/// significant ones; the same form joins
/// it on every other channel where it is significant and removes as much as that channel's best
/// form (within [`TIE`]), so a form the data cannot tell from another on some channel is
/// not split across two readings.
pub(crate) fn discover(
    data: &Data,
    terms: &mut Terms,
    alpha: f64,
    refused: &mut Vec<Refused>,
    out: &mut Vec<Discovery>,
) {
    use rayon::prelude::*;
    let work = data.working();
    let n: usize = work.iter().map(|&i| 6 * data.accs[i].n).sum();
    let m = live_columns(data, terms) as f64;
    let a = alpha / m;
    let debug = std::env::var_os("RATECAL_EXPLAIN_DEBUG").is_some();
    let first = out.len();
    while out.len() - first < MOST {
        let (base, _) = fit(data, terms, &work, &work);
        let short = super::select::screen(data, terms, &work, SHORTLIST);
        let tries: Vec<Try> = short
            .par_iter()
            .map(|&e| try_probe(data, terms, e, &base))
            .collect();
        let sig = |chi2: f64| p_value(chi2, 1) < a;
        let sig_dof = |chi2: f64, dof: usize| p_value(chi2, dof) < a;
        // Each channel's largest misfit drop by a significant column.
        let mut best_of = [0.0f64; 6];
        for t in &tries {
            for &(g, chi2, drop) in &t.cols {
                let c = channel_of(data, g);
                if sig(chi2) {
                    best_of[c] = best_of[c].max(drop);
                }
            }
        }
        // Candidates in order of the largest drop of a significant column.
        let mut order: Vec<(usize, f64)> = tries
            .iter()
            .enumerate()
            .filter_map(|(k, t)| {
                t.cols
                    .iter()
                    .filter(|c| sig(c.1))
                    .map(|c| c.2)
                    .fold(None, |m: Option<f64>, d| Some(m.map_or(d, |m| m.max(d))))
                    .map(|d| (k, d))
            })
            .collect();
        order.sort_by(|x, y| y.1.total_cmp(&x.1));
        // The first candidate that the held-out segments confirm; among candidates the
        // fitted segments cannot tell apart (a drop within TIE of it: two instants of a
        // step with only a held-out segment between them), the held-out ones choose.
        let mut accepted: Option<(f64, Accepted)> = None;
        let mut lead: Option<f64> = None;
        for (k, top) in order {
            if let Some(l) = lead
                && top < l - TIE
            {
                break;
            }
            let t = &tries[k];
            let (keep, drop): (Vec<usize>, Vec<usize>) =
                data.layout.columns_of(t.e).partition(|&g| {
                    t.cols.iter().any(|&(h, chi2, drop)| {
                        h == g && sig(chi2) && drop >= best_of[channel_of(data, g)] - TIE
                    })
                });
            if keep.is_empty() {
                continue;
            }
            if turning_only(data, t.e, &keep) {
                let effect = super::observe::candidate_name(data, t.e);
                if !refused.iter().any(|r| r.effect == effect) {
                    refused.push(Refused {
                        effect,
                        reason: "a form of the specific force alone that only the turns excite: \
                                 it cannot be told from an error of the table's motion (static \
                                 attitudes with two axes off vertical would determine it)"
                            .into(),
                    });
                }
                continue;
            }
            let mut tt = terms.clone();
            tt.effects.push(t.e);
            tt.skip.extend(drop.iter().copied());
            let (f, _) = fit(data, &tt, &work, &work);
            let chans: Vec<usize> = keep.iter().map(|&g| channel_of(data, g)).collect();
            let hold = held_misfit(data, &f, &base, &chans);
            let base_hold = held_misfit(data, &base, &base, &chans);
            if debug {
                let p = data.probe(t.e).map(|p| p.expression(0)).unwrap_or_default();
                eprintln!(
                    "discover {}: {p} on {keep:?}: chi2 {:?} hold {hold:.1} (base {base_hold:.1})",
                    out.len(),
                    t.cols
                );
            }
            if !data.held.is_empty() && hold >= base_hold {
                continue;
            }
            if let Some(prev) = refined_beside(data, out, &chans) {
                let gain = tau::beyond(data, &base, &f, prev);
                if debug {
                    eprintln!(
                        "  beyond the refined decay {}: chi2 {gain:.1}",
                        prev.step.effect
                    );
                }
                let shared = (keep.iter())
                    .filter(|&&g| {
                        prev.columns
                            .iter()
                            .any(|&h| channel_of(data, h) == channel_of(data, g))
                    })
                    .count();
                if !sig_dof(gain, shared) {
                    continue;
                }
            }
            if let Some(why) = implausible(data, t.e, &f, &keep) {
                if !refused.iter().any(|r: &Refused| r.reason == why) {
                    refused.push(Refused {
                        effect: "discovered".into(),
                        reason: why,
                    });
                }
                continue;
            }
            lead = lead.or(Some(top));
            let gain = hold - base_hold;
            if accepted.as_ref().is_none_or(|a| gain < a.0) {
                let (chi2, _) = wald(&f, &keep);
                accepted = Some((gain, (t.e, keep, drop, f, chi2)));
            }
        }
        let accepted = accepted.map(|a| a.1);
        let Some((e, keep, drop, after, chi2)) = accepted else {
            break;
        };
        let _ = n;
        let probe = data.probe(e).expect("a probe");
        terms.effects.push(e);
        terms.skip.extend(drop.iter().copied());
        let tau = match probe.form {
            Form::Decay { .. } => tau::refine(data, terms, e, &keep, probe),
            _ => None,
        };
        let dof = keep.len();
        out.push(Discovery {
            step: Step {
                effect: e,
                before: base,
                after,
                chi2,
                dof,
                // Corrected for every column of the library.
                p: (p_value(chi2, dof) * m).min(1.0),
                alpha,
                alternatives: Vec::new(),
            },
            probe,
            columns: keep,
            tau,
        });
    }
}

/// Each discovered decay's time constant profiled again in the final model `terms`: a
/// decay found before the registry's second selection (the Earth's rate hidden behind a
/// strong warm-up, say) was refined without what joined the model after it.
pub(crate) fn refine_again(data: &Data, terms: &Terms, found: &mut [Discovery]) {
    for d in found.iter_mut().filter(|d| d.tau.is_some()) {
        d.tau = tau::refine(data, terms, d.step.effect, &d.columns, d.probe);
    }
}

/// The latest decay found earlier with a time constant of its own on any of `channels`.
fn refined_beside<'d>(
    data: &Data,
    out: &'d [Discovery],
    channels: &[usize],
) -> Option<&'d Discovery> {
    out.iter().rev().find(|d| {
        d.tau.is_some()
            && d.columns
                .iter()
                .any(|&g| channels.contains(&channel_of(data, g)))
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
