//! What the format promises beyond each cell: time strictly increasing, at least two
//! samples, segments inside both streams and not empty. A problem is located by reading
//! the file again (only then).

// A refused recording is built once per read: the error's size costs nothing.
#![allow(clippy::result_large_err)]

use super::csvread::{cell_offset, lossy_span, row_start};
use super::io_error;
use super::manifest::find_segment;
use crate::error::{RecordingError, empty_stream, line_col, line_col_bytes};
use crate::{ImuStream, Manifest, TableStream};
use miette::NamedSource;
use std::path::Path;

/// Time strictly increasing, at least two rows; a problem is located by reading the file
/// again (only then).
pub(super) fn check_time(path: &Path, t: &[f64]) -> Result<(), RecordingError> {
    let file = path.display().to_string();
    if t.len() < 2 {
        let bytes = std::fs::read(path).map_err(|e| io_error(path, e))?;
        return Err(empty_stream(&file, &bytes));
    }
    let Some(k) = t.windows(2).position(|w| w[1] <= w[0]) else {
        return Ok(());
    };
    let bytes = std::fs::read(path).map_err(|e| io_error(path, e))?;
    let start = row_start(&bytes, k + 1);
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
    Err(RecordingError::TimeNotIncreasing {
        file: file.clone(),
        line,
        column,
        t: t[k + 1],
        prev: t[k],
        src: NamedSource::new(file, String::from_utf8_lossy(&bytes).into_owned()),
        span: lossy_span(&bytes, offset, offset + len),
    })
}

pub(super) fn check_segments(
    file: &str,
    text: &str,
    m: &Manifest,
    imu: &ImuStream,
    table: &TableStream,
) -> Result<(), RecordingError> {
    let lo = imu.t[0].max(table.t[0]);
    let hi = imu.t[imu.t.len() - 1].min(table.t[table.t.len() - 1]);
    // Half a table step of slack: a window may start or end between two feedback samples.
    let slack = 0.5
        * (table.t[1] - table.t[0])
            .abs()
            .max((imu.t[1] - imu.t[0]).abs());
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
            src: NamedSource::new(file, text.to_string()),
            span: (offset, len).into(),
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
        let a = imu.t.partition_point(|&t| t < seg.t_start);
        let b = imu.t.partition_point(|&t| t <= seg.t_end);
        if b <= a {
            return Err(RecordingError::EmptySegment {
                file: file.to_string(),
                line,
                column,
                id: seg.id.clone(),
                t_start: seg.t_start,
                t_end: seg.t_end,
                src: NamedSource::new(file, text.to_string()),
                span: (offset, len).into(),
            });
        }
    }
    Ok(())
}
