//! `ratecal explain RUN_DIR [--procedure PROCEDURE] [--format text|json]`: where the
//! recording and the nominal model disagree, what physics was left out, the refit with
//! it. Exit codes, like diff(1): 0 nothing found, 1 findings reported, 2 error.

use ratecal_engine::explain::{self, NominalModel, Options};
use ratecal_engine::recording;
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
    // Kept in a ratecal run folder (not in another system's recording): its report shows it.
    if rec.manifest.run.is_some() {
        let path = args.run.join("explain.json");
        let written = std::fs::write(&path, format!("{json}\n"))
            .and_then(|()| super::seal::record_addition(&path, &super::seal::command_line()));
        if let Err(e) = written {
            eprintln!("warning: cannot keep explain.json in the run folder: {e}");
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
