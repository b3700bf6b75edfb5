//! What explain tests check of an explanation: the effects found, and a finding's
//! parameters against the truth.

use ratecal_analysis::explain::{Explanation, Parameter};

/// The effects found, sorted.
pub fn found(x: &Explanation) -> Vec<&str> {
    let mut v: Vec<&str> = x.findings.iter().map(|f| f.effect.as_str()).collect();
    v.sort_unstable();
    v
}

/// Every estimated parameter of `effect` lies within `k` standard uncertainties of the
/// truth (`truth` lists the non-zero ones; the rest are zero), plus one part in a thousand
/// of the truth: the fit is linear, and the product of a scale error (up to 1000 ppm) with
/// an effect (`a = K_a s`, the lever arm inside `s`) is a second-order term it leaves out.
pub fn within(x: &Explanation, effect: &str, truth: &[(&str, f64)], k: f64) {
    let f = x
        .findings
        .iter()
        .find(|f| f.effect == effect)
        .unwrap_or_else(|| panic!("{effect} not found: {:?}", found(x)));
    for (name, p) in &f.parameters {
        if let Parameter::Estimate { value, u, .. } = p {
            let want = truth.iter().find(|t| t.0 == name).map_or(0.0, |t| t.1);
            assert!(
                (value - want).abs() <= k * u + 1e-3 * want.abs(),
                "{effect}.{name} = {value} ± {u}, truth {want}"
            );
        }
    }
}
