//! The `ratecal` command: each subcommand lives in `cli/<name>.rs`.

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// `println!` that ends quietly on a closed pipe.
macro_rules! outln {
    ($($t:tt)*) => { $crate::out::stdout(format_args!($($t)*), true) };
}
/// `print!` that ends quietly on a closed pipe.
macro_rules! out {
    ($($t:tt)*) => { $crate::out::stdout(format_args!($($t)*), false) };
}
/// `eprintln!` that ends quietly on a closed pipe.
macro_rules! errln {
    ($($t:tt)*) => { $crate::out::stderr(format_args!($($t)*), true) };
}

mod cli;
mod out;

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
    /// Release a procedure version: its signed line in the folder's versions.lock.
    Release(cli::release::Args),
    /// Check a run folder against its seal (and the lab's signature with --key).
    Verify(cli::verify::Args),
    /// Locate where a recording and the nominal model disagree and name the physics left out.
    Explain(cli::explain::Args),
    /// Lab signing keys: `ratecal key new DIR` writes DIR/lab.key and DIR/lab.pub.
    Key(cli::key::Args),
    /// The calibration archive: add, list, show, export, trend, backup, check.
    Archive(cli::archive::Args),
    /// Convert a lab's own DAQ files (CSV, raw counts, no time column) to a recording.
    Import(cli::import::Args),
    /// Approve a run's results for a certificate: signer, role and time, signed into its seal.
    Approve(cli::approve::Args),
    /// Issue a calibration certificate (PDF, HTML, Markdown or JSON) for an archived run.
    Certificate(cli::certificate::Args),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    ratecal_ops::console::install(Box::new(out::Terminal));
    match cli.command {
        Command::Check(a) => cli::check::main(a),
        Command::Fmt(a) => cli::fmt::main(a),
        Command::Run(a) => cli::run::main(a),
        Command::Emulate(a) => cli::emulate::main(a),
        Command::Analyze(a) => cli::analyze::main(a),
        Command::Report(a) => cli::report::main(a),
        Command::Diff(a) => cli::diff::main(a),
        Command::Log(a) => cli::log::main(a),
        Command::Release(a) => cli::release::main(a),
        Command::Verify(a) => cli::verify::main(a),
        Command::Explain(a) => cli::explain::main(a),
        Command::Key(a) => cli::key::main(a),
        Command::Archive(a) => cli::archive::main(a),
        Command::Import(a) => cli::import::main(a),
        Command::Approve(a) => cli::approve::main(a),
        Command::Certificate(a) => cli::certificate::main(a),
    }
}
