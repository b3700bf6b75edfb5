//! `ratecal report` (not implemented yet).

use std::process::ExitCode;

/// Arguments of `ratecal report`.
#[derive(clap::Args)]
pub struct Args {
    /// Inputs.
    inputs: Vec<std::path::PathBuf>,
}

/// Runs the subcommand.
pub fn main(args: Args) -> ExitCode {
    let _ = args.inputs;
    eprintln!("ratecal report: not implemented yet");
    ExitCode::from(1)
}
