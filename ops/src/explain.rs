//! `ratecal explain RUN_DIR [--procedure PROCEDURE] [--effects FILE_OR_DIR]... [--without ID]...
//! [--twin STATION] [--write-twin OUT.yaml] [--format text|json] [--plots DIR]`: where the
//! recording and the nominal model (or the station's twin) disagree,
//! what physics was left out, the refit with it, and one before/after figure per finding
//! (`explain-<effect>.svg`). Exit codes, like diff(1): 0 nothing found, 1 findings
//! reported, 2 error; 4 the run folder's seal fails (or it was never sealed).

use crate::procedure;
use ratecal_analysis::explain::{self, AdoptTarget, NominalModel, Options, UserEffect};
use ratecal_analysis::fit::{Source, Streamed};
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
fn effect_files(args: &[PathBuf]) -> Result<Vec<(String, String)>, String> {
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

fn load_effects(args: &[PathBuf]) -> Result<Vec<&'static UserEffect>, ()> {
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

/// Explains the recording; the exit code of spec/cli.md (0 nothing found, 1 findings, 2
/// error, 4 the seal fails).
pub fn explain(args: &Request) -> u8 {
    // A folder whose seal fails (or a run never sealed) is not explained, and its seal
    // gains nothing (exit 4, as `report`).
    if let Err(e) = ratecal_folder::verify::require_intact(&args.run, "explanation") {
        errln!("{e:?}");
        return 4;
    }
    // The IMU stream is read a window at a time (`fit::Streamed`), as `analyze` reads it.
    let rec = match Streamed::open(&args.run) {
        Ok(r) => r,
        Err(e) => {
            errln!("{:?}", miette::Report::new(e));
            return 2;
        }
    };
    // A ratecal run folder gains explain.json: its lock first, so a second writer is
    // refused at once (exit 2, an error as spec/cli.md has it for explain).
    let _lock = if rec.manifest().run.is_some() {
        match ratecal_folder::lock::acquire(&args.run, &ratecal_folder::sealing::command_line()) {
            Ok(l) => Some(l),
            Err(e) => {
                errln!("{e:?}");
                return 2;
            }
        }
    } else {
        None
    };
    let Ok(mut user) = load_effects(&args.effects) else {
        return 2;
    };
    let nominal = match &args.procedure {
        None => NominalModel::seed(),
        Some(p) => match crate::analyze::load_plan(p, args.allow_changed) {
            Ok((plan, _)) => {
                NominalModel::from_plan(&plan, rec.manifest().station.site.latitude_deg)
            }
            Err(()) => return 2,
        },
    };
    let twin_file = match &args.twin {
        None => None,
        Some(p) => {
            let Ok(f) = crate::twin::read(p) else {
                return 2;
            };
            if let Err(e) = crate::twin::refuse(&f, rec.manifest()) {
                errln!("{:?}", miette::Report::new(*e));
                return 2;
            }
            // The twin's user effects are explain's candidates too (its terms need their
            // columns); one already given with --effects is that one.
            for e in &f.user {
                if !user.iter().any(|u| u.id() == e.id()) {
                    user.push(e);
                }
            }
            Some(f)
        }
    };
    let opts = Options {
        path: args.run.display().to_string(),
        user,
        without: args.without.clone(),
        ..Options::default()
    };
    let explained = match &twin_file {
        None => explain::explain_source(&rec, &nominal, &opts).map(|x| (x, None)),
        Some(f) => {
            let twin = crate::twin::twin_of(&f.station);
            ratecal_analysis::twin::compare_source(&rec, &twin, &opts).map(|(x, r)| (x, Some(r)))
        }
    };
    let (mut x, mut twin) = match explained {
        Ok(x) => x,
        Err(e) => {
            errln!("{:?}", miette::Report::new(e));
            return 2;
        }
    };
    if let (Some(f), Some(r)) = (&twin_file, &mut twin) {
        r.station = args
            .twin
            .as_ref()
            .map(|p| p.display().to_string())
            .unwrap_or_default();
        if let Some(out) = &args.write_twin {
            // Discovered physics joins the twin as its draft effect file, written beside
            // the corrected twin and referenced from it.
            if let Err(e) = crate::twin::write_drafts(&x, &mut r.changes, out, &args.run) {
                errln!(
                    "error: cannot write the draft effect beside {}: {e}",
                    out.display()
                );
                return 2;
            }
            match crate::twin::corrected(f, &r.changes, out) {
                Ok((text, diff)) => {
                    if let Err(e) = std::fs::write(out, &text) {
                        errln!(
                            "error: cannot write the corrected twin {}: {e}",
                            out.display()
                        );
                        return 2;
                    }
                    r.written = Some(out.display().to_string());
                    r.diff = Some(diff);
                }
                Err(e) => {
                    errln!("error: cannot correct the twin: {e}");
                    return 2;
                }
            }
        }
    }
    // Only the registry's effects can be declared in a procedure.
    let ids: Vec<String> = x
        .findings
        .iter()
        .filter(|f| f.defined_in.is_none() && !f.discovered)
        .map(|f| f.effect.clone())
        .collect();
    if let Some(p) = &args.procedure
        && !ids.is_empty()
    {
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
    let in_run = rec.manifest().run.is_some();
    let drafts: Vec<(String, String)> = x
        .findings
        .iter()
        .filter_map(|f| {
            let text = explain::draft::effect_file(f, &args.run.display().to_string())?;
            Some((explain::draft::file_name(f), text))
        })
        .collect();
    let draft_dir = args
        .draft_effects
        .clone()
        .or(in_run.then(|| args.run.clone()));
    if let Some(dir) = &draft_dir {
        for (f, (name, _)) in x.findings.iter().filter(|f| f.discovered).zip(&drafts) {
            x.draft_effects.push(explain::UserEffectOut {
                effect: f.effect.clone(),
                file: dir.join(name).display().to_string(),
            });
        }
    }
    let mut value = serde_json::to_value(&x).expect("plain data serializes");
    if let Some(r) = &twin {
        value["twin"] = serde_json::to_value(r).expect("plain data serializes");
    }
    let json = serde_json::to_string_pretty(&value).expect("plain data serializes");
    let mut figures: Vec<(String, String)> =
        render::explain_figures(&serde_json::to_value(&x).expect("plain data serializes"))
            .into_iter()
            .filter_map(|(effect, svg)| Some((format!("explain-{effect}.svg"), svg?)))
            .collect();
    if let Some(svg) = twin
        .as_ref()
        .and_then(|_| render::twin_residual_figure(&value))
    {
        figures.push(("explain-twin.svg".into(), svg));
    }
    // The twin's time series, one figure per kind of segment where it disagrees.
    for (kind, svg) in render::twin_figures(&value) {
        figures.push((format!("explain-twin-{kind}.svg"), svg));
    }
    // Kept in a ratecal run folder (not in another system's recording): its report shows it.
    if in_run {
        let mut files = vec![("explain.json".to_string(), format!("{json}\n"))];
        files.extend(drafts.iter().cloned());
        files.extend(
            figures
                .iter()
                .map(|(n, svg)| (n.clone(), format!("{svg}\n"))),
        );
        if let Err(e) = write(&args.run, &files, true) {
            errln!("warning: cannot keep explain.json and its figures in the run folder: {e}");
        }
    }
    if let Some(dir) = &args.plots {
        let same = in_run && same_dir(dir, &args.run);
        let files: Vec<(String, String)> = figures
            .iter()
            .map(|(n, svg)| (n.clone(), format!("{svg}\n")))
            .collect();
        if !same && let Err(e) = write(dir, &files, false) {
            errln!(
                "error: cannot write the figures into {}: {e}",
                dir.display()
            );
            return 2;
        }
        for (name, _) in &files {
            errln!("figure: {}", dir.join(name).display());
        }
    }
    if let Some(dir) = &args.draft_effects
        && !(in_run && same_dir(dir, &args.run))
        && !drafts.is_empty()
    {
        if let Err(e) = write(dir, &drafts, false) {
            errln!(
                "error: cannot write the draft effect files into {}: {e}",
                dir.display()
            );
            return 2;
        }
        for (name, _) in &drafts {
            errln!("draft effect: {}", dir.join(name).display());
        }
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
    if let Some(r) = &twin {
        return if r.needs_change { 1 } else { 0 };
    }
    if x.findings.is_empty() && x.unexplained.is_empty() {
        0
    } else {
        1
    }
}

/// Writes `files` (name, text) into `dir`; in a sealed run folder (`seal`), records them as
/// one addition to its seal.
fn write(dir: &Path, files: &[(String, String)], seal: bool) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    if !seal {
        for (name, text) in files {
            std::fs::write(dir.join(name), text)?;
        }
        return Ok(());
    }
    let bytes: Vec<(String, Vec<u8>)> = files
        .iter()
        .map(|(n, t)| (n.clone(), t.clone().into_bytes()))
        .collect();
    ratecal_folder::sealing::write_files(dir, &bytes, &ratecal_folder::sealing::command_line())?;
    Ok(())
}

fn same_dir(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}
