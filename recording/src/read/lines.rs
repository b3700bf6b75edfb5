//! Refuses a stream file with a line far longer than a sample's before the exact reader
//! reads it whole: a NUL-filled or newline-less file (zeroed or preallocated by a crash) is
//! reported in bounded time and memory, from a few kilobytes of it.

// A refused recording is built once per read: the error's size costs nothing.
#![allow(clippy::result_large_err)]

use super::io_error;
use crate::error::RecordingError;
use crate::excerpt::Excerpt;
use std::io::{Read, Seek, SeekFrom};
use std::path::Path;

/// The longest line accepted, bytes (a sample line is a few hundred).
pub(super) const MAX_LINE: usize = 64 * 1024;

/// `Err(LineTooLong)` at the first line of `path` longer than [`MAX_LINE`]; reads the file
/// streaming, a block at a time.
pub(super) fn refuse_long_lines(path: &Path) -> Result<(), RecordingError> {
    let io = |e| io_error(path, e);
    let mut f = std::fs::File::open(path).map_err(io)?;
    let mut buf = vec![0u8; 1 << 20];
    let (mut offset, mut line_start, mut line) = (0u64, 0u64, 0u64);
    let mut prev_cr = false;
    loop {
        let n = match f.read(&mut buf) {
            Ok(0) => return Ok(()),
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(io(e)),
        };
        for (i, &b) in buf[..n].iter().enumerate() {
            let at = offset + i as u64;
            if b == b'\n' || b == b'\r' {
                if !(b == b'\n' && prev_cr) {
                    line += 1;
                }
                line_start = at + 1;
            } else if at - line_start > MAX_LINE as u64 {
                return Err(too_long(path, &mut f, line_start, line));
            }
            prev_cr = b == b'\r';
        }
        offset += n as u64;
    }
}

/// The error for the line starting at `start` (0-based line `line`), shown from a few
/// kilobytes around it.
fn too_long(path: &Path, f: &mut std::fs::File, start: u64, line: u64) -> RecordingError {
    let file = path.display().to_string();
    // The line before it too, when it is short.
    let from = start.saturating_sub(1024);
    let mut window = Vec::with_capacity(4096);
    let read = f
        .seek(SeekFrom::Start(from))
        .and_then(|_| f.take(start - from + 2048).read_to_end(&mut window));
    if let Err(e) = read {
        return io_error(path, e);
    }
    let at = (start - from) as usize;
    // The window may start inside a line: cut it at its first line break.
    let cut = if from == 0 {
        0
    } else {
        window[..at]
            .iter()
            .position(|&b| b == b'\n' || b == b'\r')
            .map_or(at, |p| p + 1)
    };
    let lines_before = window[cut..at].iter().filter(|&&b| b == b'\n').count();
    let base = (line as usize).saturating_sub(lines_before);
    let (src, span) = Excerpt::around_at(&file, &window[cut..], base, at - cut, window.len() - cut);
    RecordingError::LineTooLong {
        file,
        line: line + 1,
        max: MAX_LINE,
        src,
        span,
    }
}
