//! The text form of explain across recordings: what recurs first (the model's physics,
//! the unit's, what only the pool shows, the day's), then the outliers and each
//! recording's own findings in one line.

use super::{Across, PooledOut};
use std::fmt::Write;

/// What each verdict means, in a heading.
const HEADINGS: [(&str, &str); 4] = [
    ("model", "Physics of the model (every unit shows it)"),
    (
        "unit",
        "Physics of one unit (every recording of its serial)",
    ),
    (
        "pooled_only",
        "Seen only in the pool (no single recording passes)",
    ),
    (
        "occasional",
        "Occasional (some recordings only: of the day)",
    ),
];

/// The text output of explain across recordings.
pub fn render_text(a: &Across) -> String {
    let mut s = String::new();
    let serials = a.units();
    let _ = writeln!(
        s,
        "Across {} recordings of {serials} units:",
        a.recordings.len()
    );
    let mut any = false;
    for (verdict, heading) in HEADINGS {
        let of: Vec<&PooledOut> = a.effects.iter().filter(|e| e.verdict == verdict).collect();
        if of.is_empty() {
            continue;
        }
        any = true;
        let _ = writeln!(s, "\n{heading}:");
        for e in of {
            let _ = writeln!(s, "  {}", line(e));
            if verdict == "unit" {
                let serial = unit_serial(e);
                let _ = writeln!(s, "    in every recording of {serial}");
            }
        }
    }
    if !any {
        let _ = writeln!(
            s,
            "\nNothing recurs: no parameter is significant in the pool."
        );
    }
    if !a.outliers.is_empty() {
        let _ = writeln!(s, "\nOutliers (outside the fleet's spread):");
        for o in &a.outliers {
            let _ = writeln!(
                s,
                "  {}: {}.{} = {} ± {}",
                o.serial,
                o.effect,
                o.parameter,
                num(o.value),
                num(o.u)
            );
        }
    }
    let _ = writeln!(s, "\nEach recording:");
    for r in &a.recordings {
        let found = match r.findings.is_empty() {
            true => "nothing found".to_string(),
            false => r.findings.join(", "),
        };
        let left = match r.unexplained {
            0 => String::new(),
            n => format!("; {n} unexplained"),
        };
        let _ = writeln!(s, "  {} ({}): {found}{left}", r.run, r.serial);
    }
    s
}

/// `accel_second_order.kxx = 12.3 ± 2.1 ug/g^2 (spread 0.8, I² 12 %; 2 left out)`.
fn line(e: &PooledOut) -> String {
    let left = match e.left_out.len() {
        0 => String::new(),
        n => format!("; {n} left out"),
    };
    format!(
        "{}.{} = {} ± {} {} (spread {}, I² {:.0} %, {} recordings{left})",
        e.effect,
        e.parameter,
        num(e.pooled),
        num(e.u),
        e.unit,
        num(e.spread),
        100.0 * e.i2,
        e.per_recording.len()
    )
}

/// The serial a `unit` verdict belongs to: the one with the most recordings whose values
/// stand out most.
fn unit_serial(e: &PooledOut) -> String {
    e.per_recording
        .iter()
        .max_by(|a, b| (a.value / a.u).abs().total_cmp(&(b.value / b.u).abs()))
        .map(|r| r.serial.clone())
        .unwrap_or_default()
}

/// Four significant digits.
fn num(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let digits = (3 - v.abs().log10().floor() as i32).clamp(0, 12) as usize;
    format!("{v:.digits$}")
}
