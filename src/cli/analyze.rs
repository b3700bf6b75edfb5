//! `ratecal analyze RUN_DIR... [--procedure PROCEDURE] [--out results.json]`: fits,
//! uncertainties and acceptance for one recording, or repeatability over several runs.
//! Exit codes: 0 results written and no check failed, 3 a check failed, 1 input error,
//! 2 usage error (clap).

use ratecal_engine::fit::{self, Options};
use ratecal_engine::plan::Plan;
use ratecal_engine::recording;
use ratecal_engine::results::{Parameter, Results, Verdict};
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `ratecal analyze`.
#[derive(clap::Args)]
pub struct Args {
    /// Recording folders (manifest.yaml, imu.csv, table.csv); several runs of the same
    /// procedure give the repeatability analysis.
    #[arg(required = true, value_name = "RUN_DIR")]
    runs: Vec<PathBuf>,
    /// Procedure whose fit statements and thresholds apply (without it, segments are
    /// chosen by kind and the standard model is fitted). A checked plan as JSON is accepted.
    #[arg(long, value_name = "PROCEDURE")]
    procedure: Option<PathBuf>,
    /// Where to write results.json (default: standard output).
    #[arg(long, value_name = "FILE")]
    out: Option<PathBuf>,
}

/// Runs the subcommand.
pub fn main(args: Args) -> ExitCode {
    let plan = match args.procedure.as_deref().map(load_plan).transpose() {
        Ok(p) => p,
        Err(e) => {
            eprintln!("{e:?}");
            return ExitCode::from(1);
        }
    };
    let mut runs = Vec::with_capacity(args.runs.len());
    for dir in &args.runs {
        match recording::read(dir) {
            Ok(r) => runs.push((dir.display().to_string(), r)),
            Err(e) => {
                eprintln!("{:?}", miette::Report::new(e));
                return ExitCode::from(1);
            }
        }
    }
    let results = fit::analyze_runs(&runs, plan.as_ref(), &Options::default());
    let json = results.to_json();
    match &args.out {
        Some(path) => {
            if let Err(e) = std::fs::write(path, json + "\n") {
                eprintln!("error: cannot write {}: {e}", path.display());
                return ExitCode::from(1);
            }
        }
        None => println!("{json}"),
    }
    summary(&results);
    if results.has_failure() {
        ExitCode::from(3)
    } else {
        ExitCode::SUCCESS
    }
}

/// Loads the procedure. Until the procedure checker is merged, a checked plan serialized
/// as JSON is accepted; procedure text is refused with a clear message.
fn load_plan(path: &std::path::Path) -> miette::Result<Plan> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| miette::miette!("cannot read {}: {e}", path.display()))?;
    if path.extension().is_some_and(|e| e == "json") {
        return serde_json::from_str(&text)
            .map_err(|e| miette::miette!("{}: not a checked plan: {e}", path.display()));
    }
    Err(miette::miette!(
        help = "pass a checked plan as JSON, or analyse without --procedure (segments by kind, standard model)",
        "{}: procedure text needs the procedure checker, which this build does not include yet",
        path.display()
    ))
}

/// A short human summary on standard error (standard output may hold the JSON).
fn summary(r: &Results) {
    eprintln!(
        "ratecal analyze: {} ({})",
        r.recording.paths.join(", "),
        r.model.selection
    );
    for (name, p) in &r.parameters {
        match p {
            Parameter::Estimate { value, u, unit } => {
                eprintln!("  {name:<32} {value:>14.6} ± {u:<10.3e} {unit}")
            }
            Parameter::Unobservable { .. } => eprintln!("  {name:<32} {:>14}", "not observable"),
        }
    }
    for a in &r.acceptance {
        let v = match a.verdict {
            Verdict::Pass => "pass",
            Verdict::Fail => "FAIL",
            Verdict::Indeterminate => "indeterminate",
            Verdict::NotEvaluated => "not evaluated",
        };
        eprintln!("  [{v}] {}", a.name);
    }
    for w in &r.warnings {
        eprintln!("  warning: {w}");
    }
}
