//! One module per subcommand. Each parses its arguments (clap), calls one library function
//! (`ratecal_ops`, or a stage crate) and prints; exit codes as spec/cli.md gives them.

pub mod analyze;
pub mod approve;
pub mod archive;
pub mod certificate;
pub mod check;
pub mod diff;
pub mod emulate;
pub mod explain;
pub mod fmt;
pub mod import;
pub mod key;
pub mod log;
pub mod release;
pub mod report;
pub mod run;
pub mod verify;
