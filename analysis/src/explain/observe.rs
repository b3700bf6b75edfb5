//! Observability before fitting (docs/explain.md, "not_observable"): before any candidate
//! (registry effect, user effect, library form) is fitted, explain checks that this
//! recording determines it. A column the recording cannot determine is left out of every
//! fit (a skipped column of the model's terms) and listed with the motion that would
//! determine it.
//!
//! A column is not observable when
//! - it is a table-side term and the recording has no table feedback (an import with
//!   `table: none`): there is no encoder to err;
//! - no segment used excites it, or its column lies in the span of the nominal model's
//!   (the solver's rank test, columns scaled to unit norm);
//! - beside the nominal model the recording determines it only to a standard uncertainty
//!   `u` with `3 u` beyond its plausible range: even the largest value a real part shows
//!   would not stand out of the noise. This is what catches a column the motion never
//!   excites but round-off does (`f_y f_z` on six faces, about 1e-16 g^2): scaled to unit
//!   norm it looks independent, yet its `u` is astronomically wide.

use super::data::Data;
use super::model::{Terms, fit_with};
use super::output::NotObservable;
use super::plausible::max_abs;
use super::probe::Form;
use crate::fit::joint::{CHANNELS, WanderRule};
use rayon::prelude::*;

/// What the recording cannot determine: columns to leave out and the entries to report.
pub(crate) struct Observability {
    /// Global columns of candidates left out of every fit.
    pub skip: Vec<usize>,
    /// One entry per candidate (or per column, where only some of its columns fail).
    pub entries: Vec<NotObservable>,
}

/// Why one column is not observable.
#[derive(Clone, PartialEq)]
enum Why {
    NoTable,
    NotExcited,
    Dependent,
    Unresolved { u: f64, max: f64 },
}

/// Every candidate of `data` checked beside `start` (the nominal model) over the working
/// segments.
pub(crate) fn observe(data: &Data, start: &Terms) -> Observability {
    let mut cands: Vec<usize> = data.candidates.clone();
    // Steps are columns of the bias or scale copied after an instant between segments:
    // excited by construction, and many; the solver's rank test drops one a fit cannot
    // separate.
    cands.extend(
        data.probes
            .iter()
            .filter(|p| !matches!(p.1.form, Form::Step { .. } | Form::ScaleStep { .. }))
            .map(|p| p.0),
    );
    cands.retain(|e| !start.effects.contains(e) && !start.fixed.iter().any(|f| f.0 == *e));
    let per: Vec<(usize, Vec<(usize, Why)>)> = cands
        .par_iter()
        .map(|&e| (e, check(data, start, e)))
        .collect();
    let mut out = Observability {
        skip: Vec::new(),
        entries: Vec::new(),
    };
    for (e, cols) in per {
        if cols.is_empty() {
            continue;
        }
        out.skip.extend(cols.iter().map(|c| c.0));
        out.entries.extend(entries(data, e, &cols));
    }
    out
}

/// On faces placed by hand (`attitude: nominal`) a placement tilt is never physics: each
/// face's tilt is a nuisance within its tolerance, and on six faces an accelerometer
/// misalignment cannot be told apart from it. The misalignment joins the starting model
/// (so that what the two leave in the residuals is credited to neither, nor called
/// unexplained) and is listed as not observable, with what would tell them apart.
///
/// Unless the faces are known better than the misalignment: when the misalignment, its
/// variance holding the tilts', passes the selection's threshold (`alpha` over the
/// candidates) beside the starting model, it stays a candidate like any other (faces
/// declared within a thousandth of a degree, say).
pub(crate) fn tilt_in_start(data: &Data, start: &mut Terms, alpha: f64) -> Vec<NotObservable> {
    if data.tilt_rad <= 0.0 {
        return Vec::new();
    }
    // Each face's tilt is an offset of its own on the accelerometers (up to g times the
    // tolerance): a bias that drifts, decays or steps between faces cannot be told from it.
    let mut out = Vec::new();
    let in_time: Vec<usize> = data
        .probes
        .iter()
        .filter(|(_, p)| p.sensor == ratecal_physics::effects::Sensor::Accel && p.form.in_time())
        .map(|p| p.0)
        .collect();
    if !in_time.is_empty() {
        for &e in &in_time {
            start.skip.extend(data.layout.columns_of(e));
        }
        out.push(NotObservable {
            candidate: "form_accel_in_time".into(),
            reason: format!(
                "on faces placed by hand within {:.2} deg each face's tilt offsets the \
                 accelerometers by up to g times that: a bias that drifts, decays or steps \
                 between faces cannot be told apart from it",
                data.tilt_rad.to_degrees()
            ),
            observed_by: "a rate table's angle feedback, or repeated faces".into(),
        });
    }
    let Some(e) = data.layout.index("accel_misalignment") else {
        return out;
    };
    if beyond_the_tilts(data, start, e, alpha) {
        return out;
    }
    if !start.effects.contains(&e) {
        start.effects.push(e);
    }
    out.push(NotObservable {
        candidate: "accel_misalignment".into(),
        reason: format!(
            "on faces placed by hand within {:.2} deg (attitude: nominal) a misalignment cannot \
             be told apart from the faces' tilts: `ratecal analyze` states it as exact faces \
             give it, with the tilts in its u",
            data.tilt_rad.to_degrees()
        ),
        observed_by: "a rate table's angle feedback, or poses whose attitude is known better \
                      than the misalignment"
            .into(),
    });
    out
}

/// Whether misalignment `e` beside `start` passes the selection's threshold with the
/// faces' tilts in its variance: the faces are then known better than it is large.
fn beyond_the_tilts(data: &Data, start: &Terms, e: usize, alpha: f64) -> bool {
    let mut t = start.clone();
    if !t.effects.contains(&e) {
        t.effects.push(e);
    }
    let work = data.working();
    let (f, _) = super::model::fit(data, &t, &work, &work);
    let cols: Vec<usize> = data.layout.columns_of(e).collect();
    let (chi2, dof) = super::stats::wald(&f, &cols);
    let m = data.candidates.len().max(1) as f64;
    dof > 0 && super::stats::p_value(chi2, dof) < alpha / m
}

/// The columns of candidate `e` that the recording cannot determine, with why.
fn check(data: &Data, start: &Terms, e: usize) -> Vec<(usize, Why)> {
    let lay = &data.layout;
    let cols: Vec<usize> = lay
        .columns_of(e)
        .filter(|g| !start.skip.contains(g))
        .collect();
    if lay.effects[e].station_side() && !data.table_feedback {
        return cols.into_iter().map(|g| (g, Why::NoTable)).collect();
    }
    let work = data.working();
    let mut t = start.clone();
    t.effects.push(e);
    let (f, _) = fit_with(data, &t, &work, &work, WanderRule::WhiteOnly);
    cols.into_iter()
        .filter_map(|g| {
            if !f.estimated.contains(&g) {
                let excited = work.iter().any(|&i| data.excitation[i][g] > 0.0);
                return Some((
                    g,
                    if excited {
                        Why::Dependent
                    } else {
                        Why::NotExcited
                    },
                ));
            }
            let max = max_abs(lay.param(g))?;
            let u = f.u(g);
            // A NaN u is not determined either.
            let determined = 3.0 * u <= max;
            (!determined).then_some((g, Why::Unresolved { u, max }))
        })
        .collect()
}

/// The entries of candidate `e`: one for the whole candidate when every column fails for
/// one kind of reason, else one per column.
fn entries(data: &Data, e: usize, cols: &[(usize, Why)]) -> Vec<NotObservable> {
    let lay = &data.layout;
    let all = lay.columns_of(e).count() == cols.len();
    let kind = |w: &Why| std::mem::discriminant(w);
    let one_kind = cols.iter().all(|c| kind(&c.1) == kind(&cols[0].1));
    let name = candidate_name(data, e);
    if all && one_kind {
        let p = lay.param(cols[0].0);
        return vec![NotObservable {
            candidate: name,
            reason: reason(&cols[0].1, p.unit, cols.len() > 1),
            observed_by: observed_by(data, e, cols[0].0),
        }];
    }
    cols.iter()
        .map(|(g, why)| {
            let p = lay.param(*g);
            NotObservable {
                candidate: format!("{name}.{}", column_name(data, e, *g)),
                reason: reason(why, p.unit, false),
                observed_by: observed_by(data, e, *g),
            }
        })
        .collect()
}

/// A candidate's name: the registry or user effect's id, or for a library form
/// `form_<sensor>_<form>` (`form_accel_fy_fz`).
pub(crate) fn candidate_name(data: &Data, e: usize) -> String {
    match data.probe(e) {
        Some(p) => format!("form_{}_{}", p.sensor.name(), p.form.family()).replace(['.', '-'], "_"),
        None => data.layout.effects[e].id().to_string(),
    }
}

/// A column's name within its candidate: the parameter's, or for a form its channel.
fn column_name(data: &Data, e: usize, g: usize) -> String {
    let p = data.layout.param(g);
    match (data.probe(e), p.channel) {
        (Some(_), Some((s, ax))) => {
            let c = if s == ratecal_physics::effects::Sensor::Accel {
                ax
            } else {
                3 + ax
            };
            CHANNELS[c].to_string()
        }
        _ => p.name.to_string(),
    }
}

/// The motion that would determine column `g` of `e`.
fn observed_by(data: &Data, e: usize, g: usize) -> String {
    let fx = data.layout.effects[e];
    if fx.station_side() && !data.table_feedback {
        return "a rate table's angle feedback (this recording's table stream is synthesized)"
            .into();
    }
    let needs = data.layout.param(g).needs;
    if needs.is_empty() {
        "motion that excites its regressor".into()
    } else {
        needs.to_string()
    }
}

/// The reason in words.
fn reason(why: &Why, unit: &str, plural: bool) -> String {
    let (it, them, is) = if plural {
        ("they", "them", "are")
    } else {
        ("it", "it", "is")
    };
    match why {
        Why::NoTable => {
            format!("a table-side error, and the recording has no table feedback: {it} cannot show")
        }
        Why::NotExcited => format!("no segment of the recording excites {them}"),
        Why::Dependent => format!(
            "on this recording's segments {it} {is} not separable from the nominal model's terms"
        ),
        Why::Unresolved { u, max } => format!(
            "beside the nominal model the recording determines {it} only to u = {u:.3e} {unit}: \
             3u is beyond the plausible range |value| <= {max:.4e} {unit}"
        ),
    }
}
