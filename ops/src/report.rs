//! `ratecal report RUN_DIR [--template FILE_OR_DIR] [--format md|html] [--out FILE]`:
//! renders a calibration report from a run folder (results.json, manifest.yaml, and the
//! streams for the temperature plot). Also `write_reports`, which `ratecal run` calls to
//! write report.md and report.html into the run folder.
//!
//! Exit codes: 0 report written, 1 input error (no run folder, no or bad results.json or
//! manifest, template error), 2 usage, 4 the folder's seal fails (or a run folder was never
//! sealed).

use ratecal_folder::names::MANIFEST;
use ratecal_folder::{ReadError, RunFolder};
use ratecal_plan::Plan;
use ratecal_render::{self as render, Format, ReportInput, TemperatureSeries, Templates};
use std::path::{Path, PathBuf};

/// Report format.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FormatArg {
    /// Markdown.
    Md,
    /// Self-contained HTML with inline SVG plots.
    Html,
}

/// What `ratecal report` is asked.
pub struct Request {
    /// Run folder.
    pub run_dir: PathBuf,
    /// A template file, or a directory of templates overriding the bundled ones by name.
    pub template: Option<PathBuf>,
    /// Report format.
    pub format: FormatArg,
    /// Where to write it (standard output without it).
    pub out: Option<PathBuf>,
    /// The lab's archive, for the unit's trend.
    pub archive: Option<String>,
}

/// Renders the report; the exit code of spec/cli.md.
pub fn report(args: &Request) -> u8 {
    // A folder whose seal fails (or a run never sealed) gets no report, and its seal no
    // addition (spec/cli.md: exit 4).
    if args.run_dir.is_dir()
        && let Err(e) = ratecal_folder::verify::require_intact_replacing(
            &args.run_dir,
            "report",
            &[crate::analyze::out_name(args.out.as_deref()).as_str()],
        )
    {
        errln!("{e:?}");
        return 4;
    }
    match render_report(args) {
        Ok(()) => 0,
        Err(e) => {
            errln!("{e:?}");
            1
        }
    }
}

fn render_report(args: &Request) -> miette::Result<()> {
    // An output never replaces an input (a recording, a seal, a recorded file).
    if let Some(out) = &args.out {
        ratecal_folder::outputs::refuse_inputs(out, "--out", &[args.run_dir.as_path()])?;
    }
    // Writing into a run folder: its lock first, so a second writer is refused at once.
    let _lock = match &args.out {
        Some(out) => ratecal_folder::lock::for_file(out, &ratecal_folder::sealing::command_line())?,
        None => None,
    };
    let mut input = read_run(&args.run_dir)?;
    let serial = serial_of(&input);
    input.archive_trend = crate::archive::trend_json(args.archive.as_deref(), serial.as_deref());
    let mut templates = Templates::bundled();
    let format = match args.format {
        FormatArg::Md => Format::Markdown,
        FormatArg::Html => Format::Html,
    };
    let mut name = format.file_name().to_string();
    match &args.template {
        Some(p) if p.is_dir() => add_template_dir(&mut templates, p)?,
        Some(p) => name = add_template_file(&mut templates, p)?,
        None => {}
    }
    let text = render::render_template(&input, &templates, &name)?;
    match &args.out {
        Some(out) => {
            // A report written into a sealed run folder joins the seal, with the command,
            // in one committed change.
            // Computed from these files of the run folder (when it is written into).
            use ratecal_folder::names::{MANIFEST, PLAN, RESULTS};
            let into_run = out.parent().is_some_and(|p| {
                std::fs::canonicalize(if p.as_os_str().is_empty() {
                    Path::new(".")
                } else {
                    p
                })
                .ok()
                    == std::fs::canonicalize(&args.run_dir).ok()
            });
            let read: &[&str] = if into_run {
                &[RESULTS, MANIFEST, PLAN]
            } else {
                &[]
            };
            ratecal_folder::sealing::write_file(
                out,
                text.into_bytes(),
                &ratecal_folder::sealing::command_line(),
                read,
            )
            .map_err(|e| io(out, e, "check that the folder exists and is writable"))?;
        }
        None => crate::console::out(format_args!("{text}"), false),
    }
    Ok(())
}

/// Writes `report.md` and `report.html` into `run_dir` from `input`, with the bundled
/// templates overridden by `template_dir`'s files if given. Returns the paths written.
/// `ratecal run` calls this after the analysis (build `input` with
/// `ReportInput::from_run`).
pub fn write_reports(
    run_dir: &Path,
    input: &ReportInput,
    template_dir: Option<&Path>,
) -> miette::Result<Vec<PathBuf>> {
    let mut templates = Templates::bundled();
    if let Some(dir) = template_dir {
        add_template_dir(&mut templates, dir)?;
    }
    let mut written = vec![];
    for r in render::render_all(input, &templates)? {
        let path = run_dir.join(&r.file_name);
        ratecal_recording::commit::write_nofollow(&path, r.text.as_bytes())
            .map_err(|e| io(&path, e, "check that the run folder is writable"))?;
        written.push(path);
    }
    Ok(written)
}

/// The IMU serial a run's manifest names (a YAML number such as `1234` too).
pub fn serial_of(input: &ReportInput) -> Option<String> {
    RunFolder::serial_of(input.manifest.as_ref()?)
}

/// Reads what a report needs from a run folder: results.json (required), manifest.yaml
/// (validated, kept whole so lab-specific keys reach the templates), `plan.json` if the
/// run saved one, and the temperature columns of the streams when they can be read.
pub fn read_run(dir: &Path) -> miette::Result<ReportInput> {
    if !dir.is_dir() {
        return Err(ReadError::io(
            dir,
            "not a folder",
            "give the run folder that `ratecal run` wrote",
        )
        .into());
    }
    let folder = RunFolder::new(dir);
    let results = folder.results()?;
    let manifest = match folder.manifest("the manifest follows spec/recording-format.md") {
        Ok((text, _)) => Some(
            serde_saphyr::from_str::<serde_json::Value>(&text).map_err(|e| {
                ReadError::io(
                    &folder.path(MANIFEST),
                    e,
                    "the manifest follows spec/recording-format.md",
                )
            })?,
        ),
        Err(_) if !folder.path(MANIFEST).exists() => None,
        Err(e) => return Err(e),
    };
    let plan: Option<Plan> = folder.plan_checked()?;
    // The temperature plot is a nicety: a recording whose streams cannot be read still
    // gets its report, from results.json alone.
    let temperature = ratecal_analysis::fit::Streamed::open(dir)
        .ok()
        .and_then(|rec| TemperatureSeries::from_source(&rec).ok())
        .unwrap_or_default();
    Ok(ReportInput {
        results,
        manifest,
        plan,
        temperature,
        ratecal_version: env!("CARGO_PKG_VERSION").to_string(),
        // `ratecal explain` keeps its findings beside the run: the report gains a section.
        explain: folder.explain(),
        archive_trend: None,
    })
}

fn add_template_dir(templates: &mut Templates, dir: &Path) -> miette::Result<()> {
    let entries =
        std::fs::read_dir(dir).map_err(|e| io(dir, e, "give a folder of template files"))?;
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_file() {
            add_template_file(templates, &path)?;
        }
    }
    Ok(())
}

/// Adds one template file under its file name; returns that name.
fn add_template_file(templates: &mut Templates, path: &Path) -> miette::Result<String> {
    let text = std::fs::read_to_string(path).map_err(|e| {
        io(
            path,
            e,
            "a template is a UTF-8 text file (report.md, report.html...)",
        )
    })?;
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    templates.insert(&name, text, path.display().to_string());
    Ok(name)
}

fn io(path: &Path, e: impl std::fmt::Display, help: &str) -> ReadError {
    ReadError::io(path, e, help)
}
