//! `ratecal report RUN_DIR [--template FILE_OR_DIR] [--format md|html] [--out FILE]`: a
//! calibration report from a run folder (`ratecal_ops::report`). Exit codes: 0 report
//! written, 1 input error, 2 usage, 4 the folder's seal fails (or it was never sealed).

use ratecal_ops::report::{Request, report};
use std::path::PathBuf;
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

/// Runs the subcommand.
pub fn main(a: Args) -> ExitCode {
    ExitCode::from(report(&Request {
        run_dir: a.run_dir,
        template: a.template,
        format: match a.format {
            FormatArg::Md => ratecal_ops::report::FormatArg::Md,
            FormatArg::Html => ratecal_ops::report::FormatArg::Html,
        },
        out: a.out,
        archive: a.archive,
    }))
}
