//! What the format promises beyond each cell: time strictly increasing, at least two
//! samples, segments inside both streams and not empty. A problem is located by reading
//! the file again (only then).

// A refused recording is built once per read: the error's size costs nothing.
#![allow(clippy::result_large_err)]

use super::csvread::{cell_offset, row_start};
use super::io_error;
use super::locate::find_segment;
use crate::Manifest;
use crate::error::{RecordingError, empty_stream, line_col, line_col_bytes};
use crate::excerpt::Excerpt;
use std::path::Path;

/// Time strictly increasing, at least two rows; a problem is located by reading the file
/// again (only then).
pub(super) fn check_time(path: &Path, t: &[f64]) -> Result<(), RecordingError> {
    if t.len() < 2 {
        return Err(too_few(path));
    }
    match t.windows(2).position(|w| w[1] <= w[0]) {
        Some(k) => Err(time_error(path, k + 1, t[k], t[k + 1])),
        None => Ok(()),
    }
}

/// A stream with fewer than two samples, located where its text ends.
pub(super) fn too_few(path: &Path) -> RecordingError {
    match std::fs::read(path) {
        Ok(bytes) => empty_stream(&path.display().to_string(), &bytes),
        Err(e) => io_error(path, e),
    }
}

/// Data row `row` (0-based) whose time `t` is not after the previous row's `prev`.
pub(super) fn time_error(path: &Path, row: usize, prev: f64, t: f64) -> RecordingError {
    match t_cell(path, row) {
        Ok((file, line, column, src, span)) => RecordingError::TimeNotIncreasing {
            file,
            line,
            column,
            t,
            prev,
            src,
            span,
        },
        Err(e) => e,
    }
}

/// The IMU and table streams share no time (sanity check `clocks_overlap`), located at
/// the table's first stamp.
pub(super) fn check_overlap(
    table_path: &Path,
    imu: Extent,
    table: Extent,
) -> Result<(), RecordingError> {
    if imu.first.max(table.first) < imu.last.min(table.last) {
        return Ok(());
    }
    let (file, line, column, src, span) = t_cell(table_path, 0)?;
    Err(RecordingError::ClocksDisjoint {
        file,
        line,
        column,
        table_first: table.first,
        table_last: table.last,
        imu_first: imu.first,
        imu_last: imu.last,
        src,
        span,
    })
}

/// File name, line, column, text and span of the `t` cell of data row `row` (0-based).
fn t_cell(
    path: &Path,
    row: usize,
) -> Result<(String, u64, usize, Excerpt, miette::SourceSpan), RecordingError> {
    let file = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| io_error(path, e))?;
    let start = row_start(&bytes, row);
    let line = line_col_bytes(&bytes, start).0;
    let header = &bytes[..bytes
        .iter()
        .position(|&b| b == b'\n' || b == b'\r')
        .unwrap_or(bytes.len())];
    let field = header
        .split(|&b| b == b',')
        .position(|f| f.trim_ascii() == b"t")
        .unwrap_or(0);
    let (offset, column) = cell_offset(&bytes, start, field);
    let len = bytes[offset..]
        .iter()
        .position(|&b| b == b',' || b == b'\n' || b == b'\r')
        .unwrap_or(1)
        .max(1);
    let (src, span) = Excerpt::around(&file, &bytes, offset, offset + len);
    Ok((file, line, column, src, span))
}

/// The first two and the last time stamps of a stream of at least two: what the segment
/// checks need of it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Extent {
    pub first: f64,
    pub second: f64,
    pub last: f64,
}

impl Extent {
    pub fn of(t: &[f64]) -> Self {
        Extent {
            first: t[0],
            second: t[1],
            last: t[t.len() - 1],
        }
    }
}

/// Whether `t` (increasing) holds a stamp in `[t_start, t_end]`.
pub(super) fn holds_sample(t: &[f64], t_start: f64, t_end: f64) -> bool {
    let a = t.partition_point(|&x| x < t_start);
    let b = t.partition_point(|&x| x <= t_end);
    b > a
}

pub(super) fn check_segments(
    file: &str,
    text: &str,
    m: &Manifest,
    imu: Extent,
    table: Extent,
    imu_holds_sample: impl Fn(f64, f64) -> bool,
) -> Result<(), RecordingError> {
    let lo = imu.first.max(table.first);
    let hi = imu.last.min(table.last);
    // Half a table step of slack: a window may start or end between two feedback samples.
    let slack = 0.5
        * (table.second - table.first)
            .abs()
            .max((imu.second - imu.first).abs());
    let mut search_from = 0;
    for seg in &m.segments {
        let offset = find_segment(text, &seg.id, search_from);
        search_from = offset;
        let (line, column) = line_col(text, offset);
        let len = text[offset..]
            .find('\n')
            .unwrap_or(text.len() - offset)
            .max(1);
        let outside = |problem: String, help: String| RecordingError::SegmentOutside {
            file: file.to_string(),
            line,
            column,
            id: seg.id.clone(),
            t_start: seg.t_start,
            t_end: seg.t_end,
            problem,
            help,
            src: Excerpt::around(file, text.as_bytes(), offset, offset + len).0,
            span: Excerpt::around(file, text.as_bytes(), offset, offset + len).1,
        };
        if !(seg.t_start.is_finite() && seg.t_end.is_finite()) || seg.t_end <= seg.t_start {
            return Err(outside(
                "ends before it starts".into(),
                "t_end must be later than t_start".into(),
            ));
        }
        if seg.t_start < lo - slack || seg.t_end > hi + slack {
            return Err(outside(
                format!("is outside the streams ({lo} s .. {hi} s)"),
                "a segment lies inside both imu.csv and table.csv; check its times".into(),
            ));
        }
        if let Some((problem, help)) = attitude_problem(seg) {
            return Err(RecordingError::BadAttitude {
                file: file.to_string(),
                line,
                column,
                id: seg.id.clone(),
                problem,
                help,
                src: Excerpt::around(file, text.as_bytes(), offset, offset + len).0,
                span: Excerpt::around(file, text.as_bytes(), offset, offset + len).1,
            });
        }
        if !imu_holds_sample(seg.t_start, seg.t_end) {
            return Err(RecordingError::EmptySegment {
                file: file.to_string(),
                line,
                column,
                id: seg.id.clone(),
                t_start: seg.t_start,
                t_end: seg.t_end,
                src: Excerpt::around(file, text.as_bytes(), offset, offset + len).0,
                span: Excerpt::around(file, text.as_bytes(), offset, offset + len).1,
            });
        }
    }
    Ok(())
}

/// What is wrong with a segment's `attitude` and `tolerance_deg`, and what would fix it.
fn attitude_problem(seg: &crate::Segment) -> Option<(String, String)> {
    let tol = seg.tolerance_deg;
    match seg.attitude {
        Some(crate::Attitude::Nominal) => match tol {
            None => Some((
                "is `attitude: nominal` without `tolerance_deg`".into(),
                "a nominal attitude says how well it is known: add `tolerance_deg` (deg, e.g. \
                 `tolerance_deg: 0.5` for a fixture's face placed on a bench)"
                    .into(),
            )),
            Some(t) if !(t.is_finite() && t > 0.0) => Some((
                format!("has `tolerance_deg: {t}`"),
                "tolerance_deg is a positive number of degrees".into(),
            )),
            _ => None,
        },
        _ => None,
    }
}
