//! ratecal's commands as library functions (as `cargo::ops`): each composes the stage
//! crates for one subcommand (`run`: procedure and station files, check, the interpreter
//! over the drivers, the analysis, the reports, the folder's seal, the archive), takes its
//! inputs as plain values and returns its outcome with the exit code spec/cli.md gives
//! it. The `ratecal` binary parses arguments, calls one of these and prints; what a command
//! says on the way goes through [`console`].

/// A line for standard output, through the installed [`console`].
macro_rules! outln {
    ($($t:tt)*) => { $crate::console::out(format_args!($($t)*), true) };
}
/// A line for standard error, through the installed [`console`].
macro_rules! errln {
    ($($t:tt)*) => { $crate::console::err(format_args!($($t)*), true) };
}

pub mod across;
pub mod across_archive;
pub mod across_twin;
pub mod analyze;
pub mod archive;
pub mod certificate;
pub mod console;
pub mod explain;
pub mod procedure;
pub mod release;
pub mod report;
pub mod run;
pub mod station;
pub mod twin;
pub mod versions;
