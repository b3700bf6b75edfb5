//! One module per subcommand. Each parses its arguments (clap), builds what the engine
//! needs (files, station, drivers) and maps outcomes to the exit codes of spec/cli.md.

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
pub mod procedure;
pub mod report;
pub mod run;
pub mod station_effects;
pub mod twin;
pub mod verify;
