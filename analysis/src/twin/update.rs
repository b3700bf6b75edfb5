//! The twin with the recording's changes made: the values a corrected station file holds.

use super::Twin;
use super::output::Change;

/// `twin` with every change made: a changed parameter takes its new value, an effect the
/// twin lacked is added with the parameters the recording determined (the rest 0).
pub fn updated_terms(twin: &Twin, changes: &[Change]) -> Twin {
    let mut out = twin.clone();
    for c in changes {
        let n = ratecal_physics::effect(&c.effect)
            .map(|e| e.params().len())
            .unwrap_or(0);
        let k = ratecal_physics::effect(&c.effect)
            .and_then(|e| e.params().iter().position(|p| p.name == c.parameter));
        let (Some(k), true) = (k, n > 0) else {
            // A user effect: its parameters are not the registry's to look up; the
            // report's order is its own.
            user_change(&mut out, c);
            continue;
        };
        let slot = match out.terms.iter().position(|(id, _)| *id == c.effect) {
            Some(i) => i,
            None => {
                out.terms.push((c.effect.clone(), vec![0.0; n]));
                out.terms.len() - 1
            }
        };
        out.terms[slot].1[k] = c.to;
    }
    out
}

/// A user effect's change: its values in the order the changes list them.
fn user_change(twin: &mut Twin, c: &Change) {
    match twin.terms.iter_mut().find(|(id, _)| *id == c.effect) {
        Some((_, v)) => v.push(c.to),
        None => twin.terms.push((c.effect.clone(), vec![c.to])),
    }
}
