//! A discovered term as a finding: its name says the form, its explanation is the
//! dictionary's reading, its terms are the expressions with their coefficients from the
//! final model, and a decay or a step names its time constant or instant.

use super::data::Data;
use super::discover::{Discovery, channel_of, local_axis, name};
use super::output::{Finding, Term};
use super::probe::Form;
use super::{locate, model::Terms, model::rms};
use crate::fit::joint::{CHANNELS, Fit};
use crate::recording::Manifest;
use crate::results::Parameter;
use std::collections::BTreeMap;

/// The finding of discovery `d`, its coefficients from `last` (the final model fitted on
/// every segment).
pub(crate) fn finding(
    m: &Manifest,
    data: &Data,
    d: &Discovery,
    terms: &Terms,
    last: &Fit,
) -> Finding {
    let probe = d.probe;
    let mut parameters = BTreeMap::new();
    let mut out_terms = Vec::new();
    let mut explanation = probe.reading().to_string();
    let form = match (probe.form, &d.tau) {
        (Form::Decay { t0, .. }, Some(r)) => Form::Decay {
            t0,
            tau: r.tau_s.round(),
        },
        (f, _) => f,
    };
    for (j, &g) in d.columns.iter().enumerate() {
        let c = channel_of(data, g);
        let ax = local_axis(data, g);
        let (value, u) = match &d.tau {
            Some(r) => r.amplitudes[j],
            None => (last.theta[g], last.u(g)),
        };
        let unit = form.unit(probe.sensor).to_string();
        parameters.insert(
            format!("k_{}", CHANNELS[c]),
            Parameter::Estimate {
                value,
                u,
                unit: unit.clone(),
            },
        );
        out_terms.push(Term {
            channel: CHANNELS[c].to_string(),
            expression: form.expression(probe.sensor, ax),
            value,
            u,
            unit,
            needs: probe.form.needs().to_string(),
            max_abs: super::plausible::max_abs(data.layout.param(g)),
        });
    }
    match (probe.form, &d.tau) {
        (Form::Decay { .. }, Some(r)) => {
            parameters.insert(
                "tau_s".into(),
                Parameter::Estimate {
                    value: r.tau_s,
                    u: r.u_s,
                    unit: "s".into(),
                },
            );
            explanation.push_str(&format!(
                " (time constant {:.0} +- {:.0} s)",
                r.tau_s, r.u_s
            ));
        }
        (Form::Decay { tau, .. }, None) => {
            explanation.push_str(&format!(" (time constant about {tau:.0} s)"));
        }
        (Form::Step { at }, _) => {
            let (before, after) = gap(m, data, at);
            parameters.insert(
                "at_s".into(),
                Parameter::Estimate {
                    value: at,
                    u: (after - before) / 12f64.sqrt(),
                    unit: "s".into(),
                },
            );
            explanation.push_str(&format!(
                " between t = {before:.1} s and {after:.1} s, when no segment was recorded"
            ));
        }
        _ => {}
    }
    let all: Vec<usize> = (0..data.accs.len()).collect();
    let step = &d.step;
    Finding {
        effect: name(data, d),
        explanation,
        located: locate::locate(m, data, step),
        residuals: locate::per_segment(m, data, step),
        parameters,
        evidence: super::evidence(data, step, terms),
        rms_after: rms(data, &step.after, &all),
        defined_in: None,
        alternatives: Vec::new(),
        separate_by: None,
        station_side: false,
        discovered: true,
        terms: out_terms,
        alternative_fits: Vec::new(),
    }
}

/// The gap around instant `at`: the end of the last segment before it and the start of
/// the first after it.
fn gap(m: &Manifest, data: &Data, at: f64) -> (f64, f64) {
    let mut before = f64::NEG_INFINITY;
    let mut after = f64::INFINITY;
    for a in &data.accs {
        let s = &m.segments[a.seg];
        if s.t_end <= at {
            before = before.max(s.t_end);
        }
        if s.t_start >= at {
            after = after.min(s.t_start);
        }
    }
    if !before.is_finite() || !after.is_finite() {
        return (at, at);
    }
    (before, after)
}
