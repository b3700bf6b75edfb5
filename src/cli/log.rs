//! `ratecal log` (not implemented yet).

use std::process::ExitCode;

/// Arguments of `ratecal log`.
#[derive(clap::Args)]
pub struct Args {
    /// Inputs.
    inputs: Vec<std::path::PathBuf>,
}

/// Runs the subcommand.
pub fn main(args: Args) -> ExitCode {
    let _ = args.inputs;
    eprintln!("ratecal log: not implemented yet");
    ExitCode::from(1)
}
