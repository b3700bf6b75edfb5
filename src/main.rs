//! The `ratecal` command: each subcommand lives in `cli/<name>.rs`.

use clap::{Parser, Subcommand};
use std::process::ExitCode;

mod cli;

/// Declarative calibration procedures for IMUs on dual-axis rate tables.
#[derive(Parser)]
#[command(name = "ratecal", version, about, propagate_version = true)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Check procedures: syntax, units, names, station limits, observability, duration.
    Check(cli::check::Args),
    /// Rewrite procedures in canonical format (or check that they are).
    Fmt(cli::fmt::Args),
    /// Run a procedure on a station (simulated with --dry-run).
    Run(cli::run::Args),
    /// Serve a station file's simulated station over the hardware protocols, in real time.
    Emulate(cli::emulate::Args),
    /// Analyse a recording: fits, uncertainties, acceptance.
    Analyze(cli::analyze::Args),
    /// Render a calibration report from a run folder.
    Report(cli::report::Args),
    /// Semantic diff of two procedure versions.
    Diff(cli::diff::Args),
    /// Every version of a procedure folder, with hashes and summaries.
    Log(cli::log::Args),
    /// Check that a run folder was not altered since the run.
    Verify(cli::verify::Args),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Check(a) => cli::check::main(a),
        Command::Fmt(a) => cli::fmt::main(a),
        Command::Run(a) => cli::run::main(a),
        Command::Emulate(a) => cli::emulate::main(a),
        Command::Analyze(a) => cli::analyze::main(a),
        Command::Report(a) => cli::report::main(a),
        Command::Diff(a) => cli::diff::main(a),
        Command::Log(a) => cli::log::main(a),
        Command::Verify(a) => cli::verify::main(a),
    }
}
