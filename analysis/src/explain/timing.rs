//! Timing taken exactly. The registry's `time_offset` and `clock_rate` columns are first
//! order in the lag, and a realistic clock is far beyond that: 50 ppm is 0.2 s late after
//! an hour, and at 100 deg/s that turns gravity by 20 degrees. When explain finds a timing
//! term, the recording is read again with the feedback evaluated at the found timing (as
//! the simulator re-times the motion, [`Retime`]), the timing held in the model, and what
//! the timing columns leave is added to it; until they leave nothing beyond their u.
//!
//! The findings are the last pass's, with the timing findings of the passes before (their
//! evidence from the pass that found them, their values from the last pass: the held timing
//! plus what is left of it). The nominal model's figures stay the first pass's: the model
//! as given, without the timing.

use super::{Explanation, Finding, NominalModel, Options, Parameter, accumulate, explain_fitted};
use crate::fit::{Retime, Source};

/// The registry's timing terms, in the order of [`Retime::registry`]: `time_offset.tau_ms`
/// and `clock_rate.ppm`.
pub(crate) const TIMING: [&str; 2] = ["time_offset", "clock_rate"];

/// Passes at a corrected timing at most.
const PASSES: usize = 3;

/// The one parameter of a timing term.
fn param(id: &str) -> &'static str {
    if id == "time_offset" { "tau_ms" } else { "ppm" }
}

/// A finding's estimate of its timing parameter, if it has one.
fn value(x: &Explanation, id: &str) -> Option<(f64, f64)> {
    let f = x.findings.iter().find(|f| f.effect == id)?;
    f.parameters.get(param(id))?.value_u()
}

/// The timing terms `x` found, added to `held`, their findings kept in `found`.
fn take(x: &Explanation, held: &mut [Option<f64>; 2], found: &mut Vec<Finding>) {
    for (k, id) in TIMING.iter().enumerate() {
        if let (Some((v, _)), Some(f)) = (value(x, id), x.findings.iter().find(|f| f.effect == *id))
        {
            held[k] = Some(v + held[k].unwrap_or(0.0));
            found.retain(|g| g.effect != *id);
            found.push(f.clone());
        }
    }
}

/// `x` (explain's first pass, at no timing) taken again at the timing it found, when it
/// found one.
pub(super) fn exact<S: Source>(
    src: &S,
    nominal: &NominalModel,
    opts: &Options,
    x: Explanation,
) -> Result<Explanation, S::Error> {
    // The timing held so far, per term (tau ms, ppm), and the findings that found it.
    let mut held: [Option<f64>; 2] = [None; 2];
    let mut found = Vec::new();
    take(&x, &mut held, &mut found);
    if held.iter().all(Option::is_none) {
        return Ok(x);
    }
    let first = x;
    let mut last = None;
    for _ in 0..PASSES {
        let retime = Retime::from_registry(held.map(|h| h.unwrap_or(0.0)));
        let mut model = nominal.clone();
        for (k, id) in TIMING.iter().enumerate() {
            if held[k].is_some() && !model.effects.contains(id) {
                model.effects.push(id);
            }
        }
        let (data, nonfinite) = accumulate(src, opts, retime)?;
        let (x, left) = explain_fitted(src.manifest(), &data, &nonfinite, &model, opts);
        let mut settled = true;
        for (id, d, u) in left {
            let k = TIMING.iter().position(|t| *t == id).expect("a timing term");
            let base = held[k].unwrap_or(0.0);
            settled &= d.abs() <= u;
            held[k] = Some(base + d);
            // The finding's value: the held timing plus what is left of it.
            if let Some(f) = found.iter_mut().find(|f| f.effect == id)
                && let Some(Parameter::Estimate { value, u: fu, .. }) =
                    f.parameters.get_mut(param(id))
            {
                (*value, *fu) = (base + d, u);
            }
        }
        // A timing term this pass found that the passes before had not (a time offset
        // hidden behind a large clock rate).
        let before = held;
        take(&x, &mut held, &mut found);
        settled &= held == before;
        last = Some(x);
        if settled {
            break;
        }
    }
    let mut x = last.expect("at least one pass");
    x.findings.retain(|f| !TIMING.contains(&f.effect.as_str()));
    let n = found.len();
    x.findings.splice(0..0, found);
    x.nominal = first.nominal;
    x.adopt = super::adopt_of(&x.findings);
    x.warnings.push(format!(
        "{n} timing term(s) found: the recording was read again with the table's feedback at the found timing, so that the lag is taken exactly, not to first order"
    ));
    Ok(x)
}
