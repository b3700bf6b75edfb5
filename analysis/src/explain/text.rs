//! The text form of an explanation, for the terminal.

use super::output::{Explanation, Rms};
use crate::measured::format_measured;
use crate::results::Parameter;
use std::fmt::Write;

fn rms(r: &Rms) -> String {
    format!(
        "accel {:.3e} m/s^2, gyro {:.3e} deg/s",
        r.accel_mps2, r.gyro_dps
    )
}

/// Renders an explanation for a person.
pub fn render_text(x: &Explanation) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "explain {}", x.recording);
    match x.segments_used {
        0 => nothing_compared(&mut s, x),
        _ => compared(&mut s, x),
    }
    for w in &x.warnings {
        let _ = writeln!(s, "warning: {w}");
    }
    s
}

/// What a recording with no segment to compare the model with gets: why, and what does
/// calibrate it.
fn nothing_compared(s: &mut String, x: &Explanation) {
    let _ = writeln!(
        s,
        "nominal model ({}: {}): not compared with the recording\n\n\
         nothing to explain from: no segment of the recording has a known attitude or a \
         table's motion to compare the model with (see the warnings below); a session of \
         hand-held poses is calibrated by `ratecal analyze`",
        x.nominal.model,
        x.nominal.terms.join(", ")
    );
}

/// The comparison: the nominal model, the findings, the final model and what is left.
fn compared(s: &mut String, x: &Explanation) {
    let _ = writeln!(
        s,
        "nominal model ({}: {}): residual RMS {}",
        x.nominal.model,
        x.nominal.terms.join(", "),
        rms(&x.nominal.rms)
    );
    if x.findings.is_empty() && x.unexplained.is_empty() {
        let _ = writeln!(
            s,
            "\nnothing found: the nominal model explains the recording to its noise"
        );
    }
    for (k, f) in x.findings.iter().enumerate() {
        let origin = f
            .defined_in
            .as_ref()
            .map(|file| format!(" (user effect, {file})"))
            .unwrap_or_else(|| {
                if f.discovered {
                    " (discovered: a form outside the registry)".into()
                } else if f.station_side {
                    " (a station error: the table, not the IMU)".into()
                } else {
                    String::new()
                }
            });
        let _ = writeln!(s, "\n{}. {}{origin}: {}", k + 1, f.effect, f.explanation);
        let _ = writeln!(
            s,
            "   evidence: chi2 {:.1} on {} dof, p = {:.1e} (threshold {:.1e}); held-out RMS {} -> {}",
            f.evidence.chi2,
            f.evidence.dof,
            f.evidence.p_value,
            f.evidence.alpha,
            rms(&f.evidence.holdout_rms_before),
            rms(&f.evidence.holdout_rms_after)
        );
        if !f.evidence.not_separable_from.is_empty() {
            let _ = writeln!(
                s,
                "   this recording cannot tell it apart from: {}",
                f.evidence.not_separable_from.join(", ")
            );
        }
        for l in &f.located {
            let _ = writeln!(
                s,
                "   shows in {} {} ({:.1}-{:.1} s{}): RMS {:.3e} -> {:.3e}, follows {}",
                l.segment,
                l.channel,
                l.t_start,
                l.t_end,
                if l.held_out { ", held out" } else { "" },
                l.rms_before,
                l.rms_after,
                l.correlates_with
            );
        }
        for t in &f.terms {
            let _ = writeln!(
                s,
                "   {} += ({}) * {}",
                t.channel,
                format_measured(t.value, t.u, &t.unit),
                t.expression
            );
        }
        for (name, p) in &f.parameters {
            match p {
                Parameter::Estimate { value, u, unit } => {
                    let _ = writeln!(s, "   {name} = {}", format_measured(*value, *u, unit));
                }
                Parameter::Unobservable {
                    needs: Some(needs), ..
                } => {
                    let _ = writeln!(s, "   {name}: not determined ({needs} to observe it)");
                }
                Parameter::Unobservable { needs: None, .. } => {
                    let _ = writeln!(s, "   {name}: not determined");
                }
                Parameter::UpperBound {
                    upper_bound, unit, ..
                } => {
                    let b = crate::measured::format_value(*upper_bound, unit);
                    let _ = writeln!(s, "   {name} <= {b} (an upper bound only)");
                }
            }
        }
        if !f.alternatives.is_empty() {
            let _ = writeln!(
                s,
                "   explains it as well (the data cannot say which): {}; to separate them: {}",
                f.alternatives.join(", "),
                f.separate_by.as_deref().unwrap_or("more varied motion")
            );
        }
        let _ = writeln!(s, "   residual RMS after: {}", rms(&f.rms_after));
    }
    for u in &x.unexplained {
        let sensor = if u.sensor == "accel" {
            "accelerometer"
        } else {
            "gyro"
        };
        let _ = writeln!(
            s,
            "\nnot explained: the {sensor} residual ({}){}: {:.0} standard errors, p = {:.1e} after the multiplicity correction",
            u.channels.join(", "),
            if u.segments.is_empty() {
                String::new()
            } else {
                format!(" on {}", u.segments.join(", "))
            },
            u.standard_errors,
            u.p_value
        );
        if let Some(note) = &u.note {
            let _ = writeln!(s, "   {note}");
        }
        for f in &u.signature {
            let _ = writeln!(
                s,
                "   it follows {} on {} ({:.0} % of the leftover): {}",
                f.expression,
                f.channel,
                100.0 * f.share,
                f.reading
            );
        }
    }
    for r in &x.refused {
        let _ = writeln!(s, "\nnot reported: {}: {}", r.effect, r.reason);
    }
    let _ = writeln!(
        s,
        "\nfinal model: {}\n   RMS {} (held out: {}); noise floor {}",
        x.final_.terms.join(", "),
        rms(&x.final_.rms),
        rms(&x.final_.holdout_rms),
        rms(&x.final_.noise_floor)
    );
    match (&x.adopt_diff, &x.adopt) {
        (Some(d), _) => {
            let _ = write!(
                s,
                "to adopt, apply this diff (`patch -p0` or `git apply -p0`):\n{d}"
            );
        }
        (None, Some(a)) => {
            let _ = writeln!(s, "to adopt: add `{a}` to the procedure's fit statements");
        }
        (None, None) => {}
    }
    if !x.already_held.is_empty() {
        let _ = writeln!(
            s,
            "already in the run's procedure (nothing to add): {}",
            x.already_held.join(", ")
        );
    }
    let faint: Vec<&str> = (x.findings.iter())
        .filter(|f| super::declarable(f, &x.already_held) && !super::beyond_zero(f))
        .map(|f| f.effect.as_str())
        .collect();
    if !faint.is_empty() {
        let _ = writeln!(
            s,
            "not to adopt (significant together, yet every value within 3 standard uncertainties of zero): {}",
            faint.join(", ")
        );
    }
    let user: Vec<&str> = x
        .findings
        .iter()
        .filter(|f| f.defined_in.is_some())
        .map(|f| f.effect.as_str())
        .collect();
    if !user.is_empty() {
        let _ = writeln!(
            s,
            "user effects ({}) cannot be declared in a procedure: add them to the effect registry (docs/effects.md) to calibrate them",
            user.join(", ")
        );
    }
    for d in &x.draft_effects {
        let _ = writeln!(
            s,
            "draft effect file for {}: {} (confirm it with --effects, rename it, adopt it)",
            d.effect, d.file
        );
    }
}
