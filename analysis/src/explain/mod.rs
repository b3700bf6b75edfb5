//! Explain: where a recording and the nominal model disagree, which physics of the effect
//! registry was left out, the refit with it, and the evidence (docs/explain.md).
//!
//! The recording is accumulated once ([`data`]); the nominal model is fitted as the
//! standard would; then forward selection ([`select`]) adds catalogue effects one at a
//! time, each judged by a Wald test with the honest covariance (white noise plus the
//! wandering bias) and confirmed on segments held out of every fit. Candidates are the
//! registry's effects and the user effects of `*.effect` files ([`user`]); with a
//! procedure, [`adoption`] writes the diff that declares the findings in its fits.
//!
//! The modules stand in layers, each using only those below it, so that each can be read
//! (and changed) without the ones above: [`stats`] (pure statistics), [`probe`] and the
//! Earth's rate candidate ([`earth::candidate`]) at the bottom; [`data`] (the
//! accumulation) over them; [`model`] over `data`; [`select`] and [`earth`] over `model`;
//! discovery, location, timing and the output over those.

// Numeric loops index the six channels of several arrays at once.
#![allow(clippy::needless_range_loop)]

pub mod across;
mod adopt;
mod alternatives;
mod change;
mod change_out;
pub(crate) mod data;
mod discover;
mod discovered;
pub mod draft;
mod earth;
mod locate;
pub(crate) mod model;
mod observe;
mod output;
mod plausible;
mod probe;
pub mod profile;
mod select;
mod stats;
mod text;
mod timing;
mod unexplained;

pub(crate) use timing::TIMING;
pub mod user;

/// A finding's parameters are the results' own parameter type.
pub use crate::results::Parameter;
pub use adopt::{AdoptTarget, Adoption, adoption, next_version};
pub use model::NominalModel;
pub use output::{
    AlternativeFit, Evidence, Explanation, FORMAT, Final, Finding, Located, Nominal, NotObservable,
    RefusedOut, Rms, SegmentRms, Signature, Term, Unexplained, UserEffectOut,
};
pub use text::render_text;
pub use user::UserEffect;

use crate::fit::Source;
use crate::fit::joint::Fit;
use crate::recording::{Manifest, Recording};
use data::Data;
use model::{Terms, fit, rms, seed_segments};
use ratecal_physics::{Effect, REGISTRY};
use std::collections::BTreeMap;

/// What explain may be told besides the recording.
#[derive(Debug, Clone)]
pub struct Options {
    /// How the recording is named in the output (its folder).
    pub path: String,
    /// Family-wise false-discovery threshold of one selection step.
    pub alpha: f64,
    /// Candidate effects read from files ([`user::load`]), tried with the registry's.
    pub user: Vec<&'static UserEffect>,
    /// Registry ids left out of the candidates.
    pub without: Vec<String>,
    /// Also fit every candidate beside the final model ([`profile`]): what explain over
    /// several recordings pools.
    pub profile: bool,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            path: String::new(),
            alpha: 1e-3,
            user: Vec::new(),
            without: Vec::new(),
            profile: false,
        }
    }
}

/// Explains a recording held in memory against a nominal model.
pub fn explain(rec: &Recording, nominal: &NominalModel, opts: &Options) -> Explanation {
    let Ok(x) = explain_source(rec, nominal, opts);
    x
}

/// Explains a recording read from `src` a window of samples at a time; fails only when a
/// span of the recording cannot be read.
pub fn explain_source<S: Source>(
    src: &S,
    nominal: &NominalModel,
    opts: &Options,
) -> Result<Explanation, S::Error> {
    let (data, nonfinite) = accumulate(src, opts, crate::fit::Retime::default())?;
    let x = explain_data(src.manifest(), &data, &nonfinite, nominal, opts);
    timing::exact(src, nominal, opts, x)
}

/// The recording accumulated once for explain (the registry's effects and `opts.user`),
/// and each user effect's count of non-finite regressor values before the pass: what
/// [`explain_data`] and the twin's comparison (`crate::twin`) share.
pub(crate) fn accumulate<S: Source>(
    src: &S,
    opts: &Options,
    retime: crate::fit::Retime,
) -> Result<(Data, Vec<usize>), S::Error> {
    let mut effects: Vec<&'static dyn Effect> = REGISTRY.to_vec();
    effects.extend(opts.user.iter().map(|u| *u as &'static dyn Effect));
    let nonfinite: Vec<usize> = opts.user.iter().map(|u| u.nonfinite()).collect();
    let clock = std::time::Instant::now();
    let data = Data::with_effects(src, effects, retime)?;
    if std::env::var_os("RATECAL_EXPLAIN_DEBUG").is_some() {
        eprintln!("accumulated in {:?}", clock.elapsed());
    }
    Ok((data, nonfinite))
}

/// [`explain_source`] on a recording already accumulated ([`accumulate`]).
pub(crate) fn explain_data(
    m: &Manifest,
    data: &Data,
    nonfinite: &[usize],
    nominal: &NominalModel,
    opts: &Options,
) -> Explanation {
    explain_fitted(m, data, nonfinite, nominal, opts).0
}

/// [`explain_data`], with the final model's value and u of the first column of each
/// nominal timing term ([`TIMING`]): what is left about the timing the data hold.
pub(crate) fn explain_fitted(
    m: &Manifest,
    data: &Data,
    nonfinite: &[usize],
    nominal: &NominalModel,
    opts: &Options,
) -> (Explanation, Vec<(&'static str, f64, f64)>) {
    let clock = std::time::Instant::now();
    let debug = std::env::var_os("RATECAL_EXPLAIN_DEBUG").is_some();
    let lay = &data.layout;
    let mut warnings = Vec::new();
    for (u, &before) in opts.user.iter().zip(nonfinite) {
        let n = u.nonfinite() - before;
        if n > 0 {
            warnings.push(format!(
                "user effect `{}` ({}): {n} regressor values were not finite and were taken as zero",
                u.id(),
                u.file()
            ));
        }
    }
    for id in &opts.without {
        if lay.index(id).is_none_or(|e| lay.effects[e].nominal()) {
            warnings.push(format!("--without {id}: not a candidate effect"));
        }
    }
    let index = |id: &str| lay.index(id).expect("a registry id");
    let mut start = Terms {
        effects: nominal.effects.iter().map(|id| index(id)).collect(),
        fixed: nominal
            .fixed
            .iter()
            .map(|(id, v)| (index(id), v.clone()))
            .collect(),
        skip: Vec::new(),
    };
    if !data.left_out.is_empty() {
        warnings.push(format!(
            "{} static segments of unknown attitude (attitude: unknown, or an old recording's \
             up: oblique) are left out: explain needs each segment's attitude, and a hand-held \
             pose has none to tilt ({})",
            data.left_out.len(),
            data.left_out.join(", ")
        ));
    }
    let tilt = observe::tilt_in_start(data, &mut start, opts.alpha);
    // What this recording cannot determine is not fitted: its columns are skipped in
    // every model grown from `start`.
    let mut observed = observe::observe(data, &start);
    observed.entries.extend(tilt);
    start.skip.extend(observed.skip.iter().copied());
    let all: Vec<usize> = (0..data.accs.len()).collect();
    let (sa, sg) = seed_segments(m, data);
    if (sa.is_empty() || sg.is_empty()) && !data.accs.is_empty() {
        warnings.push(
            "the recording lacks static or rate segments: the nominal model is fitted on every segment"
                .into(),
        );
    }
    let (sa, sg) = if sa.is_empty() || sg.is_empty() {
        (all.clone(), all.clone())
    } else {
        (sa, sg)
    };
    let (nom, _) = fit(data, &start, &sa, &sg);
    let nominal_out = Nominal {
        model: nominal.name.clone(),
        terms: start.names(&data.layout),
        rms: rms(data, &nom, &all),
        holdout_rms: rms(data, &nom, &data.held),
    };
    let sel = select::forward(data, &start, opts.alpha, &opts.without);
    if debug {
        eprintln!("selected in {:?}", clock.elapsed());
    }
    let (mut steps, mut rejected, mut refused) = (sel.steps, sel.last_p, sel.refused);
    let work = data.working();
    // Each finding's parameters come from the final model, every finding in it, refitted
    // on every segment once the held-out ones have confirmed it: an effect found early was
    // fitted without those found after it (which its estimate may have partly absorbed),
    // and a held-out segment may be the one that determines a parameter best.
    let mut terms = start.clone();
    for step in &steps {
        terms.effects.push(step.effect);
    }
    let latitude = m.station.site.latitude_deg;
    let mut held = earth::hold(data, &mut terms, latitude);
    // What the registry left: forms of the probe library, found one at a time.
    let registry_terms = terms.clone();
    let mut lib_refused = Vec::new();
    let mut discoveries = Vec::new();
    discover::discover(
        data,
        &mut terms,
        opts.alpha,
        &mut lib_refused,
        &mut discoveries,
    );
    if !discoveries.is_empty() {
        // The registry's selection again beside what was found: a strong unlisted form can
        // hide the Earth's rate (or a registry effect) from the held-out segments, and a
        // free Earth scale that looked off may have been the discovery's.
        let mut again = start.clone();
        again.effects.extend(
            terms
                .effects
                .iter()
                .filter(|e| !registry_terms.effects.contains(e)),
        );
        again.skip.extend(
            terms
                .skip
                .iter()
                .filter(|g| !registry_terms.skip.contains(g)),
        );
        let sel = select::forward(data, &again, opts.alpha, &opts.without);
        (steps, rejected, refused) = (sel.steps, sel.last_p, sel.refused);
        for step in &steps {
            again.effects.push(step.effect);
        }
        held = earth::hold(data, &mut again, latitude);
        discover::discover(
            data,
            &mut again,
            opts.alpha,
            &mut lib_refused,
            &mut discoveries,
        );
        discover::refine_again(data, &again, &mut discoveries);
        terms = again;
    }
    refused.extend(lib_refused);
    let last = fit(data, &terms, &work, &work).0;
    if debug {
        eprintln!("discovered in {:?}", clock.elapsed());
    }
    let whole = fit(data, &terms, &all, &all);
    let timing_left: Vec<(&'static str, f64, f64)> = TIMING
        .iter()
        .filter(|id| nominal.effects.contains(id))
        .filter_map(|id| {
            let g = lay.columns_of(lay.index(id)?).start;
            whole
                .0
                .estimated
                .contains(&g)
                .then(|| (*id, whole.0.theta[g], whole.0.u(g)))
        })
        .collect();
    let mut findings: Vec<Finding> = steps
        .iter()
        .map(|step| {
            let mut f = finding(m, data, step, &terms, &whole);
            refused.extend(alternatives::attach(data, &mut f, step.effect, &terms));
            f.defined_in = opts
                .user
                .iter()
                .find(|u| u.id() == f.effect)
                .map(|u| u.file().to_string());
            if step.effect == data.earth
                && let Some(h) = &held
            {
                f.parameters = h.parameters(latitude);
            }
            f
        })
        .collect();
    findings.extend(
        discoveries
            .iter()
            .map(|d| discovered::finding(m, data, d, &registry_terms, &whole.0)),
    );
    refused.extend(change_points(
        m,
        data,
        &terms,
        &whole.0,
        opts.alpha,
        &mut findings,
    ));
    let mut unexplained = unexplained::leftover(m, data, &terms, &whole.0, opts.alpha);
    if debug {
        eprintln!("leftover tested in {:?}", clock.elapsed());
    }
    if let Some(note) = held.as_ref().and_then(|h| h.mimic(opts.alpha)) {
        unexplained.insert(0, note);
    }
    let floor = |cs: std::ops::Range<usize>| {
        let v: Vec<f64> = cs.map(|c| last.noise[c].sigma.powi(2)).collect();
        (v.iter().sum::<f64>() / v.len() as f64).sqrt()
    };
    let final_ = Final {
        terms: earth::names(data, &terms),
        rms: rms(data, &last, &all),
        holdout_rms: rms(data, &last, &data.held),
        noise_floor: Rms {
            accel_mps2: floor(0..3),
            gyro_dps: floor(3..6),
        },
    };
    let profile = match opts.profile {
        true => {
            let mut found: Vec<usize> = steps.iter().map(|s| s.effect).collect();
            found.extend(discoveries.iter().map(|d| d.step.effect));
            profile::profile(data, &terms, &start.skip, &found, latitude)
        }
        false => Vec::new(),
    };
    let adopt = adopt_of(&findings);
    let x = Explanation {
        format: FORMAT.into(),
        recording: opts.path.clone(),
        nominal: nominal_out,
        segments_used: data.accs.len(),
        findings,
        final_,
        held_out: data
            .held
            .iter()
            .map(|&i| m.segments[data.accs[i].seg].id.clone())
            .collect(),
        rejected,
        not_observable: observed.entries,
        refused: refused
            .into_iter()
            .map(|r| RefusedOut {
                effect: r.effect,
                reason: r.reason,
            })
            .collect(),
        unexplained,
        adopt,
        already_held: Vec::new(),
        adopt_diff: None,
        draft_effects: Vec::new(),
        user_effects: opts
            .user
            .iter()
            .map(|u| UserEffectOut {
                effect: u.id().to_string(),
                file: u.file().to_string(),
            })
            .collect(),
        warnings,
        profile,
    };
    (x, timing_left)
}

/// The change points the final model `whole` leaves inside segments, as discovered
/// findings; a library step discovered at a gap next to a change point on the same channel
/// was that change point, put at the nearest gap, and gives way to it. Returns the change
/// points refused as implausible.
fn change_points(
    m: &Manifest,
    data: &Data,
    terms: &Terms,
    whole: &Fit,
    alpha: f64,
    findings: &mut Vec<Finding>,
) -> Vec<select::Refused> {
    let library = discover::live_columns(data, terms);
    let all: Vec<usize> = (0..data.accs.len()).collect();
    let now = rms(data, whole, &all);
    let mut refused = Vec::new();
    for cp in change::scan(data, whole, alpha, library) {
        let (sensor, _) = crate::fit::joint::channel(cp.channel);
        let form = probe::Form::Step { at: cp.at_s };
        let max = data.grade * probe::range::max_abs(form, sensor, 0.0);
        match change_out::finding(m, data, &cp, alpha, max, now) {
            Ok(f) => {
                let seg = &m.segments[data.accs[cp.acc].seg];
                findings.retain(|d| !gap_step_beside(d, &f.terms[0].channel, seg));
                findings.push(f);
            }
            Err(reason) => refused.push(select::Refused {
                effect: "discovered".into(),
                reason,
            }),
        }
    }
    refused
}

/// Whether `d` is a library step on `channel` whose instant lies in a gap that borders
/// `seg` (within the gap's own span of the segment's ends).
fn gap_step_beside(d: &Finding, channel: &str, seg: &crate::recording::Segment) -> bool {
    let Some(Parameter::Estimate { value: at, u, .. }) = d.parameters.get("at_s") else {
        return false;
    };
    let reach = 12f64.sqrt() * u / 2.0 + 1.0;
    d.discovered
        && d.terms.iter().any(|t| t.channel == channel)
        && ((at - seg.t_end).abs() <= reach || (seg.t_start - at).abs() <= reach)
}

/// How to adopt the findings (`with lever_arm, time_offset`): only the registry's effects
/// can be declared in a procedure.
fn adopt_of(findings: &[Finding]) -> Option<String> {
    adopt_ids(findings, &[])
}

/// A finding a procedure declares by name (`with ...`): a registry effect, neither a user
/// file's nor discovered, that the run's procedure does not hold (`held`) already.
pub(crate) fn declarable(f: &Finding, held: &[String]) -> bool {
    f.defined_in.is_none() && !f.discovered && !held.contains(&f.effect)
}

fn adopt_ids(findings: &[Finding], held: &[String]) -> Option<String> {
    let ids: Vec<&str> = findings
        .iter()
        .filter(|f| declarable(f, held) && beyond_zero(f))
        .map(|f| f.effect.as_str())
        .collect();
    (!ids.is_empty()).then(|| format!("with {}", ids.join(", ")))
}

/// Whether a finding has a value a procedure would gain from: at least one parameter more
/// than three standard uncertainties from zero (an effect whose every value is within 3u
/// of zero passed jointly, by its number of columns, and is not asked to be adopted).
/// A finding without estimated parameters (its form alone) counts as beyond.
pub fn beyond_zero(f: &Finding) -> bool {
    let mut est = f
        .parameters
        .values()
        .filter_map(Parameter::value_u)
        .peekable();
    est.peek().is_none() || est.any(|(v, u)| v.abs() > 3.0 * u)
}

/// A run folder explained against the seed model: the findings its own procedure already
/// holds (`model`: fitted, or held at a known value such as the Earth's rate in every
/// procedure's references) are listed in `already_held` and left out of `adopt`, so that
/// explain never asks to add what the run's results hold.
pub fn mark_held(x: &mut Explanation, model: &NominalModel) {
    let held: Vec<String> = (x.findings.iter())
        .filter(|f| f.defined_in.is_none() && !f.discovered)
        .map(|f| f.effect.clone())
        .filter(|id| {
            model.effects.contains(&id.as_str()) || model.fixed.iter().any(|(f, _)| f == id)
        })
        .collect();
    if !held.is_empty() {
        x.adopt = adopt_ids(&x.findings, &held);
        x.already_held = held;
    }
}

/// One accepted step as a finding, its parameters from the final model fitted on every
/// segment (`whole`: the fit and its unobservable columns).
fn finding(
    m: &Manifest,
    data: &Data,
    step: &select::Step,
    terms: &Terms,
    whole: &(Fit, Vec<usize>),
) -> Finding {
    let (last, unobservable) = whole;
    let lay = &data.layout;
    let fx = lay.effects[step.effect];
    let mut parameters = BTreeMap::new();
    for g in lay.columns_of(step.effect) {
        let p = lay.param(g);
        let out = if unobservable.contains(&g) || !last.estimated.contains(&g) {
            // Always with the motion it needs, even an empty one: explain's JSON always
            // carries `needs` (docs/explain.md).
            Parameter::needs(p.needs)
        } else {
            Parameter::estimate(last.theta[g], last.u(g), p.unit)
        };
        parameters.insert(p.name.to_string(), out);
    }
    // The Earth's rate is the only candidate with a latitude, and it is held: its
    // parameters are replaced by the held ones (earth::Held::parameters).
    let all: Vec<usize> = (0..data.accs.len()).collect();
    let evidence = evidence(data, step, terms);
    Finding {
        effect: fx.id().into(),
        explanation: fx.explanation().into(),
        located: locate::locate(m, data, step),
        residuals: locate::per_segment(m, data, step),
        parameters,
        evidence,
        rms_after: rms(data, &step.after, &all),
        defined_in: None,
        alternatives: step
            .alternatives
            .iter()
            .map(|&e| lay.effects[e].id().to_string())
            .collect(),
        station_side: fx.station_side(),
        discovered: false,
        terms: Vec::new(),
        alternative_fits: Vec::new(),
        separate_by: None,
    }
}

/// A step's evidence: its test, and the held-out residual before and after it.
fn evidence(data: &Data, step: &select::Step, terms: &Terms) -> Evidence {
    Evidence {
        chi2: step.chi2,
        dof: step.dof,
        p_value: step.p,
        alpha: step.alpha,
        holdout_rms_before: rms(data, &step.before, &data.held),
        holdout_rms_after: rms(data, &step.after, &data.held),
        not_separable_from: locate::confusions(data, terms, step.effect),
    }
}
