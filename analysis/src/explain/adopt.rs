//! How to adopt explain's findings: a unified diff against the procedure's file in which
//! its fit statements declare the effects (`fit accel bias_scale with lever_arm from ...`).
//! A released version is never edited: the diff then copies it to the next minor version
//! (a git-style copy), so `ratecal check` accepts the result and `ratecal diff` shows the
//! auditor the added effects. Paths are written as given (apply with `patch -p0` or
//! `git apply -p0`).

use ratecal_grammar::ast::{File, Fit, Item, ProcItem, Stmt, TopItem};
use ratecal_physics::effects::Sensor;
use ratecal_plan::versions::{Version, parse_lock, version_of_file_name};

/// The procedure file a diff is made against.
#[derive(Debug, Clone)]
pub struct AdoptTarget {
    /// The file as named on the command line.
    pub path: String,
    /// Its text.
    pub text: String,
    /// For a released version: the next version and the path of its file.
    pub next: Option<(String, String)>,
}

/// The diff and what it could not place.
#[derive(Debug, Clone, PartialEq)]
pub struct Adoption {
    /// Unified diff; `None` when every effect is already declared.
    pub diff: Option<String>,
    /// Effects no fit statement of their sensors could declare.
    pub not_placed: Vec<String>,
}

/// The version a released version file's changes go to: the next minor version above every
/// version of its folder (released in `lock_text` or present among `siblings`, file
/// names). `None` when `file_name` is not a released version.
pub fn next_version(file_name: &str, lock_text: &str, siblings: &[String]) -> Option<String> {
    let v = version_of_file_name(file_name)?;
    let (entries, _) = parse_lock("", lock_text);
    let released: Vec<Version> = entries
        .iter()
        .filter_map(|e| Version::parse(&e.version))
        .collect();
    if !released.contains(&v) {
        return None;
    }
    let top = released
        .into_iter()
        .chain(siblings.iter().filter_map(|s| version_of_file_name(s)))
        .max()?;
    let [major, minor, _] = top.numbers;
    Some(
        Version {
            numbers: [major, minor + 1, 0],
            pre: None,
        }
        .to_string(),
    )
}

/// Whether a fit statement may declare effects on `sensor` (the fits of the joint model:
/// not the Allan deviation, the temperature compensation nor the size effect).
fn declares(fit: &Fit) -> Option<Sensor> {
    let model = fit.model.as_ref().map(|m| m.node.as_str());
    match (fit.sensor.node.as_str(), model) {
        ("accel", None | Some("bias_scale" | "full")) => Some(Sensor::Accel),
        ("gyro", None | Some("bias" | "scale" | "full")) => Some(Sensor::Gyro),
        _ => None,
    }
}

fn fits<'a>(items: &'a [Item<Stmt>], out: &mut Vec<(&'a Fit, usize)>) {
    for it in items {
        match &it.node {
            Stmt::Fit(f) => out.push((f, it.span.start)),
            Stmt::For { body, .. } | Stmt::Repeat { body, .. } => fits(&body.items, out),
            _ => {}
        }
    }
}

/// The diff that adds `effects` (registry ids) to the procedure's fit statements: each
/// effect goes to the last fit statement of a sensor it acts on, unless a fit declares it
/// already.
pub fn adoption(target: &AdoptTarget, effects: &[&str]) -> Result<Adoption, String> {
    let file: File = ratecal_grammar::parse(&target.text).map_err(|d| format!("{d:?}"))?;
    let Some(proc_) = file.body.items.iter().find_map(|i| match &i.node {
        TopItem::Procedure(p) => Some(p),
        _ => None,
    }) else {
        return Err(format!("{} holds no procedure", target.path));
    };
    let mut all = Vec::new();
    for it in &proc_.body.items {
        if let ProcItem::Step(s) = &it.node {
            fits(&s.body.items, &mut all);
        }
    }
    let declared = |id: &str| all.iter().any(|(f, _)| f.with.iter().any(|w| w.node == id));
    let mut adds: Vec<Vec<&str>> = vec![Vec::new(); all.len()];
    let mut not_placed = Vec::new();
    for &id in effects {
        if declared(id) {
            continue;
        }
        let sensors = ratecal_physics::effect(id).map_or(&[][..], |e| e.sensors());
        let last = all
            .iter()
            .rposition(|(f, _)| declares(f).is_some_and(|s| sensors.contains(&s)));
        match last {
            Some(k) => adds[k].push(id),
            None => not_placed.push(id.to_string()),
        }
    }
    // Edits as (start, end, replacement), applied from the end so offsets stay valid.
    let text = &target.text;
    let mut edits: Vec<(usize, usize, String)> = Vec::new();
    for ((f, start), ids) in all.iter().zip(&adds) {
        if ids.is_empty() {
            continue;
        }
        if let Some(last) = f.with.last() {
            let end = last.span.end;
            edits.push((end, end, format!(", {}", ids.join(", "))));
        } else {
            let first = f.from.first().map_or(*start, |p| p.span.start);
            let at = text
                .get(*start..first)
                .and_then(|head| head.rfind("from"))
                .map_or(first, |k| start + k);
            edits.push((at, at, format!("with {} ", ids.join(", "))));
        }
    }
    if edits.is_empty() {
        return Ok(Adoption {
            diff: None,
            not_placed,
        });
    }
    if let Some((v, _)) = &target.next {
        let s = proc_.version.span;
        edits.push((s.start, s.end, v.clone()));
    }
    edits.sort_by_key(|e| std::cmp::Reverse(e.0));
    let mut new = text.clone();
    for (start, end, with) in edits {
        new.replace_range(start..end, &with);
    }
    let new_path = target.next.as_ref().map_or(&target.path, |n| &n.1);
    let body = similar::TextDiff::from_lines(text.as_str(), new.as_str())
        .unified_diff()
        .context_radius(3)
        .header(&target.path, new_path)
        .to_string();
    let diff = match &target.next {
        None => body,
        Some((_, np)) => format!(
            "diff --git {p} {np}\ncopy from {p}\ncopy to {np}\n{body}",
            p = target.path
        ),
    };
    Ok(Adoption {
        diff: Some(diff),
        not_placed,
    })
}
