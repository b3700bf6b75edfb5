//! `ratecal explain RUN_DIR [--procedure PROCEDURE] [--effects FILE_OR_DIR]... [--without ID]...
//! [--twin STATION] [--write-twin OUT.yaml] [--format text|json] [--plots DIR]`: where the
//! recording and the nominal model (or the station's twin) disagree,
//! what physics was left out, the refit with it, and one before/after figure per finding
//! (`explain-<effect>.svg`). Exit codes, like diff(1): 0 nothing found, 1 findings
//! reported, 2 error; 4 the run folder's seal fails (or it was never sealed).

use crate::procedure;
use ratecal_analysis::explain::{self, AdoptTarget, NominalModel, Options, UserEffect};
use ratecal_analysis::fit::{Source, Streamed};
use ratecal_folder::names::EXPLAIN;
use ratecal_physics::Effect;
use ratecal_render as render;
use std::path::{Path, PathBuf};

/// Output format.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// For a person.
    Text,
    /// `ratecal-explain/1` JSON on standard output, nothing else.
    Json,
}

/// What `ratecal explain` is asked (the command's options, docs/explain.md).
pub struct Request {
    /// Recording folder.
    pub run: PathBuf,
    /// Procedure whose fits are the nominal model; adoption becomes a diff against it.
    pub procedure: Option<PathBuf>,
    /// Effect files or folders of them.
    pub effects: Vec<PathBuf>,
    /// Registry effects left out of the candidates.
    pub without: Vec<String>,
    /// Output format.
    pub format: Format,
    /// Accept a released procedure version whose text changed after release.
    pub allow_changed: bool,
    /// Where to write the figures as well.
    pub plots: Option<PathBuf>,
    /// Where to write the draft effect files as well.
    pub draft_effects: Option<PathBuf>,
    /// The station file (or run folder) to compare as the twin.
    pub twin: Option<PathBuf>,
    /// Where to write the corrected twin.
    pub write_twin: Option<PathBuf>,
}

/// The effect files named by `--effects` and `RATECAL_EFFECTS`: files as given, folders
/// by their `*.effect` files in name order.
pub(crate) fn effect_files(args: &[PathBuf]) -> Result<Vec<(String, String)>, String> {
    let env: Vec<PathBuf> = std::env::var_os("RATECAL_EFFECTS")
        .map(|v| {
            std::env::split_paths(&v)
                .filter(|p| !p.as_os_str().is_empty())
                .collect()
        })
        .unwrap_or_default();
    let mut paths = Vec::new();
    for p in env.iter().chain(args) {
        if p.is_dir() {
            let mut inside: Vec<PathBuf> = std::fs::read_dir(p)
                .map_err(|e| format!("cannot read the folder {}: {e}", p.display()))?
                .flatten()
                .map(|e| e.path())
                .filter(|f| f.is_file() && f.extension().is_some_and(|x| x == "effect"))
                .collect();
            inside.sort();
            paths.extend(inside);
        } else {
            paths.push(p.clone());
        }
    }
    paths
        .iter()
        .map(|p| {
            let bytes =
                std::fs::read(p).map_err(|e| format!("cannot read {}: {e}", p.display()))?;
            Ok((
                p.display().to_string(),
                String::from_utf8_lossy(&bytes).into_owned(),
            ))
        })
        .collect()
}

pub(crate) fn load_effects(args: &[PathBuf]) -> Result<Vec<&'static UserEffect>, ()> {
    let files = effect_files(args).map_err(|e| errln!("error: {e}"))?;
    explain::user::load(&files).map_err(|diags| diags.iter().for_each(procedure::report))
}

/// The file a diff is made against: the procedure as resolved, and for a released version
/// the next version's file in the same folder.
fn adopt_target(arg: &Path) -> Option<AdoptTarget> {
    let file = procedure::read(&arg.display().to_string()).ok()?;
    let dir = file.path.parent()?;
    let name = file.path.file_name()?.to_string_lossy().into_owned();
    let lock = std::fs::read_to_string(dir.join(ratecal_audit::versions::LOCK_FILE));
    let next = lock.ok().and_then(|lock| {
        let siblings: Vec<String> = std::fs::read_dir(dir)
            .ok()?
            .flatten()
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .collect();
        let v = explain::next_version(&name, &lock, &siblings)?;
        let path = file.path.with_file_name(format!("{v}.rcal"));
        Some((v, path.display().to_string()))
    });
    Some(AdoptTarget {
        path: file.display,
        text: file.text,
        next,
    })
}

/// A command that stops with this exit code, its diagnostics said.
type Exit = u8;

/// Explains the recording; the exit code of spec/cli.md (0 nothing found, 1 findings, 2
/// error, 4 the seal fails).
pub fn explain(args: &Request) -> u8 {
    match explain_or_exit(args) {
        Ok(code) | Err(code) => code,
    }
}

fn explain_or_exit(args: &Request) -> Result<u8, Exit> {
    crate::across_twin::needs_twin(args.write_twin.as_deref(), args.twin.as_deref())?;
    // An output never replaces an input (a recording, a seal, a recorded file): exit 2.
    if let Some(out) = &args.write_twin
        && let Err(e) =
            ratecal_folder::outputs::refuse_inputs(out, "--write-twin", &[args.run.as_path()])
    {
        errln!("{e:?}");
        return Err(2);
    }
    // A folder whose seal fails (or a run never sealed) is not explained, and its seal
    // gains nothing (exit 4, as `report`). The seal is checked beside the reading: nothing
    // is shown or written before it has passed, and its failure outranks any other.
    // A corrected twin is written as the explanation is computed: its seal check comes first.
    let run = args.run.clone();
    let check = move || {
        ratecal_folder::verify::require_intact(&run, "explanation").map_err(|e| format!("{e:?}"))
    };
    let failed = |e: String| {
        errln!("{e}");
        Err(4)
    };
    let computed = if args.write_twin.is_some() {
        check().or_else(failed)?;
        open_and_compute(args)
    } else {
        let seal = std::thread::spawn(check);
        let computed = open_and_compute(args);
        (seal.join())
            .unwrap_or_else(|_| Err("the seal check failed".into()))
            .or_else(failed)?;
        computed
    };
    let (rec, _lock, (mut x, twin, twin_failed)) = computed?;
    let in_run = rec.manifest().run.is_some();
    adopt(args, &mut x);
    let drafts = drafts(args, in_run, &mut x);
    let mut value = serde_json::to_value(&x).expect("plain data serializes");
    if let Some(r) = &twin {
        value["twin"] = serde_json::to_value(r).expect("plain data serializes");
    }
    let json = serde_json::to_string_pretty(&value).expect("plain data serializes");
    let figures = figures(&x, twin.is_some(), &value);
    // Kept in a ratecal run folder (not in another system's recording): its report shows it.
    if in_run {
        let mut files = vec![(EXPLAIN.to_string(), format!("{json}\n"))];
        files.extend(drafts.iter().cloned());
        files.extend(figures.iter().cloned());
        if let Err(e) = write(&args.run, &files, true) {
            errln!("warning: cannot keep explain.json and its figures in the run folder: {e}");
        }
    }
    if let Some(dir) = &args.plots {
        write_beside(
            dir,
            &figures,
            in_run && same_dir(dir, &args.run),
            ("figure", "the figures"),
        )?;
    }
    if let Some(dir) = &args.draft_effects
        && !(in_run && same_dir(dir, &args.run))
        && !drafts.is_empty()
    {
        write_beside(
            dir,
            &drafts,
            false,
            ("draft effect", "the draft effect files"),
        )?;
    }
    let out = match args.format {
        Format::Json => json + "\n",
        Format::Text => {
            explain::render_text(&x)
                + &twin
                    .as_ref()
                    .map(ratecal_analysis::twin::render_text)
                    .unwrap_or_default()
        }
    };
    crate::console::out(format_args!("{out}"), false);
    // The explanation is shown even when the corrected twin could not be written.
    if let Some(why) = twin_failed {
        let out = args.write_twin.as_deref().unwrap_or(Path::new(""));
        let e = miette::miette!(
            code = "explain::twin_not_written",
            help = "the explanation above stands; fix what is named and run explain again \
                    with --write-twin (or write the changes listed above by hand)",
            "the corrected twin \"{}\" was not written: {why}",
            out.display()
        );
        errln!("{e:?}");
        return Err(2);
    }
    Ok(match &twin {
        Some(r) => u8::from(r.needs_change),
        // What the run's own procedure already holds is nothing to add.
        None => u8::from(
            (x.findings.iter()).any(|f| !x.already_held.contains(&f.effect))
                || !x.unexplained.is_empty(),
        ),
    })
}

/// What [`compute`] gives: the explanation, the twin's report, and why the corrected twin
/// was not written.
type Computed = (
    explain::Explanation,
    Option<ratecal_analysis::twin::TwinReport>,
    Option<String>,
);

/// The recording opened (a ratecal run folder locked) and explained.
fn open_and_compute(
    args: &Request,
) -> Result<(Streamed, Option<ratecal_folder::lock::FolderLock>, Computed), Exit> {
    // The IMU stream is read a window at a time (`fit::Streamed`), as `analyze` reads it.
    let rec = Streamed::open(&args.run).map_err(|e| {
        errln!("{:?}", miette::Report::new(e));
        2
    })?;
    // A ratecal run folder gains explain.json: its lock first, so a second writer is
    // refused at once (exit 2, an error as spec/cli.md has it for explain).
    let lock = match rec.manifest().run.is_some() {
        true => Some(
            ratecal_folder::lock::acquire(&args.run, &ratecal_folder::sealing::command_line())
                .map_err(|e| {
                    errln!("{e:?}");
                    2
                })?,
        ),
        false => None,
    };
    let computed = compute(args, &rec)?;
    Ok((rec, lock, computed))
}

/// The explanation, against the nominal model or the station's twin (with the corrected
/// twin written when asked).
fn compute(args: &Request, rec: &Streamed) -> Result<Computed, Exit> {
    let mut user = load_effects(&args.effects).map_err(|()| 2)?;
    let nominal = match &args.procedure {
        None => NominalModel::seed(),
        Some(p) => {
            let (plan, _) = crate::analyze::load_plan(p, args.allow_changed).map_err(|()| 2)?;
            NominalModel::from_plan(&plan, rec.manifest().station.site.latitude_deg)
        }
    };
    let twin_file = args
        .twin
        .as_ref()
        .map(|p| twin_file(p, rec, &mut user))
        .transpose()?;
    let opts = Options {
        path: args.run.display().to_string(),
        user,
        without: args.without.clone(),
        ..Options::default()
    };
    let explained = match &twin_file {
        None => explain::explain_source(rec, &nominal, &opts).map(|x| (x, None)),
        Some(f) => {
            let twin = crate::twin::twin_of(&f.station);
            ratecal_analysis::twin::compare_source(rec, &twin, &opts).map(|(x, r)| (x, Some(r)))
        }
    };
    let (mut x, mut twin) = explained.map_err(|e| {
        errln!("{:?}", miette::Report::new(e));
        2
    })?;
    if args.procedure.is_none() && twin.is_none() {
        held_by_the_run(&args.run, rec, &mut x);
    }
    let mut failed = None;
    if let (Some(f), Some(r)) = (&twin_file, &mut twin) {
        r.station = args
            .twin
            .as_ref()
            .map(|p| p.display().to_string())
            .unwrap_or_default();
        if let Some(out) = &args.write_twin {
            failed = write_twin(f, &x, r, out, &args.run).err();
        }
    }
    Ok((x, twin, failed))
}

/// A run folder's own procedure (its `plan.json`): the findings it already holds are not
/// to be added (`already_held`). A folder without one (an import) is left as it is.
pub(crate) fn held_by_the_run(run: &Path, rec: &Streamed, x: &mut explain::Explanation) {
    let plan = std::fs::read_to_string(run.join(ratecal_folder::names::PLAN))
        .ok()
        .and_then(|t| serde_json::from_str::<ratecal_analysis::plan::Plan>(&t).ok());
    if let Some(plan) = plan {
        let lat = rec.manifest().station.site.latitude_deg;
        explain::mark_held(x, &NominalModel::from_plan(&plan, lat));
    }
}

/// The twin's station file, read and held against the manifest; its user effects join
/// explain's candidates (its terms need their columns; one given with --effects is that one).
fn twin_file(
    path: &Path,
    rec: &Streamed,
    user: &mut Vec<&'static UserEffect>,
) -> Result<crate::twin::TwinFile, Exit> {
    let f = crate::twin::read(path).map_err(|()| 2)?;
    if let Err(e) = crate::twin::refuse(&f, rec.manifest()) {
        errln!("{:?}", miette::Report::new(*e));
        return Err(2);
    }
    for e in &f.user {
        if !user.iter().any(|u| u.id() == e.id()) {
            user.push(e);
        }
    }
    Ok(f)
}

/// Writes the corrected twin at `out` with the draft effects of discovered physics beside
/// it (referenced from it), and records both in the report; else why not (the draft
/// effects it wrote are removed again, and the report names no file it did not write).
fn write_twin(
    f: &crate::twin::TwinFile,
    x: &explain::Explanation,
    r: &mut ratecal_analysis::twin::TwinReport,
    out: &Path,
    run: &Path,
) -> Result<(), String> {
    let before = r.changes.clone();
    let undo = |r: &mut ratecal_analysis::twin::TwinReport| {
        for c in &r.changes {
            let new = before.iter().all(|b| b.defined_in != c.defined_in);
            if let (true, Some(d)) = (new, &c.defined_in) {
                std::fs::remove_file(d).ok();
            }
        }
        r.changes = before.clone();
    };
    if let Err(e) = crate::twin::write_drafts(x, &mut r.changes, out, run) {
        undo(r);
        return Err(format!("the draft effect beside it cannot be written: {e}"));
    }
    let corrected = crate::twin::corrected(f, &r.changes, out, "")
        .map_err(|e| format!("the twin cannot be corrected: {e}"))
        .and_then(|(text, diff)| {
            ratecal_recording::commit::write_nofollow(out, text.as_bytes())
                .map(|()| diff)
                .map_err(|e| format!("{e}"))
        });
    let diff = match corrected {
        Ok(d) => d,
        Err(e) => {
            undo(r);
            return Err(e);
        }
    };
    r.written = Some(out.display().to_string());
    r.diff = Some(diff);
    Ok(())
}

/// With `--procedure`, the diff that declares the registry's findings in it (only the
/// registry's effects can be declared in a procedure).
fn adopt(args: &Request, x: &mut explain::Explanation) {
    let ids: Vec<String> = x
        .findings
        .iter()
        .filter(|f| f.defined_in.is_none() && !f.discovered && explain::beyond_zero(f))
        .map(|f| f.effect.clone())
        .collect();
    let Some(p) = &args.procedure else { return };
    if ids.is_empty() {
        return;
    }
    let ids: Vec<&str> = ids.iter().map(String::as_str).collect();
    match adopt_target(p).map(|t| explain::adoption(&t, &ids)) {
        Some(Ok(a)) => {
            x.adopt_diff = a.diff;
            for id in a.not_placed {
                x.warnings.push(format!(
                    "{id}: the procedure has no fit statement of the sensors it acts on to declare it"
                ));
            }
        }
        Some(Err(e)) => x.warnings.push(format!("no adoption diff: {e}")),
        None => x.warnings.push(format!(
            "no adoption diff: {} is not a procedure file",
            p.display()
        )),
    }
}

/// The draft effect file (name, text) of every discovered finding, listed in the
/// explanation where they will be written.
fn drafts(args: &Request, in_run: bool, x: &mut explain::Explanation) -> Vec<(String, String)> {
    let drafts: Vec<(String, String)> = x
        .findings
        .iter()
        .filter_map(|f| {
            let text = explain::draft::effect_file(f, &args.run.display().to_string())?;
            Some((explain::draft::file_name(f), text))
        })
        .collect();
    let dir = args
        .draft_effects
        .clone()
        .or(in_run.then(|| args.run.clone()));
    if let Some(dir) = &dir {
        let listed: Vec<explain::UserEffectOut> = x
            .findings
            .iter()
            .filter(|f| f.discovered)
            .zip(&drafts)
            .map(|(f, (name, _))| explain::UserEffectOut {
                effect: f.effect.clone(),
                file: dir.join(name).display().to_string(),
            })
            .collect();
        x.draft_effects.extend(listed);
    }
    drafts
}

/// Each finding's before/after figure, the twin's residual figure and its time series, as
/// files (name, text).
fn figures(
    x: &explain::Explanation,
    with_twin: bool,
    value: &serde_json::Value,
) -> Vec<(String, String)> {
    let mut figures: Vec<(String, String)> =
        render::explain_figures(&serde_json::to_value(x).expect("plain data serializes"))
            .into_iter()
            .filter_map(|(effect, svg)| Some((format!("explain-{effect}.svg"), svg?)))
            .collect();
    if let Some(svg) = with_twin
        .then(|| render::twin_residual_figure(value))
        .flatten()
    {
        figures.push(("explain-twin.svg".into(), svg));
    }
    // The twin's time series, one figure per kind of segment where it disagrees.
    for (kind, svg) in render::twin_figures(value) {
        figures.push((format!("explain-twin-{kind}.svg"), svg));
    }
    figures
        .into_iter()
        .map(|(n, svg)| (n, format!("{svg}\n")))
        .collect()
}

/// Writes `files` into `dir` (unless `same`: it is the run folder, which has them) and
/// names each; `what` is one file and all of them, in words.
fn write_beside(
    dir: &Path,
    files: &[(String, String)],
    same: bool,
    what: (&str, &str),
) -> Result<(), Exit> {
    let (one, all) = what;
    if !same && let Err(e) = write(dir, files, false) {
        errln!("error: cannot write {all} into {}: {e}", dir.display());
        return Err(2);
    }
    for (name, _) in files {
        errln!("{one}: {}", dir.join(name).display());
    }
    Ok(())
}

/// Writes `files` (name, text) into `dir`; in a sealed run folder (`seal`), records them as
/// one addition to its seal.
fn write(dir: &Path, files: &[(String, String)], seal: bool) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    if !seal {
        for (name, text) in files {
            ratecal_recording::commit::write_nofollow(&dir.join(name), text.as_bytes())?;
        }
        return Ok(());
    }
    let bytes: Vec<(String, Vec<u8>)> = files
        .iter()
        .map(|(n, t)| (n.clone(), t.clone().into_bytes()))
        .collect();
    use ratecal_folder::names::{IMU, MANIFEST, STATION, TABLE};
    ratecal_folder::sealing::write_files(
        dir,
        &bytes,
        &ratecal_folder::sealing::command_line(),
        &[MANIFEST, IMU, TABLE, STATION],
    )?;
    Ok(())
}

fn same_dir(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}
