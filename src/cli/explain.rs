//! `ratecal explain RUN_DIR [--procedure PROCEDURE] [--effects FILE_OR_DIR]... [--without ID]...
//! [--twin STATION] [--write-twin OUT.yaml] [--format text|json] [--plots DIR]`: where the
//! recording and the nominal model (or the station's twin) disagree, what physics was left
//! out (`ratecal_ops::explain`). Exit codes, like diff(1): 0 nothing found, 1 findings
//! reported, 2 error; 4 the run folder's seal fails (or it was never sealed).

use ratecal_ops::explain::{Request, explain};
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
    /// Procedure whose fits are the nominal model (default: the standard's seed model);
    /// "how to adopt" becomes a diff against its file.
    #[arg(long, value_name = "PROCEDURE")]
    procedure: Option<PathBuf>,
    /// Candidate effects defined in a file, or every `*.effect` file of a folder
    /// (docs/user-effects.md); repeatable. `RATECAL_EFFECTS` adds paths too (`:`-separated).
    #[arg(long, value_name = "FILE_OR_DIR")]
    effects: Vec<PathBuf>,
    /// Leave a registry effect out of the candidates (repeatable).
    #[arg(long, value_name = "EFFECT")]
    without: Vec<String>,
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
    /// Write each discovered finding as a draft effect file `DIR/<effect>.effect`, which
    /// `--effects` reads unchanged (in a ratecal run folder they are written beside
    /// explain.json in any case).
    #[arg(long, value_name = "DIR")]
    draft_effects: Option<PathBuf>,
    /// Compare the recording with its station's twin: a station file, or a run folder
    /// (its station.yaml). The JSON gains `twin` (docs/explain.md).
    #[arg(long, value_name = "STATION", conflicts_with = "procedure")]
    twin: Option<PathBuf>,
    /// Write the corrected twin there (the input's layout and comments, values changed,
    /// effects added) and print the diff.
    #[arg(long, value_name = "OUT.yaml", requires = "twin")]
    write_twin: Option<PathBuf>,
}

/// Runs the subcommand.
pub fn main(a: Args) -> ExitCode {
    ExitCode::from(explain(&Request {
        run: a.run,
        procedure: a.procedure,
        effects: a.effects,
        without: a.without,
        format: match a.format {
            Format::Text => ratecal_ops::explain::Format::Text,
            Format::Json => ratecal_ops::explain::Format::Json,
        },
        allow_changed: a.allow_changed,
        plots: a.plots,
        draft_effects: a.draft_effects,
        twin: a.twin,
        write_twin: a.write_twin,
    }))
}
