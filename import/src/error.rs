//! Why an import is refused: every error names the file (the map or a source), the line
//! and the column (or the sample), with a help line.

use miette::{Diagnostic, SourceSpan};
use ratecal_recording::Excerpt;
use std::ops::Range;

/// The words of a diagnostic: the message, the label on the span, the help line.
#[derive(Debug, Clone, Copy)]
pub struct Say<'a> {
    /// The message (after `file:line:column: `).
    pub what: &'a str,
    /// The label on the span.
    pub label: &'a str,
    /// What to do.
    pub help: &'a str,
}

/// What kind of problem stopped the import (tests and callers branch on this, never on
/// the message).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ErrorKind {
    /// The map file is not valid YAML or has a wrong key or value.
    Map,
    /// A source file could not be read, or the output folder not written.
    Io,
    /// A source cell that is not a finite number, a missing column, a ragged file.
    Cell,
    /// Time going backwards or repeating.
    Time,
    /// A declared segment outside the data, overlapping another, or out of order.
    Segment,
    /// The data do not fit the declared units (gravity, gyro at rest, rate segments).
    Units,
    /// A declared `up` axis that gravity contradicts.
    Up,
    /// A source format that is not supported (MATLAB v7.3/HDF5...).
    Format,
}

/// A located import diagnostic.
#[derive(Debug, thiserror::Error, Diagnostic)]
#[error("{message}")]
#[diagnostic(code(import::refused))]
pub struct ImportError {
    /// What went wrong.
    pub kind: ErrorKind,
    /// `file:line:column: what` (as much of the location as is known).
    pub message: String,
    /// The file named.
    pub file: String,
    /// 1-based line, when known.
    pub line: Option<u64>,
    /// 1-based column (character), when known.
    pub column: Option<usize>,
    /// The lines around the problem.
    #[source_code]
    pub src: Excerpt,
    /// Where in `src`.
    #[label("{label}")]
    pub span: Option<SourceSpan>,
    /// The label's text.
    pub label: String,
    /// What to do.
    #[help]
    pub help: String,
}

impl ImportError {
    /// An error at byte `start..end` of `text` (a whole file: the map), line/column computed.
    pub fn in_text(
        kind: ErrorKind,
        file: &str,
        text: &str,
        range: Range<usize>,
        say: Say<'_>,
    ) -> Box<Self> {
        let (start, end) = (range.start, range.end);
        let start = floor_char(text, start.min(text.len()));
        let end = floor_char(text, end.clamp(start, text.len()));
        let (src, span) = Excerpt::around(file, text.as_bytes(), start, end.max(start + 1));
        let before = &text[..start];
        let line = before.matches('\n').count() as u64 + 1;
        let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
        Self::located(kind, file, (line, column), (src, span), say)
    }

    /// An error in one line of a source file (`line_text` without its newline, 1-based
    /// `line`), at bytes `start..end` of that line.
    pub fn in_line(
        kind: ErrorKind,
        file: &str,
        line: u64,
        line_text: &[u8],
        range: Range<usize>,
        say: Say<'_>,
    ) -> Box<Self> {
        let (start, end) = (range.start, range.end);
        let start = start.min(line_text.len());
        let end = end.clamp(start, line_text.len()).max(start + 1);
        let (src, span) =
            Excerpt::around_at(file, line_text, line.saturating_sub(1) as usize, start, end);
        let column = String::from_utf8_lossy(&line_text[..start]).chars().count() + 1;
        Self::located(kind, file, (line, column), (src, span), say)
    }

    /// The error at `line`, `column` of `file`, with its excerpt: what `in_text` and
    /// `in_line` locate.
    fn located(
        kind: ErrorKind,
        file: &str,
        (line, column): (u64, usize),
        (src, span): (Excerpt, SourceSpan),
        say: Say<'_>,
    ) -> Box<Self> {
        let Say { what, label, help } = say;
        Box::new(ImportError {
            kind,
            message: format!("{file}:{line}:{column}: {what}"),
            file: file.to_string(),
            line: Some(line),
            column: Some(column),
            src,
            span: Some(span),
            label: label.to_string(),
            help: help.to_string(),
        })
    }

    /// An error about a whole file (it cannot be opened, it is empty...).
    pub fn in_file(kind: ErrorKind, file: &str, what: &str, help: &str) -> Box<Self> {
        let (src, _) = Excerpt::around(file, b"", 0, 0);
        Box::new(ImportError {
            kind,
            message: format!("{file}: {what}"),
            file: file.to_string(),
            line: None,
            column: None,
            src,
            span: None,
            label: String::new(),
            help: help.to_string(),
        })
    }
}

fn floor_char(text: &str, mut i: usize) -> usize {
    while !text.is_char_boundary(i) {
        i -= 1;
    }
    i
}
