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
    /// Several: each is explained, then the findings are pooled across them (what recurs
    /// in the model, in a unit, in the pool only; docs/explain.md "Across recordings").
    #[arg(value_name = "RUN_DIR", required_unless_present_any = ["serial", "model"])]
    runs: Vec<PathBuf>,
    /// The archive to select runs from with --serial or --model (a folder or a
    /// postgres:// URL; default `RATECAL_ARCHIVE`, else ./archive/).
    #[arg(long, value_name = "DIR_OR_URL")]
    archive: Option<String>,
    /// Explain one unit's history: every archived run of this IMU serial.
    #[arg(long, value_name = "SN", conflicts_with = "model")]
    serial: Option<String>,
    /// Explain a model's fleet: every archived run of this IMU model.
    #[arg(long, value_name = "M")]
    model: Option<String>,
    /// With --serial/--model: runs started on or after (YYYY-MM-DD or RFC 3339).
    #[arg(long, value_name = "DATE")]
    since: Option<String>,
    /// With --serial/--model: runs started on or before (a date includes that day).
    #[arg(long, value_name = "DATE")]
    until: Option<String>,
    /// With --serial/--model: dry runs too.
    #[arg(long)]
    include_dry_runs: bool,
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
    /// ratecal run folder they are written beside explain.json in any case). Across
    /// recordings: a forest plot per pooled parameter in `DIR/explain-across.html`.
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
    /// Across recordings of one model (--model M, or folders of one imu.model): write the
    /// model's twin, the --twin station file with the fleet's pooled IMU effects.
    #[arg(long, value_name = "OUT.yaml")]
    write_twin: Option<PathBuf>,
}

/// Runs the subcommand.
pub fn main(a: Args) -> ExitCode {
    let format = match a.format {
        Format::Text => ratecal_ops::explain::Format::Text,
        Format::Json => ratecal_ops::explain::Format::Json,
    };
    let select = a.serial.is_some() || a.model.is_some();
    if !select && (a.archive.is_some() || a.since.is_some() || a.until.is_some()) {
        let e = miette::miette!(
            code = "explain::no_selection",
            help = "add --serial SN (one unit's history) or --model M (a model's fleet)",
            "--archive, --since and --until select archived runs, and need --serial or --model"
        );
        eprintln!("{e:?}");
        return ExitCode::from(2);
    }
    if a.runs.len() > 1 || select {
        return across(a, format);
    }
    ExitCode::from(explain(&Request {
        run: a.runs.into_iter().next().unwrap_or_default(),
        procedure: a.procedure,
        effects: a.effects,
        without: a.without,
        format,
        allow_changed: a.allow_changed,
        plots: a.plots,
        draft_effects: a.draft_effects,
        twin: a.twin,
        write_twin: a.write_twin,
    }))
}

/// Several recordings: explained each, then pooled (the options of one recording's output
/// files are refused there, exit 2).
fn across(a: Args, format: ratecal_ops::explain::Format) -> ExitCode {
    ExitCode::from(ratecal_ops::across::explain_across(
        &ratecal_ops::across::Request {
            runs: a.runs,
            procedure: a.procedure,
            effects: a.effects,
            without: a.without,
            format,
            allow_changed: a.allow_changed,
            archive: (a.serial.is_some() || a.model.is_some()).then_some(
                ratecal_ops::across_archive::Selection {
                    archive: a.archive,
                    serial: a.serial,
                    model: a.model,
                    since: a.since,
                    until: a.until,
                    include_dry_runs: a.include_dry_runs,
                },
            ),
            plots: a.plots,
            twin: a.twin,
            write_twin: a.write_twin,
            draft_effects: a.draft_effects,
        },
    ))
}
