//! A discovered finding as a draft `.effect` file (docs/user-effects.md): one parameter per
//! channel, `k_<channel>`, times the term's expression. `ratecal explain --effects` reads it
//! unchanged and tries it like any user effect, so the engineer confirms the discovery on
//! this recording or the next one, renames it and adopts it.

use super::output::Finding;
use crate::results::Parameter;

/// The draft file's name for a finding.
pub fn file_name(f: &Finding) -> String {
    format!("{}.effect", f.effect)
}

/// The draft effect file of a discovered finding (`None` for any other finding).
pub fn effect_file(f: &Finding, recording: &str) -> Option<String> {
    if !f.discovered || f.terms.is_empty() {
        return None;
    }
    let clean = |s: &str| s.replace(['"', '\\', '\n'], " ");
    let mut out = String::new();
    out.push_str(&format!(
        "# Draft written by `ratecal explain` from {}: a form that no registry effect\n\
         # and no effect file holds. Read it, rename the effect and its parameters, then\n\
         # confirm it: ratecal explain RECORDING --effects THIS_FILE\n#\n",
        clean(recording)
    ));
    out.push_str(&format!(
        "# Found with p = {:.2e} (threshold {:.0e} over the whole library); held-out\n\
         # residual {:.4e} -> {:.4e} m/s^2, {:.4e} -> {:.4e} deg/s.\n",
        f.evidence.p_value,
        f.evidence.alpha,
        f.evidence.holdout_rms_before.accel_mps2,
        f.evidence.holdout_rms_after.accel_mps2,
        f.evidence.holdout_rms_before.gyro_dps,
        f.evidence.holdout_rms_after.gyro_dps,
    ));
    for (name, p) in &f.parameters {
        if let Parameter::Estimate { value, u, unit } = p {
            out.push_str(&format!("#   {name} = {value:.6} +- {u:.6} {unit}\n"));
        }
    }
    out.push_str(&format!("\neffect {} {{\n", f.effect));
    out.push_str(&format!("  explanation \"{}\"\n", clean(&f.explanation)));
    let follows: Vec<&str> = f.terms.iter().map(|t| t.expression.as_str()).collect();
    out.push_str(&format!("  follows \"{}\"\n\n", clean(&follows.join("; "))));
    for t in &f.terms {
        out.push_str(&format!(
            "  param k_{} unit \"{}\" needs \"{}\"\n",
            t.channel,
            clean(&t.unit),
            clean(&t.needs)
        ));
    }
    out.push('\n');
    for t in &f.terms {
        out.push_str(&format!(
            "  {} += k_{} * ({})\n",
            t.channel, t.channel, t.expression
        ));
    }
    out.push_str("}\n");
    Some(out)
}
