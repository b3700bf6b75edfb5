//! `ratecal explain RUN RUN... [--format json]`: several recordings explained, each as one
//! is (in parallel), then every candidate's parameters pooled across them
//! (`ratecal_analysis::explain::across`, docs/explain.md "Across recordings"). Exit codes
//! as explain's: 0 nothing found, 1 a recording or the pool has a finding, 2 error, 4 a run
//! folder's seal fails.

use crate::explain::Format;
use ratecal_analysis::explain::{self, Explanation, NominalModel, Options, UserEffect, across};
use ratecal_analysis::fit::{Source, Streamed};
use std::path::PathBuf;

/// Family-wise (per recording) and false-discovery (pool) level.
const ALPHA: f64 = 1e-3;

/// What `ratecal explain` over several recordings is asked.
pub struct Request {
    /// The run folders (recordings), in the order given.
    pub runs: Vec<PathBuf>,
    /// Procedure whose fits are the nominal model of every recording.
    pub procedure: Option<PathBuf>,
    /// Effect files or folders of them.
    pub effects: Vec<PathBuf>,
    /// Registry effects left out of the candidates.
    pub without: Vec<String>,
    /// Output format.
    pub format: Format,
    /// Accept a released procedure version whose text changed after release.
    pub allow_changed: bool,
    /// Runs from the archive too (`--archive`, `--serial`/`--model`, `--since`/`--until`).
    pub archive: Option<crate::across_archive::Selection>,
}

/// One recording explained: its run (as named in the output), its serial and model, the
/// explanation with its profile.
pub struct Explained {
    /// The run as the output names it.
    pub run: String,
    /// The manifest's `imu.serial`.
    pub serial: String,
    /// The manifest's `imu.model`.
    pub model: String,
    /// Explain's result, with its profile.
    pub explanation: Explanation,
}

/// A command that stops with this exit code, its diagnostics said.
type Exit = u8;

/// Explains the recordings and pools them; the exit code (0 nothing found, 1 a finding in
/// a recording or the pool, 2 error, 4 a seal fails).
pub fn explain_across(args: &Request) -> u8 {
    match run(args) {
        Ok(code) | Err(code) => code,
    }
}

fn run(args: &Request) -> Result<u8, Exit> {
    for dir in &args.runs {
        if let Err(e) = ratecal_folder::verify::require_intact(dir, "explanation") {
            errln!("{e:?}");
            return Err(4);
        }
    }
    let files = crate::explain::effect_files(&args.effects).map_err(|e| {
        errln!("error: {e}");
        2u8
    })?;
    let user = crate::explain::load_effects(&args.effects).map_err(|()| 2)?;
    let plan = match &args.procedure {
        Some(p) => Some(
            crate::analyze::load_plan(p, args.allow_changed)
                .map_err(|()| 2)?
                .0,
        ),
        None => None,
    };
    let jobs: Vec<(String, PathBuf)> = args
        .runs
        .iter()
        .map(|p| (p.display().to_string(), p.clone()))
        .collect();
    let cx = Context {
        user,
        without: args.without.clone(),
        plan,
    };
    let mut explained = explain_all(&jobs, &cx)?;
    if let Some(sel) = &args.archive {
        let key = crate::across_archive::key(&cx, &files);
        explained.extend(crate::across_archive::explained(sel, &cx, &key)?);
    }
    report(&explained, args.format)
}

/// What every recording is explained with.
pub struct Context {
    /// User effects.
    pub user: Vec<&'static UserEffect>,
    /// Registry effects left out.
    pub without: Vec<String>,
    /// The procedure whose fits are the nominal model.
    pub plan: Option<ratecal_analysis::plan::Plan>,
}

/// Explains every (name, folder) in parallel (a worker per core, each taking the next
/// recording), in the order given; the first error is said and ends the command (exit 2).
pub fn explain_all(jobs: &[(String, PathBuf)], cx: &Context) -> Result<Vec<Explained>, Exit> {
    let next = std::sync::atomic::AtomicUsize::new(0);
    let slots: Vec<std::sync::Mutex<Option<Result<Explained, String>>>> =
        jobs.iter().map(|_| std::sync::Mutex::new(None)).collect();
    let workers = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(jobs.len())
        .max(1);
    std::thread::scope(|s| {
        for _ in 0..workers {
            s.spawn(|| {
                loop {
                    let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    let Some((name, dir)) = jobs.get(i) else {
                        break;
                    };
                    let r = explain_one(name, dir, cx);
                    *slots[i].lock().expect("not poisoned") = Some(r);
                }
            });
        }
    });
    let mut out = Vec::new();
    for slot in slots {
        match slot.into_inner().expect("not poisoned") {
            Some(Ok(x)) => out.push(x),
            Some(Err(e)) => {
                errln!("{e}");
                return Err(2);
            }
            None => return Err(2),
        }
    }
    Ok(out)
}

/// One recording explained with its profile.
pub fn explain_one(name: &str, dir: &std::path::Path, cx: &Context) -> Result<Explained, String> {
    let rec = Streamed::open(dir).map_err(|e| format!("{:?}", miette::Report::new(e)))?;
    let m = rec.manifest();
    let nominal = match &cx.plan {
        Some(p) => NominalModel::from_plan(p, m.station.site.latitude_deg),
        None => NominalModel::seed(),
    };
    let opts = Options {
        path: name.to_string(),
        user: cx.user.clone(),
        without: cx.without.clone(),
        profile: true,
        ..Options::default()
    };
    let mut x = explain::explain_source(&rec, &nominal, &opts)
        .map_err(|e| format!("{:?}", miette::Report::new(e)))?;
    if cx.plan.is_none() {
        crate::explain::held_by_the_run(dir, &rec, &mut x);
    }
    let get = |k: &str| m.imu.get(k).cloned();
    let serial = get("serial").unwrap_or_else(|| {
        x.warnings
            .push("the manifest names no imu.serial: the run's name stands for its unit".into());
        name.to_string()
    });
    Ok(Explained {
        run: name.to_string(),
        serial,
        model: get("model").unwrap_or_else(|| "unknown".into()),
        explanation: x,
    })
}

/// Pools the explained recordings, prints the result, returns the exit code.
pub fn report(explained: &[Explained], format: Format) -> Result<u8, Exit> {
    let members: Vec<across::Member> = explained
        .iter()
        .map(|e| across::Member {
            run: e.run.clone(),
            serial: e.serial.clone(),
            explanation: &e.explanation,
        })
        .collect();
    let a = across::pool(&members, ALPHA);
    let found = explained
        .iter()
        .any(|e| !(e.explanation.findings.is_empty() && e.explanation.unexplained.is_empty()));
    let out = match format {
        Format::Json => {
            let recs: Vec<serde_json::Value> = explained
                .iter()
                .map(|e| {
                    let mut x = e.explanation.clone();
                    // Each recording's own values are in `across`: its profile is not repeated.
                    x.profile.clear();
                    serde_json::to_value(&x).expect("plain data serializes")
                })
                .collect();
            let v = serde_json::json!({
                "format": explain::FORMAT,
                "across": a,
                "explanations": recs,
            });
            serde_json::to_string_pretty(&v).expect("plain data serializes") + "\n"
        }
        Format::Text => across::render_text(&a),
    };
    crate::console::out(format_args!("{out}"), false);
    Ok(u8::from(found || a.has_finding()))
}
