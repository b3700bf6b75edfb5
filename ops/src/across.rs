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
    /// Where to write the forest plots (`explain-across.html`).
    pub plots: Option<PathBuf>,
    /// The station file the model's twin is written into (with `write_twin` only).
    pub twin: Option<PathBuf>,
    /// Where to write the model's twin.
    pub write_twin: Option<PathBuf>,
    /// `--draft-effects`: one recording's, refused here.
    pub draft_effects: Option<PathBuf>,
}

/// The forest plots' page in `--plots DIR`.
pub const PLOTS_PAGE: &str = "explain-across.html";

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
    let target = outputs_allowed(args)?;
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
    let outputs = Outputs {
        plots: args.plots.as_deref(),
        twin: target.as_ref(),
        user: &cx.user,
    };
    report(&explained, args.format, &outputs)
}

/// The options of one recording are refused with several (`--draft-effects`, `--twin`
/// without `--write-twin`), and so is a model's twin of one unit's history or of several
/// models, or written over a run's input: exit 2 before anything is explained. The model's
/// twin's target, when asked.
fn outputs_allowed(args: &Request) -> Result<Option<crate::across_twin::Job>, Exit> {
    use crate::across_twin as twin;
    twin::needs_twin(args.write_twin.as_deref(), args.twin.as_deref())?;
    let one_only = [
        ("--draft-effects", args.draft_effects.is_some()),
        ("--twin", args.twin.is_some() && args.write_twin.is_none()),
    ];
    if let Some((flag, _)) = one_only.iter().find(|(_, given)| *given) {
        let e = miette::miette!(
            code = "explain::one_recording_only",
            help = "explain the recording on its own for {flag}, or leave it out to pool several \
                    (across recordings, --twin is the station file --write-twin writes the \
                    model's twin into)",
            "{flag} applies to one recording, not to several"
        );
        errln!("{e:?}");
        return Err(2);
    }
    if let Some(dir) = &args.plots {
        let runs: Vec<&std::path::Path> = args.runs.iter().map(PathBuf::as_path).collect();
        if let Err(e) =
            ratecal_folder::outputs::refuse_inputs(&dir.join(PLOTS_PAGE), "--plots", &runs)
        {
            errln!("{e:?}");
            return Err(2);
        }
    }
    let (Some(station), Some(out)) = (&args.twin, &args.write_twin) else {
        return Ok(None);
    };
    let target = twin::Target {
        twin: station.clone(),
        out: out.clone(),
    };
    let sel = args.archive.as_ref();
    let serial = sel.and_then(|s| s.serial.as_deref());
    let model = sel.and_then(|s| s.model.as_deref());
    twin::prepare(target, &args.runs, serial, model).map(Some)
}

/// What explain across writes besides its output.
pub struct Outputs<'a> {
    /// `--plots DIR`.
    pub plots: Option<&'a std::path::Path>,
    /// The model's twin.
    pub twin: Option<&'a crate::across_twin::Job>,
    /// The user effects (a pooled one is written by reference to its file).
    pub user: &'a [&'static UserEffect],
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

/// Explains every (name, folder) in parallel (rayon's pool, which each explanation's own
/// passes share), in the order given; the first error in that order is said and ends the
/// command (exit 2).
pub fn explain_all(jobs: &[(String, PathBuf)], cx: &Context) -> Result<Vec<Explained>, Exit> {
    use rayon::prelude::*;
    let done: Vec<Result<Explained, String>> = jobs
        .par_iter()
        .map(|(name, dir)| explain_one(name, dir, cx))
        .collect();
    done.into_iter()
        .map(|r| {
            r.map_err(|e| {
                errln!("{e}");
                2
            })
        })
        .collect()
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

/// Pools the explained recordings, writes the plots and the model's twin when asked,
/// prints the result, returns the exit code.
pub fn report(explained: &[Explained], format: Format, outputs: &Outputs) -> Result<u8, Exit> {
    let members: Vec<across::Member> = explained
        .iter()
        .map(|e| across::Member {
            run: e.run.clone(),
            serial: e.serial.clone(),
            explanation: &e.explanation,
        })
        .collect();
    let a = across::pool(&members, ALPHA);
    let twin = match outputs.twin {
        Some(t) => Some(crate::across_twin::write(t, &a, explained, outputs.user)?),
        None => None,
    };
    let found = explained
        .iter()
        .any(|e| !(e.explanation.findings.is_empty() && e.explanation.unexplained.is_empty()));
    let out = match format {
        Format::Json => json(explained, &a, twin.as_ref()),
        Format::Text => across::render_text(&a) + &twin.as_ref().map(twin_text).unwrap_or_default(),
    };
    crate::console::out(format_args!("{out}"), false);
    if let Some(dir) = outputs.plots {
        write_plots(dir, &a)?;
    }
    // The pool is shown even when the model's twin could not be written.
    if let (Some(t), Some(job)) = (&twin, outputs.twin)
        && let Some(code) = crate::across_twin::say_failed(t, &job.target.out)
    {
        return Err(code);
    }
    Ok(u8::from(found || a.has_finding()))
}

/// The JSON output: `across`, each recording's explanation, the model's twin.
fn json(
    explained: &[Explained],
    a: &across::Across,
    twin: Option<&crate::across_twin::ModelTwin>,
) -> String {
    let recs: Vec<serde_json::Value> = explained
        .iter()
        .map(|e| {
            let mut x = e.explanation.clone();
            // Each recording's own values are in `across`: its profile is not repeated.
            x.profile.clear();
            serde_json::to_value(&x).expect("plain data serializes")
        })
        .collect();
    let mut v = serde_json::json!({
        "format": explain::FORMAT,
        "across": a,
        "explanations": recs,
    });
    if let Some(t) = twin {
        v["twin"] = serde_json::to_value(t).expect("plain data serializes");
    }
    serde_json::to_string_pretty(&v).expect("plain data serializes") + "\n"
}

/// Writes the forest plots' page into `dir` and names it.
fn write_plots(dir: &std::path::Path, a: &across::Across) -> Result<(), Exit> {
    let page = ratecal_render::across_page(a);
    let path = dir.join(PLOTS_PAGE);
    let written = std::fs::create_dir_all(dir)
        .and_then(|()| ratecal_recording::commit::write_nofollow(&path, page.as_bytes()));
    if let Err(e) = written {
        errln!(
            "error: cannot write the forest plots into {}: {e}",
            dir.display()
        );
        return Err(2);
    }
    errln!("figure: {}", path.display());
    Ok(())
}

/// The model's twin in the text output: what it holds, where it was written, its diff.
fn twin_text(t: &crate::across_twin::ModelTwin) -> String {
    let mut s = format!("\nThe model's twin ({}), from {}:\n", t.model, t.station);
    for c in &t.changes {
        s.push_str(&format!(
            "  {}.{}: {} -> {} ± {} {}\n",
            c.effect,
            c.parameter,
            ratecal_drivers::station::number(c.from, c.u),
            ratecal_drivers::station::number(c.to, c.u),
            ratecal_drivers::station::number(c.u, c.u),
            c.unit
        ));
    }
    for n in &t.not_written {
        s.push_str(&format!(
            "  {}.{}: not written: {}\n",
            n.effect, n.parameter, n.why
        ));
    }
    if let Some(w) = &t.written {
        s.push_str(&format!("written to {w}\n"));
    }
    s + t.diff.as_deref().unwrap_or_default()
}
