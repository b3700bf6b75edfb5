//! One module per subcommand. Each parses its arguments (clap), builds what the engine
//! needs (files, station, drivers) and maps outcomes to the exit codes of spec/cli.md.

pub mod analyze;
pub mod check;
pub mod diff;
pub mod explain;
pub mod fmt;
pub mod log;
pub mod procedure;
pub mod report;
pub mod run;
pub mod verify;

/// Writes to standard output; a closed pipe (`ratecal ... | head`) is not an error worth a
/// panic: the caller ends quietly.
pub fn print_out(s: &str) -> std::io::Result<()> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    out.write_all(s.as_bytes())?;
    out.flush()
}
