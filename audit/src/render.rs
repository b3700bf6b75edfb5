//! Renderers of a diff: a change list an auditor reads and signs (text), the stable JSON
//! interface, and the one-line summary `ratecal log` prints per version.

use super::change::{Change, ChangeKind, DiffReport};
use std::fmt::Write as _;

/// The JSON form, keys in this order: `{"old": {name, version, sha256}, "new": {...},
/// "changes": [{path, kind, old, new}]}`, a change's `old`/`new` being `null` when absent.
pub fn json(report: &DiffReport) -> String {
    serde_json::to_string_pretty(report).unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}"))
}

/// Whether a change is about an abort rule (its loosening is a weakening).
fn is_abort(c: &Change) -> bool {
    c.path.starts_with("abort when") || c.path.contains("/ abort when")
}

/// The label of a change in the text form; alerts are upper case.
fn label(c: &Change) -> &'static str {
    match (c.kind, is_abort(c), c.alert) {
        (ChangeKind::Loosened, true, _) => "WEAKENED",
        (ChangeKind::Tightened, true, _) => "strengthened",
        (ChangeKind::Loosened, false, _) => "LOOSENED",
        (ChangeKind::Removed, _, true) => "REMOVED",
        (k, _, _) => k.as_str(),
    }
}

fn value_text(c: &Change) -> String {
    match (&c.old, &c.new) {
        (Some(o), Some(n)) => format!("{o} -> {n}"),
        (None, Some(n)) => n.clone(),
        (Some(o), None) => format!("was {o}"),
        (None, None) => String::new(),
    }
}

/// Counts of each kind, alerts first (`2 loosened, 1 removed, 3 changed`).
fn counts(changes: &[Change]) -> String {
    let kinds = [
        ChangeKind::Loosened,
        ChangeKind::Removed,
        ChangeKind::Tightened,
        ChangeKind::Added,
        ChangeKind::Changed,
        ChangeKind::Moved,
    ];
    kinds
        .iter()
        .filter_map(|k| {
            let n = changes.iter().filter(|c| c.kind == *k).count();
            (n > 0).then(|| format!("{n} {}", k.as_str()))
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// The text form: a header naming both versions with their full hashes, one line per
/// change (`!` and an upper-case label on what weakens the procedure), and lines to sign.
/// `color` adds ANSI colour (only for a terminal).
pub fn text(report: &DiffReport, color: bool) -> String {
    let (o, n) = (&report.old, &report.new);
    let mut s = String::new();
    let name = if o.name == n.name {
        o.name.clone()
    } else {
        format!("{} -> {}", o.name, n.name)
    };
    let _ = writeln!(
        s,
        "Procedure {name}: changes from {} to {}",
        o.version, n.version
    );
    let _ = writeln!(s, "  old {} sha256 {}", o.version, o.sha256);
    let _ = writeln!(s, "  new {} sha256 {}", n.version, n.sha256);
    let _ = writeln!(s);
    if report.changes.is_empty() {
        let _ = writeln!(s, "No semantic change.");
        return s;
    }
    let alerts = report.changes.iter().filter(|c| c.alert).count();
    let _ = writeln!(
        s,
        "{} change(s): {}",
        report.changes.len(),
        counts(&report.changes)
    );
    if alerts > 0 {
        let _ = writeln!(s, "{alerts} change(s) weaken the procedure (marked !)");
    }
    let _ = writeln!(s);
    let width = report
        .changes
        .iter()
        .map(|c| label(c).len())
        .max()
        .unwrap_or(0);
    for (i, c) in report.changes.iter().enumerate() {
        let mark = if c.alert { "!" } else { " " };
        let lab = format!("{:<width$}", label(c));
        let lab = if !color {
            lab
        } else if c.alert {
            format!("\x1b[1;31m{lab}\x1b[0m")
        } else if c.kind == ChangeKind::Tightened {
            format!("\x1b[32m{lab}\x1b[0m")
        } else {
            format!("\x1b[33m{lab}\x1b[0m")
        };
        let _ = writeln!(
            s,
            "{mark} {:>3}. {lab}  {}: {}",
            i + 1,
            c.path,
            value_text(c)
        );
    }
    let _ = writeln!(s);
    let _ = writeln!(
        s,
        "Reviewed by: ______________________  Date: ____________  Signature: ______________"
    );
    s
}

/// One line summarising the changes from the previous version, for `ratecal log`:
/// counts by kind, then the alerts by path (`3 change(s): 1 loosened, 2 added; loosened:
/// step gyro_scale / accept gyro.residual.std`).
pub fn summary(changes: &[Change]) -> String {
    if changes.is_empty() {
        return "no semantic change".into();
    }
    let mut s = format!("{} change(s): {}", changes.len(), counts(changes));
    let alerts: Vec<String> = changes
        .iter()
        .filter(|c| c.alert)
        .map(|c| format!("{} {}", label(c), c.path))
        .collect();
    if !alerts.is_empty() {
        let _ = write!(s, "; ! {}", alerts.join("; ! "));
    }
    let added: Vec<&str> = changes
        .iter()
        .filter(|c| c.kind == ChangeKind::Added)
        .map(|c| c.path.as_str())
        .collect();
    if !added.is_empty() {
        let _ = write!(s, "; added {}", added.join(", "));
    }
    s
}
