//! Reading a recording folder written by any acquisition system.

// A refused recording is built once per read: the error's size costs nothing.
#![allow(clippy::result_large_err)]

mod check;
mod csvread;
mod fast;
mod index;
mod lines;
mod locate;
mod manifest;
mod number;
mod scan;
mod span;
mod stream;
mod validate;

pub use manifest::parse_manifest;
pub use span::{OpenRecording, SpanRows};

use crate::error::RecordingError;
use crate::{ImuStream, Manifest, Recording, TableStream};
use check::Extent;
use csvread::read_columns;
use std::path::Path;
use stream::Stream;

/// Reads `dir/manifest.yaml`, `dir/imu.csv` and `dir/table.csv`, checking what the format
/// promises: columns present, numbers finite, time strictly increasing, segments inside
/// both streams and not empty.
pub fn read(dir: &Path) -> Result<Recording, RecordingError> {
    let (manifest_name, manifest_text, manifest) = read_manifest(dir)?;

    let imu_path = dir.join(ImuStream::FILE);
    let table_path = dir.join(TableStream::FILE);
    let (imu, table) = fast::fast_streams(&imu_path, &table_path)?;
    let imu = match imu {
        Some(s) => s,
        None => exact(&imu_path)?,
    };
    let table = match table {
        Some(s) => s,
        None => exact(&table_path)?,
    };
    check::check_time(&imu_path, &imu.t)?;
    check::check_time(&table_path, &table.t)?;
    check::check_overlap(&table_path, Extent::of(&imu.t), Extent::of(&table.t))?;
    check::check_segments(
        &manifest_name,
        &manifest_text,
        &manifest,
        Extent::of(&imu.t),
        Extent::of(&table.t),
        |a, b| check::holds_sample(&imu.t, a, b),
    )?;
    Ok(Recording {
        manifest,
        imu,
        table,
    })
}

/// `dir/manifest.yaml`: its name as errors show it, its text, and the parsed manifest.
fn read_manifest(dir: &Path) -> Result<(String, String, Manifest), RecordingError> {
    let path = dir.join("manifest.yaml");
    crate::files::regular(&path).map_err(|e| io_error(&path, e))?;
    let bytes = std::fs::read(&path).map_err(|e| io_error(&path, e))?;
    let name = path.display().to_string();
    let text = String::from_utf8_lossy(&bytes).into_owned();
    let manifest = parse_manifest(&name, &text)?;
    Ok((name, text, manifest))
}

fn io_error(path: &Path, e: std::io::Error) -> RecordingError {
    RecordingError::Io {
        file: path.display().to_string(),
        message: e.to_string(),
    }
}

/// The exact reader (csv crate), for what the fast path does not handle: it accepts
/// quoted cells and locates every problem.
fn exact<S: Stream>(path: &Path) -> Result<S, RecordingError> {
    lines::refuse_long_lines(path)?;
    let bytes = std::fs::read(path).map_err(|e| io_error(path, e))?;
    let file = path.display().to_string();
    read_columns(&file, &bytes, S::REQUIRED, &[S::OPTIONAL]).map(S::from_columns)
}

/// Reads one stream file (`imu.csv`, `table.csv`) as `read` reads it: columns present,
/// numbers finite, time strictly increasing.
fn read_stream<S: Stream>(path: &Path) -> Result<S, RecordingError> {
    let s = match fast::fast_one::<S>(path)? {
        Some(s) => s,
        None => exact::<S>(path)?,
    };
    check::check_time(path, s.t())?;
    Ok(s)
}

/// Reads an `imu.csv` on its own (the replay driver's IMU), checked as [`read`] checks it.
pub fn read_imu(path: &Path) -> Result<ImuStream, RecordingError> {
    read_stream(path)
}

/// Reads a `table.csv` on its own (the replay driver's table), checked as [`read`] checks it.
pub fn read_table(path: &Path) -> Result<TableStream, RecordingError> {
    read_stream(path)
}
