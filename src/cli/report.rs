//! `ratecal report RUN_DIR [--template FILE_OR_DIR] [--format md|html] [--out FILE]`:
//! renders a calibration report from a run folder (results.json, manifest.yaml, and the
//! streams for the temperature plot). Also `write_reports`, which `ratecal run` calls to
//! write report.md and report.html into the run folder.
//!
//! Exit codes: 0 report written, 1 input error (no run folder, no or bad results.json or
//! manifest, template error), 2 usage, 4 the folder's seal fails (or a run folder was never
//! sealed).

use miette::{Diagnostic, NamedSource, SourceSpan};
use ratecal_plan::Plan;
use ratecal_render::{self as render, Format, ReportInput, TemperatureSeries, Templates};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Arguments of `ratecal report`.
#[derive(clap::Args)]
pub struct Args {
    /// Run folder (results.json and manifest.yaml; imu.csv and table.csv for temperatures).
    run_dir: PathBuf,
    /// A template file, or a directory whose files override the bundled templates by name
    /// (`report.md`, `report.html`, `report.css`).
    #[arg(long, value_name = "FILE_OR_DIR")]
    template: Option<PathBuf>,
    /// Report format (bundled templates, or a template directory's `report.<format>`).
    #[arg(long, value_enum, default_value_t = FormatArg::Md)]
    format: FormatArg,
    /// Write the report here instead of standard output.
    #[arg(long, value_name = "FILE")]
    out: Option<PathBuf>,
    /// The lab's archive (folder or postgres:// URL; also $RATECAL_ARCHIVE): the report's
    /// conclusions then use the unit's trend across the calibrations it holds.
    #[arg(long, value_name = "DIR_OR_URL")]
    archive: Option<String>,
}

/// `--format`.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum FormatArg {
    /// Markdown.
    Md,
    /// Self-contained HTML with inline SVG plots.
    Html,
}

/// An input problem, located where possible.
#[derive(Debug, thiserror::Error, Diagnostic)]
enum InputError {
    #[error("cannot read {path}: {message}")]
    #[diagnostic(code(report::io), help("{help}"))]
    Io {
        path: String,
        message: String,
        help: String,
    },
    #[error("{file} is not valid JSON: {message}")]
    #[diagnostic(
        code(report::results_json),
        help("results.json is written by `ratecal analyze RUN_DIR`")
    )]
    Json {
        file: String,
        message: String,
        #[source_code]
        src: NamedSource<String>,
        #[label("{message}")]
        span: SourceSpan,
    },
}

/// Runs the subcommand.
pub fn main(args: Args) -> ExitCode {
    // A folder whose seal fails (or a run never sealed) gets no report, and its seal no
    // addition (spec/cli.md: exit 4).
    if args.run_dir.is_dir()
        && let Err(e) = ratecal_folder::verify::require_intact(&args.run_dir, "report")
    {
        errln!("{e:?}");
        return ExitCode::from(4);
    }
    match report(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            errln!("{e:?}");
            ExitCode::from(1)
        }
    }
}

fn report(args: &Args) -> miette::Result<()> {
    // Writing into a run folder: its lock first, so a second writer is refused at once.
    let _lock = match &args.out {
        Some(out) => ratecal_folder::lock::for_file(out, &ratecal_folder::sealing::command_line())?,
        None => None,
    };
    let mut input = read_run(&args.run_dir)?;
    let serial = serial_of(&input);
    input.archive_trend = super::archive::trend_json(args.archive.as_deref(), serial.as_deref());
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
            ratecal_folder::sealing::write_file(
                out,
                text.into_bytes(),
                &ratecal_folder::sealing::command_line(),
            )
            .map_err(|e| io(out, e, "check that the folder exists and is writable"))?;
        }
        None => out!("{text}"),
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
        std::fs::write(&path, r.text)
            .map_err(|e| io(&path, e, "check that the run folder is writable"))?;
        written.push(path);
    }
    Ok(written)
}

/// The IMU serial a run's manifest names (a YAML number such as `1234` too).
pub fn serial_of(input: &ReportInput) -> Option<String> {
    match input.manifest.as_ref()?.get("imu")?.get("serial")? {
        serde_json::Value::String(s) => Some(s.clone()),
        serde_json::Value::Number(n) => Some(n.to_string()),
        _ => None,
    }
}

/// Reads what a report needs from a run folder: results.json (required), manifest.yaml
/// (validated, kept whole so lab-specific keys reach the templates), `plan.json` if the
/// run saved one, and the temperature columns of the streams when they can be read.
pub fn read_run(dir: &Path) -> miette::Result<ReportInput> {
    if !dir.is_dir() {
        return Err(io(
            dir,
            "not a folder",
            "give the run folder that `ratecal run` wrote",
        )
        .into());
    }
    let results_path = dir.join("results.json");
    let text = std::fs::read_to_string(&results_path).map_err(|e| {
        io(
            &results_path,
            e,
            "run `ratecal analyze RUN_DIR` first to write results.json",
        )
    })?;
    let results = serde_json::from_str(&text).map_err(|e| json_error(&results_path, &text, &e))?;

    let manifest_path = dir.join("manifest.yaml");
    let manifest = match std::fs::read_to_string(&manifest_path) {
        Ok(text) => {
            let file = manifest_path.display().to_string();
            ratecal_recording::parse_manifest(&file, &text)?;
            Some(
                serde_saphyr::from_str::<serde_json::Value>(&text).map_err(|e| {
                    io(
                        &manifest_path,
                        e,
                        "the manifest follows spec/recording-format.md",
                    )
                })?,
            )
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => None,
        Err(e) => return Err(io(&manifest_path, e, "check the file's permissions").into()),
    };
    let plan_path = dir.join("plan.json");
    let plan: Option<Plan> = match std::fs::read_to_string(&plan_path) {
        Ok(text) => {
            Some(serde_json::from_str(&text).map_err(|e| json_error(&plan_path, &text, &e))?)
        }
        Err(_) => None,
    };
    // The temperature plot is a nicety: a recording whose streams cannot be read still
    // gets its report, from results.json alone.
    let temperature = ratecal_analysis::fit::Streamed::open(dir)
        .ok()
        .and_then(|rec| TemperatureSeries::from_source(&rec).ok())
        .unwrap_or_default();
    // `ratecal explain` keeps its findings beside the run: the report gains a section.
    let explain = std::fs::read_to_string(dir.join("explain.json"))
        .ok()
        .and_then(|t| serde_json::from_str(&t).ok());
    Ok(ReportInput {
        results,
        manifest,
        plan,
        temperature,
        ratecal_version: env!("CARGO_PKG_VERSION").to_string(),
        explain,
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

fn io(path: &Path, e: impl std::fmt::Display, help: &str) -> InputError {
    InputError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
        help: help.into(),
    }
}

fn json_error(path: &Path, text: &str, e: &serde_json::Error) -> InputError {
    let offset: usize = text
        .split_inclusive('\n')
        .take(e.line().saturating_sub(1))
        .map(str::len)
        .sum::<usize>()
        + e.column().saturating_sub(1);
    let file = path.display().to_string();
    InputError::Json {
        file: file.clone(),
        message: e.to_string(),
        src: NamedSource::new(file, text.to_string()),
        span: (offset.min(text.len()), 1).into(),
    }
}
