//! Reading a recording folder written by any acquisition system.

// A refused recording is built once per read: the error's size costs nothing.
#![allow(clippy::result_large_err)]

use super::csvread::{Columns, cell_offset, lossy_span, read_columns, row_start};
use super::error::{RecordingError, empty_stream, line_col, line_col_bytes};
use super::scan::{self, Layout, MAX_SLOTS, RowSink, SKIP};
use super::{FORMAT, ImuStream, Manifest, Recording, TableStream};
use miette::NamedSource;
use ratecal_drivers::yaml_offset;
use std::path::Path;

const IMU_COLS: [&str; 7] = ["t", "ax", "ay", "az", "gx", "gy", "gz"];
const TABLE_COLS: [&str; 5] = ["t", "outer", "inner", "outer_rate", "inner_rate"];

/// Reads `dir/manifest.yaml`, `dir/imu.csv` and `dir/table.csv`, checking what the format
/// promises: columns present, numbers finite, time strictly increasing, segments inside
/// both streams and not empty.
pub fn read(dir: &Path) -> Result<Recording, RecordingError> {
    let manifest_path = dir.join("manifest.yaml");
    let manifest_bytes = std::fs::read(&manifest_path).map_err(|e| io_error(&manifest_path, e))?;
    let manifest_name = manifest_path.display().to_string();
    let manifest_text = String::from_utf8_lossy(&manifest_bytes).into_owned();
    let manifest = parse_manifest(&manifest_name, &manifest_text)?;

    let imu_path = dir.join("imu.csv");
    let table_path = dir.join("table.csv");
    let (imu, table) = fast_streams(&imu_path, &table_path)?;
    let imu = match imu {
        Some(s) => s,
        None => parse_imu(&imu_path)?,
    };
    let table = match table {
        Some(s) => s,
        None => parse_table(&table_path)?,
    };
    check_time(&imu_path, &imu.t)?;
    check_time(&table_path, &table.t)?;
    check_segments(&manifest_name, &manifest_text, &manifest, &imu, &table)?;
    Ok(Recording {
        manifest,
        imu,
        table,
    })
}

fn io_error(path: &Path, e: std::io::Error) -> RecordingError {
    RecordingError::Io {
        file: path.display().to_string(),
        message: e.to_string(),
    }
}

impl RowSink for ImuStream {
    #[inline]
    fn push(&mut self, r: &[f64; MAX_SLOTS]) {
        self.t.push(r[0]);
        for k in 0..3 {
            self.accel[k].push(r[1 + k]);
            self.gyro[k].push(r[4 + k]);
        }
        if let Some(tc) = &mut self.temp {
            tc.push(r[7]);
        }
    }
    fn append(&mut self, o: Self) {
        self.t.extend(o.t);
        for (a, b) in self
            .accel
            .iter_mut()
            .chain(&mut self.gyro)
            .zip(o.accel.into_iter().chain(o.gyro))
        {
            a.extend(b);
        }
        if let (Some(a), Some(b)) = (&mut self.temp, o.temp) {
            a.extend(b);
        }
    }
}

impl RowSink for TableStream {
    #[inline]
    fn push(&mut self, r: &[f64; MAX_SLOTS]) {
        self.t.push(r[0]);
        self.outer.push(r[1]);
        self.inner.push(r[2]);
        self.outer_rate.push(r[3]);
        self.inner_rate.push(r[4]);
        if let Some(a) = &mut self.ambient {
            a.push(r[5]);
        }
    }
    fn append(&mut self, o: Self) {
        self.t.extend(o.t);
        self.outer.extend(o.outer);
        self.inner.extend(o.inner);
        self.outer_rate.extend(o.outer_rate);
        self.inner_rate.extend(o.inner_rate);
        if let (Some(a), Some(b)) = (&mut self.ambient, o.ambient) {
            a.extend(b);
        }
    }
}

/// Where the asked columns are in a header; `None` when a required one is missing (the
/// exact reader then says so, located).
fn layout(
    names: &[String],
    required: &[&str],
    optional: &[&str],
    data_start: u64,
) -> Option<(Layout, bool)> {
    let mut want = vec![SKIP; names.len()];
    for (slot, c) in required.iter().enumerate() {
        let i = names.iter().position(|n| n == c)?;
        want[i] = slot;
    }
    let opt = optional
        .first()
        .and_then(|c| names.iter().position(|n| n == c));
    if let Some(i) = opt {
        want[i] = required.len();
    }
    Some((Layout { want, data_start }, opt.is_some()))
}

/// Both streams by the fast path (`scan`), the IMU file split over two threads with the
/// table file on the second; `None` for a stream the exact reader must read instead.
#[allow(clippy::type_complexity)]
fn fast_streams(
    imu_path: &Path,
    table_path: &Path,
) -> Result<(Option<ImuStream>, Option<TableStream>), RecordingError> {
    let head = |p: &Path| {
        let (names, start) = scan::header(p).map_err(|e| io_error(p, e))?;
        let len = std::fs::metadata(p).map_err(|e| io_error(p, e))?.len();
        Ok::<_, RecordingError>((names, start, len))
    };
    let (imu_names, imu_start, imu_len) = head(imu_path)?;
    let (table_names, table_start, table_len) = head(table_path)?;
    let imu_layout = layout(&imu_names, &IMU_COLS, &["temp"], imu_start);
    let table_layout = layout(&table_names, &TABLE_COLS, &["ambient"], table_start);
    // Columns are sized once from the line density, so that they neither grow by doubling
    // nor move when the second part is appended to the first (at 1 kHz that is hundreds of
    // megabytes).
    let imu_density = scan::line_density(imu_path, imu_start, imu_len);
    let imu_rows = |from: u64| scan::rows_for(imu_density, imu_len - from);
    let new_imu = |temp: bool, rows: usize| {
        let col = || Vec::with_capacity(rows);
        ImuStream {
            t: col(),
            accel: [col(), col(), col()],
            gyro: [col(), col(), col()],
            temp: temp.then(col),
        }
    };
    let table_density = scan::line_density(table_path, table_start, table_len);
    let table_rows = scan::rows_for(table_density, table_len - table_start);
    let new_table = |amb: bool| {
        let col = || Vec::with_capacity(table_rows);
        TableStream {
            t: col(),
            outer: col(),
            inner: col(),
            outer_rate: col(),
            inner_rate: col(),
            ambient: amb.then(col),
        }
    };
    let table_bytes = if table_layout.is_some() {
        table_len - table_start
    } else {
        0
    };
    let mid = match &imu_layout {
        Some(_) => scan::split_point((imu_start, imu_len), table_bytes),
        None => imu_start,
    };
    let (first, second) = std::thread::scope(|s| {
        let h = s.spawn(|| {
            let imu = imu_layout.as_ref().and_then(|(l, temp)| {
                let mut part = new_imu(*temp, imu_rows(mid));
                scan::scan_range(imu_path, l, mid, imu_len, &mut part)
                    .ok()
                    .map(|_| part)
            });
            let table = table_layout.as_ref().and_then(|(l, amb)| {
                let mut all = new_table(*amb);
                scan::scan_range(table_path, l, table_start, table_len, &mut all)
                    .ok()
                    .map(|_| all)
            });
            (imu, table)
        });
        let first = imu_layout.as_ref().and_then(|(l, temp)| {
            // The first part holds the whole stream once the second is appended.
            let mut part = new_imu(*temp, imu_rows(imu_start));
            scan::scan_range(imu_path, l, imu_start, mid, &mut part)
                .ok()
                .map(|_| part)
        });
        (first, h.join().expect("reader thread"))
    });
    let (second, table) = second;
    let imu = first.zip(second).map(|(mut a, b)| {
        a.append(b);
        a
    });
    Ok((imu, table))
}

/// Parses manifest text (`file` names it in errors).
pub fn parse_manifest(file: &str, text: &str) -> Result<Manifest, RecordingError> {
    let manifest: Manifest = serde_saphyr::from_str(text).map_err(|e| {
        let (offset, len, line, column) = match e.location() {
            // The parser's line and column locate the error; its span's byte offset is
            // absent at some scanner errors (the snippet then showed line 1), so it is
            // used only when it points where they do.
            Some(loc) if loc.line() > 0 => {
                let off = yaml_offset(text, loc.line(), loc.column());
                let len = match loc.span().byte_offset() {
                    Some(o) if o as usize == off => loc.span().byte_len().unwrap_or(1) as usize,
                    _ => 1,
                };
                (off, len, loc.line(), loc.column())
            }
            _ => (0, 0, 1, 1),
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
    super::validate::manifest(file, text, &manifest)?;
    Ok(manifest)
}

/// The exact reader (csv crate), for what the fast path does not handle: it accepts
/// quoted cells and locates every problem.
fn exact(path: &Path, required: &[&str], optional: &[&str]) -> Result<Columns, RecordingError> {
    let bytes = std::fs::read(path).map_err(|e| io_error(path, e))?;
    read_columns(&path.display().to_string(), &bytes, required, optional)
}

fn parse_imu(path: &Path) -> Result<ImuStream, RecordingError> {
    let Columns { mut cols } = exact(path, &IMU_COLS, &["temp"])?;
    let mut take = |k: usize| cols[k].take().expect("required column");
    Ok(ImuStream {
        t: take(0),
        accel: [take(1), take(2), take(3)],
        gyro: [take(4), take(5), take(6)],
        temp: cols[7].take(),
    })
}

fn parse_table(path: &Path) -> Result<TableStream, RecordingError> {
    let Columns { mut cols } = exact(path, &TABLE_COLS, &["ambient"])?;
    let mut take = |k: usize| cols[k].take().expect("required column");
    Ok(TableStream {
        t: take(0),
        outer: take(1),
        inner: take(2),
        outer_rate: take(3),
        inner_rate: take(4),
        ambient: cols[5].take(),
    })
}

/// Time strictly increasing, at least two rows; a problem is located by reading the file
/// again (only then).
fn check_time(path: &Path, t: &[f64]) -> Result<(), RecordingError> {
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
pub(crate) fn find_segment(text: &str, id: &str, from: usize) -> usize {
    let at = |needle: &str| text[from..].find(needle).map(|p| p + from);
    let hit = at(&format!("\"{id}\""))
        .or_else(|| at(&format!("'{id}'")))
        .or_else(|| at(&format!("id: {id}")));
    match hit {
        Some(p) => text[..p].rfind('\n').map_or(0, |n| n + 1),
        None => text.find("segments").unwrap_or(0),
    }
}
