//! Explain: where a recording and the nominal model disagree, which physics of the effect
//! registry was left out, the refit with it, and the evidence (docs/explain.md).
//!
//! The recording is accumulated once ([`data`]); the nominal model is fitted as the
//! standard would; then forward selection ([`select`]) adds catalogue effects one at a
//! time, each judged by a Wald test with the honest covariance (white noise plus the
//! wandering bias) and confirmed on segments held out of every fit.

// Numeric loops index the six channels of several arrays at once.
#![allow(clippy::needless_range_loop)]

pub(crate) mod data;
mod locate;
pub(crate) mod model;
mod output;
mod select;
mod text;

pub use model::NominalModel;
pub use output::{
    Evidence, Explanation, FORMAT, Final, Finding, Located, Nominal, ParamOut, Rms, SegmentRms,
};
pub use text::render_text;

use crate::recording::Recording;
use data::Data;
use model::{Terms, fit, rms, seed_segments};
use std::collections::BTreeMap;

/// What explain may be told besides the recording.
#[derive(Debug, Clone)]
pub struct Options {
    /// How the recording is named in the output (its folder).
    pub path: String,
    /// Family-wise false-discovery threshold of one selection step.
    pub alpha: f64,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            path: String::new(),
            alpha: 1e-3,
        }
    }
}

/// Explains a recording against a nominal model.
pub fn explain(rec: &Recording, nominal: &NominalModel, opts: &Options) -> Explanation {
    let data = Data::new(rec);
    let lay = &data.layout;
    let mut warnings = Vec::new();
    let index = |id: &str| lay.index(id).expect("a registry id");
    let start = Terms {
        effects: nominal.effects.iter().map(|id| index(id)).collect(),
        fixed: nominal
            .fixed
            .iter()
            .map(|(id, v)| (index(id), v.clone()))
            .collect(),
    };
    let all: Vec<usize> = (0..data.accs.len()).collect();
    let (sa, sg) = seed_segments(rec, &data);
    if sa.is_empty() || sg.is_empty() {
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
    let (nom, _) = fit(&data, &start, &sa, &sg);
    let nominal_out = Nominal {
        model: nominal.name.clone(),
        terms: start.names(&data),
        rms: rms(&data, &nom, &all),
        holdout_rms: rms(&data, &nom, &data.held),
    };
    let (steps, rejected) = select::forward(&data, &start, opts.alpha);
    let mut findings = Vec::new();
    let mut terms = start.clone();
    for step in &steps {
        terms.effects.push(step.effect);
        findings.push(finding(rec, &data, step, &terms));
    }
    let work = data.working();
    let last = match steps.last() {
        Some(s) => s.after.clone(),
        None => fit(&data, &start, &work, &work).0,
    };
    let floor = |cs: std::ops::Range<usize>| {
        let v: Vec<f64> = cs.map(|c| last.noise[c].sigma.powi(2)).collect();
        (v.iter().sum::<f64>() / v.len() as f64).sqrt()
    };
    let final_ = Final {
        terms: terms.names(&data),
        rms: rms(&data, &last, &all),
        holdout_rms: rms(&data, &last, &data.held),
        noise_floor: Rms {
            accel_mps2: floor(0..3),
            gyro_dps: floor(3..6),
        },
    };
    let adopt = (!findings.is_empty()).then(|| {
        let ids: Vec<&str> = findings.iter().map(|f| f.effect.as_str()).collect();
        format!("with {}", ids.join(", "))
    });
    Explanation {
        format: FORMAT.into(),
        recording: opts.path.clone(),
        nominal: nominal_out,
        findings,
        final_,
        held_out: data
            .held
            .iter()
            .map(|&i| rec.manifest.segments[data.accs[i].seg].id.clone())
            .collect(),
        rejected,
        adopt,
        warnings,
    }
}

/// One accepted step as a finding.
fn finding(rec: &Recording, data: &Data, step: &select::Step, terms: &Terms) -> Finding {
    let lay = &data.layout;
    let fx = lay.effects[step.effect];
    let mut parameters = BTreeMap::new();
    for g in lay.columns_of(step.effect) {
        let p = lay.param(g);
        let out = if step.unobservable.contains(&g) {
            ParamOut::Unobservable {
                observable: false,
                needs: p.needs.to_string(),
            }
        } else {
            ParamOut::Estimate {
                value: step.after.theta[g],
                u: step.after.u(g),
                unit: p.unit.to_string(),
            }
        };
        parameters.insert(p.name.to_string(), out);
    }
    if let Some((lat, ulat)) = model::latitude(data, &step.after, step.effect) {
        parameters.insert(
            "latitude_deg".into(),
            ParamOut::Estimate {
                value: lat,
                u: ulat,
                unit: "deg".into(),
            },
        );
    }
    let all: Vec<usize> = (0..data.accs.len()).collect();
    let evidence = Evidence {
        chi2: step.chi2,
        dof: step.dof,
        p_value: step.p,
        alpha: step.alpha,
        holdout_rms_before: rms(data, &step.before, &data.held),
        holdout_rms_after: rms(data, &step.after, &data.held),
        not_separable_from: locate::confusions(data, terms, step.effect),
    };
    Finding {
        effect: fx.id().into(),
        explanation: fx.explanation().into(),
        located: locate::locate(rec, data, step),
        residuals: locate::per_segment(rec, data, step),
        parameters,
        evidence,
        rms_after: rms(data, &step.after, &all),
    }
}
