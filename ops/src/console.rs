//! Where the commands' messages go. A library does not print: the commands say what they
//! have to say through this sink, which the `ratecal` binary installs once (its own
//! terminal output, quiet on a closed pipe). Without one, nothing is printed (a library
//! user, a test).

use std::fmt::Arguments;
use std::sync::OnceLock;

/// A sink for the commands' messages: the report (`out`) and the diagnostics (`err`).
pub trait Console: Send + Sync {
    /// Standard output's share; `newline` ends the line.
    fn out(&self, args: Arguments, newline: bool);
    /// Standard error's share.
    fn err(&self, args: Arguments, newline: bool);
    /// Bytes for standard output as they are (a PDF).
    fn bytes(&self, bytes: &[u8]);
}

static CONSOLE: OnceLock<Box<dyn Console>> = OnceLock::new();

/// Installs the sink (once; a second call is ignored).
pub fn install(console: Box<dyn Console>) {
    let _ = CONSOLE.set(console);
}

/// Says `args` on the report's stream.
pub fn out(args: Arguments, newline: bool) {
    if let Some(c) = CONSOLE.get() {
        c.out(args, newline);
    }
}

/// Says `args` on the diagnostics' stream.
pub fn err(args: Arguments, newline: bool) {
    if let Some(c) = CONSOLE.get() {
        c.err(args, newline);
    }
}

/// Puts `bytes` on the report's stream as they are.
pub fn bytes(bytes: &[u8]) {
    if let Some(c) = CONSOLE.get() {
        c.bytes(bytes);
    }
}

/// A failure whose diagnostics were already said on the console: the caller only stops.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Reported;
