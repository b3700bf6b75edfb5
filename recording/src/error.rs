//! Why a recording folder is refused: every variant names the file, line and column.

use crate::excerpt::Excerpt;
use miette::{Diagnostic, SourceSpan};
use thiserror::Error;

/// A recording that cannot be read, located in its file.
#[derive(Debug, Error, Diagnostic)]
pub enum RecordingError {
    /// A file of the folder could not be opened or read.
    #[error("cannot read {file}: {message}")]
    #[diagnostic(
        code(recording::io),
        help(
            "a recording folder holds manifest.yaml, imu.csv and table.csv (spec/recording-format.md)"
        )
    )]
    Io {
        /// File path.
        file: String,
        /// OS message.
        message: String,
    },

    /// A required column is absent from the header.
    #[error("{file}:1: missing column `{column}`")]
    #[diagnostic(
        code(recording::missing_column),
        help("{file} needs the columns {required}; the header has {found}")
    )]
    MissingColumn {
        /// File name.
        file: String,
        /// Missing column.
        column: String,
        /// Required columns, comma-separated.
        required: String,
        /// Columns found.
        found: String,
        /// File text.
        #[source_code]
        src: Excerpt,
        /// The header line.
        #[label("no `{column}` here")]
        span: SourceSpan,
    },

    /// A cell that is not a finite number.
    #[error("{file}:{line}:{column}: `{cell}` in column `{name}` is not a number")]
    #[diagnostic(
        code(recording::not_a_number),
        help("every cell of {file} holds a finite decimal number (e.g. 9.80665 or 1.5e-3)")
    )]
    NotANumber {
        /// File name.
        file: String,
        /// Line, 1-based.
        line: u64,
        /// Column (character), 1-based.
        column: usize,
        /// Column name.
        name: String,
        /// Cell text.
        cell: String,
        /// File text.
        #[source_code]
        src: Excerpt,
        /// The cell.
        #[label("not a number")]
        span: SourceSpan,
    },

    /// A row with a different number of cells than the header.
    #[error("{file}:{line}: {found} cells where the header has {expected}")]
    #[diagnostic(
        code(recording::ragged_row),
        help("each line of {file} has one cell per header column")
    )]
    RaggedRow {
        /// File name.
        file: String,
        /// Line, 1-based.
        line: u64,
        /// Cells found.
        found: usize,
        /// Header cells.
        expected: usize,
        /// File text.
        #[source_code]
        src: Excerpt,
        /// The row.
        #[label("this row")]
        span: SourceSpan,
    },

    /// Time stamps that do not strictly increase (sanity check `time_increasing`).
    #[error(
        "{file}:{line}:{column}: time goes backwards or repeats ({t} s after {prev} s): sanity check `time_increasing` fails"
    )]
    #[diagnostic(
        code(sanity::time_increasing),
        help(
            "the `t` column of {file} must strictly increase, one sample a line; a clock reset or two runs in one file does this: cut the file there or re-stamp it"
        )
    )]
    TimeNotIncreasing {
        /// File name.
        file: String,
        /// Line, 1-based.
        line: u64,
        /// Column, 1-based.
        column: usize,
        /// This stamp.
        t: f64,
        /// Previous stamp.
        prev: f64,
        /// File text.
        #[source_code]
        src: Excerpt,
        /// The stamp.
        #[label("not after the previous line's {prev} s")]
        span: SourceSpan,
    },

    /// A line far longer than a sample's (a file zeroed or preallocated by a crash).
    #[error("{file}:{line}: a line of more than {max} bytes without a line break")]
    #[diagnostic(
        code(recording::line_too_long),
        help(
            "a line of {file} holds one sample, at most a few hundred bytes; this one looks like a file zeroed or preallocated by a crash (NUL bytes show as \\0)"
        )
    )]
    LineTooLong {
        /// File name.
        file: String,
        /// Line, 1-based.
        line: u64,
        /// The longest line accepted, bytes.
        max: usize,
        /// The start of the line.
        #[source_code]
        src: Excerpt,
        /// The line.
        #[label("no line break here")]
        span: SourceSpan,
    },

    /// The IMU's and the table's clocks have no time in common (sanity check
    /// `clocks_overlap`): the two streams cannot be one clock's.
    #[error(
        "{file}:{line}:{column}: the table feedback ({table_first} s .. {table_last} s) and the IMU stream ({imu_first} s .. {imu_last} s) do not overlap in time: sanity check `clocks_overlap` fails"
    )]
    #[diagnostic(
        code(sanity::clocks_overlap),
        help(
            "imu.csv and table.csv share one clock (spec/recording-format.md); stamp both with it (e.g. subtract the difference of their origins from one `t` column)"
        )
    )]
    ClocksDisjoint {
        /// File name (the table feedback's).
        file: String,
        /// Line, 1-based.
        line: u64,
        /// Column, 1-based.
        column: usize,
        /// The table's first and last stamps, s.
        table_first: f64,
        /// Last table stamp, s.
        table_last: f64,
        /// First IMU stamp, s.
        imu_first: f64,
        /// Last IMU stamp, s.
        imu_last: f64,
        /// File text.
        #[source_code]
        src: Excerpt,
        /// The table's first stamp.
        #[label("the table's clock starts here")]
        span: SourceSpan,
    },

    /// A stream with fewer than two samples.
    #[error("{file}:{line}:{column}: no samples")]
    #[diagnostic(
        code(recording::empty_stream),
        help("{file} needs a header line and at least two samples")
    )]
    EmptyStream {
        /// File name.
        file: String,
        /// Line where the samples end, 1-based.
        line: u64,
        /// Column, 1-based.
        column: u64,
        /// File text.
        #[source_code]
        src: Excerpt,
        /// The end of the file's text.
        #[label("the samples end here")]
        span: SourceSpan,
    },

    /// manifest.yaml is not valid YAML or does not have the manifest's shape.
    #[error("{file}:{line}:{column}: {message}")]
    #[diagnostic(
        code(recording::manifest),
        help("see spec/recording-format.md for the manifest's keys")
    )]
    Manifest {
        /// File name.
        file: String,
        /// Line, 1-based.
        line: u64,
        /// Column, 1-based.
        column: u64,
        /// Parser message.
        message: String,
        /// File text.
        #[source_code]
        src: Excerpt,
        /// Where.
        #[label("{message}")]
        span: SourceSpan,
    },

    /// A station value of the manifest that no table or site can have (a non-finite
    /// number, a gravity off the Earth's, an axis that is not a unit vector, a mount that
    /// is not a rotation): the analysis would turn it into NaN results.
    #[error("{file}:{line}:{column}: {problem}")]
    #[diagnostic(code(recording::station), help("{help}"))]
    BadStation {
        /// File name.
        file: String,
        /// Line.
        line: u64,
        /// Column.
        column: u64,
        /// What is wrong.
        problem: String,
        /// What would fix it.
        help: String,
        /// File text.
        #[source_code]
        src: Excerpt,
        /// The value.
        #[label("{problem}")]
        span: SourceSpan,
    },

    /// A static segment's `attitude` that cannot be used: `nominal` without a positive,
    /// finite `tolerance_deg`.
    #[error("{file}:{line}:{column}: segment `{id}` {problem}")]
    #[diagnostic(code(recording::attitude), help("{help}"))]
    BadAttitude {
        /// File name.
        file: String,
        /// Line.
        line: u64,
        /// Column.
        column: u64,
        /// Segment id.
        id: String,
        /// What is wrong.
        problem: String,
        /// What would fix it.
        help: String,
        /// File text.
        #[source_code]
        src: Excerpt,
        /// The segment.
        #[label("this segment")]
        span: SourceSpan,
    },

    /// A format tag this version does not read.
    #[error("{file}:{line}:{column}: unknown recording format `{found}`")]
    #[diagnostic(
        code(recording::unknown_format),
        help("this ratecal reads `ratecal-recording/1`")
    )]
    UnknownFormat {
        /// File name.
        file: String,
        /// Line.
        line: u64,
        /// Column.
        column: u64,
        /// Tag found.
        found: String,
        /// File text.
        #[source_code]
        src: Excerpt,
        /// Where.
        #[label("unknown format")]
        span: SourceSpan,
    },

    /// A segment whose window is not inside both streams, or ends before it starts.
    #[error("{file}:{line}:{column}: segment `{id}` ({t_start} s .. {t_end} s) {problem}")]
    #[diagnostic(code(recording::segment_outside), help("{help}"))]
    SegmentOutside {
        /// File name.
        file: String,
        /// Line.
        line: u64,
        /// Column.
        column: u64,
        /// Segment id.
        id: String,
        /// Start, s.
        t_start: f64,
        /// End, s.
        t_end: f64,
        /// What is wrong.
        problem: String,
        /// What would fix it.
        help: String,
        /// File text.
        #[source_code]
        src: Excerpt,
        /// The segment.
        #[label("this segment")]
        span: SourceSpan,
    },

    /// A segment without IMU samples.
    #[error(
        "{file}:{line}:{column}: segment `{id}` ({t_start} s .. {t_end} s) holds no IMU sample"
    )]
    #[diagnostic(
        code(recording::empty_segment),
        help("a segment covers at least one IMU sample; check its times against imu.csv")
    )]
    EmptySegment {
        /// File name.
        file: String,
        /// Line.
        line: u64,
        /// Column.
        column: u64,
        /// Segment id.
        id: String,
        /// Start, s.
        t_start: f64,
        /// End, s.
        t_end: f64,
        /// File text.
        #[source_code]
        src: Excerpt,
        /// The segment.
        #[label("empty segment")]
        span: SourceSpan,
    },
}

/// A stream with fewer than two samples, located where its text ends.
pub(crate) fn empty_stream(file: &str, bytes: &[u8]) -> RecordingError {
    let end = bytes.trim_ascii_end().len();
    let (line, column) = line_col_bytes(bytes, end);
    let (src, span) = Excerpt::around(file, bytes, end, end);
    RecordingError::EmptyStream {
        file: file.to_string(),
        line,
        column: column as u64,
        src,
        span,
    }
}

/// 1-based line and column of a byte offset, lines broken at LF, CRLF or a bare CR (as
/// YAML, the csv crate and miette's snippets break them); the column counts characters.
pub(crate) fn line_col(text: &str, offset: usize) -> (u64, u64) {
    let (line, column) = line_col_bytes(text.as_bytes(), offset);
    (line, column as u64)
}

/// `line_col` of raw bytes (invalid UTF-8 counts one character a byte).
pub(crate) fn line_col_bytes(bytes: &[u8], offset: usize) -> (u64, usize) {
    let before = &bytes[..offset.min(bytes.len())];
    let mut line = 1;
    let mut start = 0;
    for (i, &b) in before.iter().enumerate() {
        let lone_cr = b == b'\r' && bytes.get(i + 1) != Some(&b'\n');
        if b == b'\n' || lone_cr {
            line += 1;
            start = i + 1;
        }
    }
    // Counted without copying the line (it may be a gigabyte without a line break).
    let column = before[start..]
        .utf8_chunks()
        .map(|c| c.valid().chars().count() + c.invalid().len())
        .sum::<usize>()
        + 1;
    (line, column)
}

/// Byte offset of 1-based `line` and character `column` in a YAML text, lines broken as
/// YAML (and miette) break them: LF, CRLF or a bare CR. Turns the line and column that
/// serde-saphyr reports into a span (recording manifests here, station files in the drivers).
pub fn yaml_offset(text: &str, line: u64, column: u64) -> usize {
    let b = text.as_bytes();
    let mut start = 0;
    for _ in 1..line {
        match b[start..].iter().position(|&c| c == b'\n' || c == b'\r') {
            Some(p) => {
                start += p + 1;
                if b[start - 1] == b'\r' && b.get(start) == Some(&b'\n') {
                    start += 1;
                }
            }
            None => return text.len(),
        }
    }
    text[start..]
        .char_indices()
        .nth(column.saturating_sub(1) as usize)
        .map_or(text.len(), |(i, _)| start + i)
}
