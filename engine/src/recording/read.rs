//! Reading a recording folder written by any acquisition system.

// A refused recording is built once per read: the error's size costs nothing.
#![allow(clippy::result_large_err)]

use super::csvread::{Columns, cell_offset, read_columns};
use super::error::{RecordingError, line_col};
use super::{FORMAT, ImuStream, Manifest, Recording, TableStream};
use miette::NamedSource;
use std::path::Path;

const IMU_COLS: [&str; 7] = ["t", "ax", "ay", "az", "gx", "gy", "gz"];
const TABLE_COLS: [&str; 5] = ["t", "outer", "inner", "outer_rate", "inner_rate"];

/// Reads `dir/manifest.yaml`, `dir/imu.csv` and `dir/table.csv`, checking what the format
/// promises: columns present, numbers finite, time strictly increasing, segments inside
/// both streams and not empty.
pub fn read(dir: &Path) -> Result<Recording, RecordingError> {
    let load = |name: &str| {
        let path = dir.join(name);
        std::fs::read(&path).map_err(|e| RecordingError::Io {
            file: path.display().to_string(),
            message: e.to_string(),
        })
    };
    let manifest_bytes = load("manifest.yaml")?;
    let imu_bytes = load("imu.csv")?;
    let table_bytes = load("table.csv")?;
    let manifest_name = dir.join("manifest.yaml").display().to_string();
    let manifest_text = String::from_utf8_lossy(&manifest_bytes).into_owned();
    let manifest = parse_manifest(&manifest_name, &manifest_text)?;

    let imu_name = dir.join("imu.csv").display().to_string();
    let table_name = dir.join("table.csv").display().to_string();
    // The two files are independent: parse them on two threads.
    let (imu, table) = std::thread::scope(|s| {
        let h = s.spawn(|| parse_imu(&imu_name, &imu_bytes));
        let table = parse_table(&table_name, &table_bytes);
        (h.join().expect("imu reader thread"), table)
    });
    let (imu, table) = (imu?, table?);
    check_segments(&manifest_name, &manifest_text, &manifest, &imu, &table)?;
    Ok(Recording {
        manifest,
        imu,
        table,
    })
}

/// Parses manifest text (`file` names it in errors).
pub fn parse_manifest(file: &str, text: &str) -> Result<Manifest, RecordingError> {
    let manifest: Manifest = serde_saphyr::from_str(text).map_err(|e| {
        let (offset, len, line, column) = match e.location() {
            Some(loc) => {
                let off = loc.span().byte_offset().unwrap_or(0) as usize;
                let len = loc.span().byte_len().unwrap_or(1) as usize;
                (off, len, loc.line(), loc.column())
            }
            None => (0, 0, 1, 1),
        };
        let message = e.to_string();
        let message = message.lines().next().unwrap_or("invalid manifest");
        // The parser's message repeats the location we print already.
        let message = message.strip_prefix("error: ").unwrap_or(message);
        let message = match message
            .strip_prefix("line ")
            .and_then(|m| m.split_once(": "))
        {
            Some((_, rest)) => rest.to_string(),
            None => message.to_string(),
        };
        RecordingError::Manifest {
            file: file.to_string(),
            line,
            column,
            message,
            src: NamedSource::new(file, text.to_string()),
            span: (offset.min(text.len()), len).into(),
        }
    })?;
    if manifest.format != FORMAT {
        let offset = text
            .find(&manifest.format)
            .or_else(|| text.find("format"))
            .unwrap_or(0);
        let (line, column) = line_col(text, offset);
        return Err(RecordingError::UnknownFormat {
            file: file.to_string(),
            line,
            column,
            found: manifest.format.clone(),
            src: NamedSource::new(file, text.to_string()),
            span: (offset, manifest.format.len().max(1)).into(),
        });
    }
    Ok(manifest)
}

fn parse_imu(file: &str, bytes: &[u8]) -> Result<ImuStream, RecordingError> {
    let Columns { mut cols, lines } = read_columns(file, bytes, &IMU_COLS, &["temp"])?;
    let mut take = |k: usize| cols[k].take().expect("required column");
    let t = take(0);
    check_time(file, bytes, &t, &lines)?;
    let (ax, ay, az, gx, gy, gz) = (take(1), take(2), take(3), take(4), take(5), take(6));
    let accel = (0..t.len()).map(|i| [ax[i], ay[i], az[i]]).collect();
    let gyro = (0..t.len()).map(|i| [gx[i], gy[i], gz[i]]).collect();
    Ok(ImuStream {
        t,
        accel,
        gyro,
        temp: cols[7].take(),
    })
}

fn parse_table(file: &str, bytes: &[u8]) -> Result<TableStream, RecordingError> {
    let Columns { mut cols, lines } = read_columns(file, bytes, &TABLE_COLS, &["ambient"])?;
    let mut take = |k: usize| cols[k].take().expect("required column");
    let t = take(0);
    check_time(file, bytes, &t, &lines)?;
    Ok(TableStream {
        t,
        outer: take(1),
        inner: take(2),
        outer_rate: take(3),
        inner_rate: take(4),
        ambient: cols[5].take(),
    })
}

fn check_time(file: &str, bytes: &[u8], t: &[f64], lines: &[u64]) -> Result<(), RecordingError> {
    if t.len() < 2 {
        return Err(RecordingError::EmptyStream {
            file: file.to_string(),
        });
    }
    let Some(k) = t.windows(2).position(|w| w[1] <= w[0]) else {
        return Ok(());
    };
    let line = lines[k + 1];
    // Find the byte where that line starts, and the `t` column in it.
    let start = line_start(bytes, line);
    let header = &bytes[..bytes
        .iter()
        .position(|&b| b == b'\n')
        .unwrap_or(bytes.len())];
    let field = header
        .split(|&b| b == b',')
        .position(|f| f.trim_ascii() == b"t")
        .unwrap_or(0);
    let (offset, column) = cell_offset(bytes, start, field);
    let len = bytes[offset..]
        .iter()
        .position(|&b| b == b',' || b == b'\n')
        .unwrap_or(1)
        .max(1);
    Err(RecordingError::TimeNotIncreasing {
        file: file.to_string(),
        line,
        column,
        t: t[k + 1],
        prev: t[k],
        src: NamedSource::new(file, String::from_utf8_lossy(bytes).into_owned()),
        span: (offset, len).into(),
    })
}

fn line_start(bytes: &[u8], line: u64) -> usize {
    if line <= 1 {
        return 0;
    }
    let mut seen = 1;
    for (i, &b) in bytes.iter().enumerate() {
        if b == b'\n' {
            seen += 1;
            if seen == line {
                return i + 1;
            }
        }
    }
    bytes.len()
}

fn check_segments(
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

/// Byte offset of the start of the line that declares segment `id` (at or after `from`).
fn find_segment(text: &str, id: &str, from: usize) -> usize {
    let at = |needle: &str| text[from..].find(needle).map(|p| p + from);
    let hit = at(&format!("\"{id}\""))
        .or_else(|| at(&format!("'{id}'")))
        .or_else(|| at(&format!("id: {id}")));
    match hit {
        Some(p) => text[..p].rfind('\n').map_or(0, |n| n + 1),
        None => text.find("segments").unwrap_or(0),
    }
}
