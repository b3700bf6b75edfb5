//! A finding's alternatives (docs/explain.md, "alternatives"): the candidates that tie with
//! it and those its evidence cannot separate from it, each fitted in its place so that an
//! engineer sees both answers. An alternative whose own fit lies outside its plausible
//! range is not an answer: it is refused, with why.

use super::data::Data;
use super::model::{Terms, fit};
use super::output::{AlternativeFit, Finding};
use super::plausible::max_abs;
use super::select::Refused;
use crate::results::Parameter;
use std::collections::BTreeMap;

/// Fills `f.alternatives` (ties and `not_separable_from`), `f.alternative_fits` and
/// `f.separate_by` for the finding of layout effect `e` in the final model `terms`;
/// returns the alternatives refused.
pub(crate) fn attach(data: &Data, f: &mut Finding, e: usize, terms: &Terms) -> Vec<Refused> {
    let lay = &data.layout;
    let mut ids: Vec<String> = f.alternatives.clone();
    for id in &f.evidence.not_separable_from {
        if !ids.contains(id) {
            ids.push(id.clone());
        }
    }
    let mut refused = Vec::new();
    let mut kept = Vec::new();
    for id in ids {
        let Some(alt) = lay.index(&id) else { continue };
        match fit_in_place(data, e, alt, terms) {
            Ok(parameters) => {
                f.alternative_fits.push(AlternativeFit {
                    effect: id.clone(),
                    parameters,
                });
                kept.push((id, alt));
            }
            Err(why) => refused.push(Refused {
                effect: id,
                reason: format!("as an alternative to {}: {why}", f.effect),
            }),
        }
    }
    f.separate_by = (!kept.is_empty()).then(|| {
        kept.iter()
            .filter_map(|&(_, a)| lay.effects[a].params().first())
            .map(|p| p.needs)
            .chain(lay.effects[e].params().first().map(|p| p.needs))
            .collect::<Vec<_>>()
            .join("; ")
    });
    f.alternatives = kept.into_iter().map(|k| k.0).collect();
    refused
}

/// The parameters of `alt` fitted in place of `e` on every segment, or why they are not
/// plausible.
fn fit_in_place(
    data: &Data,
    e: usize,
    alt: usize,
    terms: &Terms,
) -> Result<BTreeMap<String, Parameter>, String> {
    let lay = &data.layout;
    let mut t = terms.clone();
    t.effects.retain(|x| *x != e);
    t.effects.push(alt);
    let all: Vec<usize> = (0..data.accs.len()).collect();
    let (f, unobservable) = fit(data, &t, &all, &all);
    let mut out = BTreeMap::new();
    for g in lay.columns_of(alt) {
        let p = lay.param(g);
        if unobservable.contains(&g) || !f.estimated.contains(&g) {
            out.insert(p.name.to_string(), Parameter::needs(p.needs));
            continue;
        }
        let (v, u) = (f.theta[g], f.u(g));
        if let Some(max) = max_abs(p)
            && v.abs() > max
        {
            return Err(format!(
                "its fit {} = {v:.4} {} is outside what a real part shows (|{}| <= {max} {})",
                p.name, p.unit, p.name, p.unit
            ));
        }
        out.insert(p.name.to_string(), Parameter::estimate(v, u, p.unit));
    }
    Ok(out)
}
