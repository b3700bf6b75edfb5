//! `ratecal explain RUN_DIR [--procedure PROCEDURE] [--format text|json] [--plots DIR]`:
//! where the recording and the nominal model disagree, what physics was left out, the refit
//! with it, and one before/after figure per finding (`explain-<effect>.svg`). Exit codes,
//! like diff(1): 0 nothing found, 1 findings reported, 2 error.

use ratecal_engine::explain::{self, NominalModel, Options};
use ratecal_engine::{recording, render};
use std::path::Path;
use std::path::PathBuf;
use std::process::ExitCode;

/// Output format.
#[derive(Clone, Copy, clap::ValueEnum)]
pub enum Format {
    /// For a person.
    Text,
    /// `ratecal-explain/1` JSON on standard output, nothing else.
    Json,
}

/// Arguments of `ratecal explain`.
#[derive(clap::Args)]
pub struct Args {
    /// Recording folder (manifest.yaml, imu.csv, table.csv), from any acquisition system.
    #[arg(value_name = "RUN_DIR")]
    run: PathBuf,
    /// Procedure whose fits are the nominal model (default: the standard's seed model).
    #[arg(long, value_name = "PROCEDURE")]
    procedure: Option<PathBuf>,
    /// Output format.
    #[arg(long, value_enum, default_value = "text")]
    format: Format,
    /// Accept a released procedure version whose text changed after release.
    #[arg(long)]
    allow_changed: bool,
    /// Also write each finding's before/after figure as `DIR/explain-<effect>.svg` (in a
    /// ratecal run folder they are written beside explain.json in any case).
    #[arg(long, value_name = "DIR")]
    plots: Option<PathBuf>,
}

/// Runs the subcommand.
pub fn main(args: Args) -> ExitCode {
    let rec = match recording::read(&args.run) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("{:?}", miette::Report::new(e));
            return ExitCode::from(2);
        }
    };
    let nominal = match &args.procedure {
        None => NominalModel::seed(),
        Some(p) => match super::analyze::load_plan(p, args.allow_changed) {
            Ok((plan, _)) => NominalModel::from_plan(&plan, rec.manifest.station.site.latitude_deg),
            Err(()) => return ExitCode::from(2),
        },
    };
    let opts = Options {
        path: args.run.display().to_string(),
        ..Options::default()
    };
    let x = explain::explain(&rec, &nominal, &opts);
    let json = serde_json::to_string_pretty(&x).expect("plain data serializes");
    let figures: Vec<(String, String)> =
        render::explain_figures(&serde_json::to_value(&x).expect("plain data serializes"))
            .into_iter()
            .filter_map(|(effect, svg)| Some((format!("explain-{effect}.svg"), svg?)))
            .collect();
    // Kept in a ratecal run folder (not in another system's recording): its report shows it.
    let in_run = rec.manifest.run.is_some();
    if in_run {
        let mut files = vec![("explain.json".to_string(), format!("{json}\n"))];
        files.extend(
            figures
                .iter()
                .map(|(n, svg)| (n.clone(), format!("{svg}\n"))),
        );
        if let Err(e) = write(&args.run, &files, true) {
            eprintln!("warning: cannot keep explain.json and its figures in the run folder: {e}");
        }
    }
    if let Some(dir) = &args.plots {
        let same = in_run && same_dir(dir, &args.run);
        let files: Vec<(String, String)> = figures
            .iter()
            .map(|(n, svg)| (n.clone(), format!("{svg}\n")))
            .collect();
        if !same && let Err(e) = write(dir, &files, false) {
            eprintln!(
                "error: cannot write the figures into {}: {e}",
                dir.display()
            );
            return ExitCode::from(2);
        }
        for (name, _) in &files {
            eprintln!("figure: {}", dir.join(name).display());
        }
    }
    let out = match args.format {
        Format::Json => json + "\n",
        Format::Text => explain::render_text(&x),
    };
    out!("{out}");
    if x.findings.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    }
}

/// Writes `files` (name, text) into `dir`; in a sealed run folder (`seal`), records them as
/// one addition to its seal.
fn write(dir: &Path, files: &[(String, String)], seal: bool) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    let paths: Vec<std::path::PathBuf> = files.iter().map(|(n, _)| dir.join(n)).collect();
    for (path, (_, text)) in paths.iter().zip(files) {
        std::fs::write(path, text)?;
    }
    if seal && !paths.is_empty() {
        let refs: Vec<&Path> = paths.iter().map(|p| p.as_path()).collect();
        super::seal::record_additions(&refs, &super::seal::command_line())?;
    }
    Ok(())
}

fn same_dir(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}
