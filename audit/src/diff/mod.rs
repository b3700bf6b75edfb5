//! Semantic diff of two checked procedures. Plans are compared after the checker resolved
//! parameters, imports, units and `for` loops, so formatting, comments, unit spelling
//! (`0.002 g` against `2 mg`) and parameter indirection are not changes. The version
//! number itself is not a change: both sides' versions head the report.

mod limits;
mod pair;
mod step;

use super::change::{Change, ChangeKind, fmt_num, fmt_s};
use pair::{Pair, moved_pairs, pair};
use ratecal_plan::{Plan, Step};

/// Every semantic change from `old` to `new`, in procedure order: metadata, station
/// requirements, environment, run-wide abort rules, steps (with their fits and
/// acceptance limits), procedure-level acceptance, verification points, duration.
pub fn diff(old: &Plan, new: &Plan) -> Vec<Change> {
    let mut out = Vec::new();
    metadata(old, new, &mut out);
    limits::requirements(&old.requirements, &new.requirements, &mut out);
    limits::environment(&old.environment, &new.environment, &mut out);
    limits::aborts("", &old.aborts, &new.aborts, &mut out);
    steps(old, new, &mut out);
    limits::accepts(None, &old.accepts, &new.accepts, &mut out);
    limits::verifications(&old.verifications, &new.verifications, &mut out);
    if (old.estimated_duration_s - new.estimated_duration_s).abs() >= 1.0 {
        let (a, b) = fmt_durations(old.estimated_duration_s, new.estimated_duration_s);
        out.push(Change::value(
            "estimated duration",
            ChangeKind::Changed,
            a,
            b,
        ));
    }
    out
}

/// A duration for people (`82.5 min`, `45 s`).
fn fmt_duration(s: f64) -> String {
    if s >= 60.0 {
        format!("{} min", fmt_num((s / 60.0 * 10.0).round() / 10.0))
    } else {
        fmt_s(s.round())
    }
}

/// Two durations that differ, in the coarsest form that shows it (`73.4 min` to `73.5
/// min`, else minutes and seconds: `73 min 24 s` to `73 min 27 s`).
fn fmt_durations(old: f64, new: f64) -> (String, String) {
    let (a, b) = (fmt_duration(old), fmt_duration(new));
    if a != b {
        return (a, b);
    }
    let ms = |s: f64| {
        let s = s.round();
        format!("{} min {} s", (s / 60.0).floor(), s % 60.0)
    };
    (ms(old), ms(new))
}

fn text_change(path: &str, old: &str, new: &str, out: &mut Vec<Change>) {
    if old != new {
        out.push(Change::value(path, ChangeKind::Changed, old, new));
    }
}

fn option_change(path: &str, old: Option<&str>, new: Option<&str>, out: &mut Vec<Change>) {
    match (old, new) {
        (Some(o), Some(n)) => text_change(path, o, n, out),
        (None, Some(n)) => out.push(Change::added(path, n)),
        (Some(o), None) => out.push(Change::removed(path, o)),
        (None, None) => {}
    }
}

fn metadata(old: &Plan, new: &Plan, out: &mut Vec<Change>) {
    text_change("name", &old.name, &new.name, out);
    text_change("title", &old.title, &new.title, out);
    option_change(
        "imu class",
        old.imu_class.as_deref(),
        new.imu_class.as_deref(),
        out,
    );
    for p in pair(&old.references, &new.references, |r| r.clone()) {
        match p {
            Pair::Old(r) => out.push(Change::removed("reference", r)),
            Pair::New(r) => out.push(Change::added("reference", r)),
            Pair::Both(..) => {}
        }
    }
    let keys: std::collections::BTreeSet<&String> =
        old.meta.keys().chain(new.meta.keys()).collect();
    for k in keys {
        let path = format!("meta {k}");
        option_change(
            &path,
            old.meta.get(k).map(String::as_str),
            new.meta.get(k).map(String::as_str),
            out,
        );
    }
}

/// The path prefix of a step (`step accel_static`).
fn step_path(s: &Step) -> String {
    format!("step {}", s.name)
}

fn steps(old: &Plan, new: &Plan, out: &mut Vec<Change>) {
    let pairs = pair(&old.steps, &new.steps, |s| s.name.clone());
    let mut moved_flags = moved_pairs(&pairs).into_iter();
    for p in pairs {
        let name = match p {
            Pair::Both(_, s, _, _) | Pair::Old(s) | Pair::New(s) => s.name.clone(),
        };
        match p {
            Pair::Old(s) => {
                out.push(Change::removed(step_path(s), step_summary(s)).alerting());
            }
            Pair::New(s) => out.push(Change::added(step_path(s), step_summary(s))),
            Pair::Both(i, o, j, n) => {
                if moved_flags.next().unwrap_or(false) {
                    out.push(Change::value(
                        step_path(n),
                        ChangeKind::Moved,
                        format!("position {}", i + 1),
                        format!("position {}", j + 1),
                    ));
                }
                step::step(o, n, out);
            }
        }
        let (of, nf) = (fits_of(&old.fits, &name), fits_of(&new.fits, &name));
        limits::fits(&format!("step {name}"), &of, &nf, out);
        limits::accepts(Some(&name), &old.accepts, &new.accepts, out);
    }
}

fn fits_of(fits: &[ratecal_plan::FitSpec], step: &str) -> Vec<ratecal_plan::FitSpec> {
    fits.iter()
        .filter(|f| f.step == step)
        .cloned()
        .collect::<Vec<_>>()
}

/// One line describing a whole step (title, acquisitions).
fn step_summary(s: &Step) -> String {
    let segs = step::segments(s);
    let title = s
        .title
        .as_deref()
        .map(|t| format!("\"{t}\", "))
        .unwrap_or_default();
    format!(
        "{title}{} acquisition(s), about {}",
        segs.len(),
        fmt_duration(s.estimated_duration_s)
    )
}
