//! The twin's section of explain's text output.

use super::output::TwinReport;
use std::fmt::Write;

/// The twin's comparison for a person: the prediction before and after, what disagrees,
/// the changes.
pub fn render_text(r: &TwinReport) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "\nTwin: {}", r.station);
    for (name, p) in [("as it is", &r.before), ("updated", &r.after)] {
        let _ = writeln!(
            s,
            "  {name}: residual RMS accel {:.3e} m/s^2 (noise {:.3e}), gyro {:.3e} deg/s (noise {:.3e})",
            p.rms.accel_mps2, p.noise.accel_mps2, p.rms.gyro_dps, p.noise.gyro_dps
        );
    }
    if !r.before.disagree.is_empty() {
        let _ = writeln!(s, "  where the twin disagrees (residual RMS / noise):");
        for d in &r.before.disagree {
            let _ = writeln!(
                s,
                "    {} {}: {:.3e} ({:.1}x the noise; mean {:.3e})",
                d.segment, d.channel, d.rms, d.ratio, d.mean
            );
        }
    }
    if r.changes.is_empty() {
        let _ = writeln!(
            s,
            "  no change: the twin predicts the recording to its noise"
        );
    } else {
        let _ = writeln!(s, "  changes:");
        for c in &r.changes {
            let what = if c.added {
                "  (the twin lacked it)"
            } else {
                ""
            };
            let _ = writeln!(
                s,
                "    {}.{}: {} -> {} ({:.1} standard errors){what}",
                c.effect,
                c.parameter,
                crate::measured::format_value(c.from, &c.unit),
                crate::measured::format_measured(c.to, c.u, &c.unit),
                c.standard_errors
            );
        }
    }
    if !r.not_determined.is_empty() {
        let names: Vec<String> = (r.not_determined.iter())
            .map(|k| {
                let v = crate::measured::format_value(k.value, &k.unit);
                format!("{}.{} ({v})", k.effect, k.parameter)
            })
            .collect();
        let _ = writeln!(
            s,
            "  kept as the twin has them (this recording cannot determine them): {}",
            names.join(", ")
        );
    }
    if let Some(w) = &r.written {
        let _ = writeln!(s, "  written: {w}");
    }
    if let Some(d) = &r.diff {
        let _ = write!(s, "{d}");
    }
    s
}
