//! Terminal output that ends quietly when the reader has gone (`ratecal log | head -1`):
//! `println!` would panic on the closed pipe; here the rest of the output is dropped and
//! the command finishes with its usual exit code (spec/cli.md, Pipes).

use std::io::Write;
use std::sync::atomic::{AtomicBool, Ordering};

static STDOUT_GONE: AtomicBool = AtomicBool::new(false);
static STDERR_GONE: AtomicBool = AtomicBool::new(false);

/// Writes to standard output; after the first failed write, nothing more is tried.
pub fn stdout(args: std::fmt::Arguments, newline: bool) {
    write(&mut std::io::stdout().lock(), &STDOUT_GONE, args, newline);
}

/// Writes to standard error; after the first failed write, nothing more is tried.
pub fn stderr(args: std::fmt::Arguments, newline: bool) {
    write(&mut std::io::stderr().lock(), &STDERR_GONE, args, newline);
}

fn write(w: &mut dyn Write, gone: &AtomicBool, args: std::fmt::Arguments, newline: bool) {
    if gone.load(Ordering::Relaxed) {
        return;
    }
    let r = w
        .write_fmt(args)
        .and_then(|()| if newline { w.write_all(b"\n") } else { Ok(()) })
        .and_then(|()| w.flush());
    // A closed pipe (or any failed write) cannot be reported on the stream that failed.
    if r.is_err() {
        gone.store(true, Ordering::Relaxed);
    }
}

/// Writes bytes to standard output as they are; after a failed write, nothing more.
pub fn stdout_bytes(bytes: &[u8]) {
    if STDOUT_GONE.load(Ordering::Relaxed) {
        return;
    }
    let mut out = std::io::stdout().lock();
    if out.write_all(bytes).and_then(|()| out.flush()).is_err() {
        STDOUT_GONE.store(true, Ordering::Relaxed);
    }
}

/// The commands' console: the terminal, quiet once a reader has gone.
pub struct Terminal;

impl ratecal_ops::console::Console for Terminal {
    fn out(&self, args: std::fmt::Arguments, newline: bool) {
        stdout(args, newline);
    }

    fn err(&self, args: std::fmt::Arguments, newline: bool) {
        stderr(args, newline);
    }

    fn bytes(&self, bytes: &[u8]) {
        stdout_bytes(bytes);
    }
}
