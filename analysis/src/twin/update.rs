//! The twin with the recording's changes made: the values a corrected station file holds.

use super::Twin;
use super::output::Change;
use crate::fit::joint::Layout;

/// `twin` with every change made: a changed parameter takes its new value, an effect the
/// twin lacked is added with the parameters the recording determined (the rest 0). The
/// layout knows every effect's parameters, the user effects' too.
pub(super) fn updated(twin: &Twin, changes: &[Change], lay: &Layout) -> Twin {
    let mut out = twin.clone();
    for c in changes {
        let Some(fx) = lay.index(&c.effect).map(|e| lay.effects[e]) else {
            continue;
        };
        let Some(k) = fx.params().iter().position(|p| p.name == c.parameter) else {
            continue;
        };
        let slot = match out.terms.iter().position(|(id, _)| *id == c.effect) {
            Some(i) => i,
            None => {
                out.terms
                    .push((c.effect.clone(), vec![0.0; fx.params().len()]));
                out.terms.len() - 1
            }
        };
        out.terms[slot].1[k] = c.to;
    }
    out
}
