//! One module per subcommand. Each parses its arguments (clap), builds what the engine
//! needs (files, station, drivers) and maps outcomes to the exit codes of spec/cli.md.

pub mod analyze;
pub mod check;
pub mod diff;
pub mod emulate;
pub mod fmt;
pub mod log;
pub mod procedure;
pub mod report;
pub mod run;
pub mod verify;
