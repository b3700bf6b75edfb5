//! `ratecal analyze RUN_DIR... [--procedure PROCEDURE] [--out results.json]`: fits,
//! uncertainties and acceptance for one recording, or repeatability over several runs.
//! Exit codes: 0 results written and no check failed, 3 a check failed, 1 input error,
//! 2 usage error (clap).

use super::procedure::{self, FsSources};
use ratecal_engine::check::{CheckOptions, NoImports, check_text};
use ratecal_engine::fit::{self, Options};
use ratecal_engine::plan::{Plan, segment_matches};
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
    /// Procedure whose fit statements and thresholds apply: a file, a procedure folder
    /// (newest version) or folder@version; a checked plan as JSON is accepted too. Without
    /// it, the bundled standard procedure's fits apply when its segment names match,
    /// otherwise segments are chosen by kind.
    #[arg(long, value_name = "PROCEDURE")]
    procedure: Option<PathBuf>,
    /// Catalogue effects to add to whatever model applies, fitted jointly with it
    /// (`--with lever_arm,time_offset`; ids of spec/physics.md).
    #[arg(long, value_name = "EFFECTS", value_delimiter = ',')]
    with: Vec<String>,
    /// Where to write results.json (default: standard output).
    #[arg(long, value_name = "FILE")]
    out: Option<PathBuf>,
}

/// Runs the subcommand.
pub fn main(args: Args) -> ExitCode {
    let (plan, sha256) = match args.procedure.as_deref().map(load_plan).transpose() {
        Ok(Some((p, h))) => (Some(p), h),
        Ok(None) => (None, None),
        Err(()) => return ExitCode::from(1),
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
    let plan = plan.or_else(|| default_plan(&runs[0].1));
    let opts = Options {
        with: args.with.clone(),
        ..Options::default()
    };
    let mut results = fit::analyze_runs(&runs, plan.as_ref(), &opts);
    // The procedure given on the command line is identified by its own canonical hash.
    if let (Some(h), Some(p)) = (sha256, results.model.procedure.as_mut()) {
        p.sha256 = h;
    }
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

/// Loads and checks the procedure (a file, a folder's newest version, `folder@version`)
/// with the SHA-256 of its canonical text; a checked plan serialized as JSON is accepted
/// too (no hash then). Diagnostics go to standard error.
pub(crate) fn load_plan(arg: &std::path::Path) -> Result<(Plan, Option<String>), ()> {
    if arg.extension().is_some_and(|e| e == "json") {
        let text = std::fs::read_to_string(arg)
            .map_err(|e| eprintln!("error: cannot read {}: {e}", arg.display()))?;
        return serde_json::from_str(&text)
            .map(|p| (p, None))
            .map_err(|e| eprintln!("error: {}: not a checked plan: {e}", arg.display()));
    }
    let file = procedure::read(&arg.display().to_string()).map_err(|d| procedure::report(&d))?;
    match check_text(
        &file.display,
        &file.text,
        &FsSources,
        &CheckOptions::default(),
    ) {
        Ok(checked) => {
            checked.warnings.iter().for_each(procedure::report);
            let sha256 = ratecal_grammar::canonical(&file.text)
                .ok()
                .map(|c| c.sha256);
            Ok((checked.plan, sha256))
        }
        Err(diags) => {
            diags.iter().for_each(procedure::report);
            Err(())
        }
    }
}

/// The bundled standard procedure, shipped in the binary.
const STANDARD: &str = include_str!("../../procedures/imu-2d-standard/1.0.0.rcal");

/// Without `--procedure`: the standard procedure's fit statements (not its thresholds, which
/// the user did not ask for) when its segment patterns match the recording; otherwise the
/// analysis picks segments by kind.
fn default_plan(rec: &recording::Recording) -> Option<Plan> {
    let mut plan = check_text(
        "imu-2d-standard/1.0.0.rcal",
        STANDARD,
        &NoImports,
        &CheckOptions::default(),
    )
    .ok()?
    .plan;
    let ids: Vec<&str> = rec
        .manifest
        .segments
        .iter()
        .map(|s| s.id.as_str())
        .collect();
    let all_match = plan.fits.iter().all(|f| {
        f.segments
            .iter()
            .any(|p| ids.iter().any(|id| segment_matches(p, id)))
    });
    if !all_match {
        return None;
    }
    plan.accepts.clear();
    plan.verifications.clear();
    plan.environment.clear();
    Some(plan)
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
