//! `ratecal analyze RUN_DIR... [--procedure PROCEDURE] [--out results.json]`: fits,
//! uncertainties and acceptance for one recording, or repeatability over several runs
//! (`ratecal_ops::analyze`). Exit codes: 0 the verdict is pass or not_judged, 3 it is not,
//! 1 input error, 2 usage error (clap).

use ratecal_ops::analyze::{Request, analyze};
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
    /// it, segments are chosen by kind (spec/recording-format.md) and no thresholds apply.
    #[arg(long, value_name = "PROCEDURE")]
    procedure: Option<PathBuf>,
    /// Catalogue effects to add to whatever model applies, fitted jointly with it
    /// (`--with lever_arm,time_offset`; ids of spec/physics.md).
    #[arg(long, value_name = "EFFECTS", value_delimiter = ',')]
    with: Vec<String>,
    /// Where to write results.json (default: standard output).
    #[arg(long, value_name = "FILE")]
    out: Option<PathBuf>,
    /// Accept a released version whose text no longer matches versions.lock.
    #[arg(long)]
    allow_changed: bool,
}

/// Runs the subcommand.
pub fn main(a: Args) -> ExitCode {
    ExitCode::from(analyze(&Request {
        runs: a.runs,
        procedure: a.procedure,
        with: a.with,
        out: a.out,
        allow_changed: a.allow_changed,
    }))
}
