//! `ratecal run`: runs a procedure on a station (simulated with `--dry-run` or without a
//! station), records the run folder, analyses it, writes the reports and seals the folder
//! (`ratecal_ops::run`). Exit codes (spec/cli.md): 0 the verdict is pass or not_judged, 3 it
//! is not, 4 aborted, 1 input error (or a run that failed: its folder ends with `status:
//! failed`), 2 usage.

mod progress;

use ratecal_ops::run::{Request, run};
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `ratecal run`.
#[derive(clap::Args)]
pub struct Args {
    /// Procedure file, or procedure folder (its latest version).
    #[arg(required_unless_present = "resume")]
    procedure: Option<PathBuf>,
    /// Station file (YAML); the embedded default simulated station without it.
    #[arg(long)]
    station: Option<PathBuf>,
    /// Run folder to create (default: runs/<procedure>-<UTC timestamp>).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Simulate the station (table and IMU) whatever drivers the station file names.
    #[arg(long)]
    dry_run: bool,
    /// Seed of the simulated station.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Continue an interrupted run from its last completed step (procedure and station
    /// come from the run folder).
    #[arg(long, value_name = "RUN_DIR", conflicts_with_all = ["procedure", "station", "out", "serial"])]
    resume: Option<PathBuf>,
    /// Operator name, recorded in the manifest.
    #[arg(long)]
    operator: Option<String>,
    /// The IMU's serial number for this run (the manifest's `imu.serial`, the archive's
    /// index, the certificate), instead of the station file's `imu.serial`.
    #[arg(long, value_name = "SN")]
    serial: Option<String>,
    /// Sign the run folder's seal with the lab's private key (`ratecal key new` wrote it).
    #[arg(long, value_name = "LAB_KEY")]
    sign: Option<PathBuf>,
    /// Run a released version although its text no longer matches versions.lock (the
    /// manifest and the report record it).
    #[arg(long)]
    allow_changed: bool,
    /// Run a version its folder has not released (the folder form then takes the newest
    /// version): manifest, results, reports and console say DRAFT PROCEDURE, and no
    /// certificate is issued for the run.
    #[arg(long)]
    draft: bool,
    /// Progress when standard error is not a terminal: `text` lines, or `json` lines (one
    /// object per line; on a terminal too). Keys: docs/run-folders.md.
    #[arg(long, value_parser = ["text", "json"], default_value = "text")]
    log_format: String,
    /// Archive the run here (folder or postgres:// URL; also $RATECAL_ARCHIVE).
    #[arg(long, value_name = "DIR_OR_URL")]
    archive: Option<String>,
}

/// Runs the subcommand.
pub fn main(a: Args) -> ExitCode {
    let request = Request {
        procedure: a.procedure,
        station: a.station,
        out: a.out,
        dry_run: a.dry_run,
        seed: a.seed,
        resume: a.resume,
        operator: a.operator,
        serial: a.serial,
        sign: a.sign,
        allow_changed: a.allow_changed,
        draft: a.draft,
        archive: a.archive,
    };
    let json = a.log_format == "json";
    ExitCode::from(run(
        request,
        Box::new(
            move |estimated_s, simulated| -> Box<dyn ratecal_ops::run::Shown> {
                use std::io::IsTerminal;
                if json || !std::io::stderr().is_terminal() {
                    Box::new(ratecal_ops::run::log::LogLines::new(
                        estimated_s,
                        simulated,
                        json,
                    ))
                } else {
                    Box::new(progress::Bar::new(estimated_s, simulated))
                }
            },
        ),
    ))
}
