//! Reading a recording folder written by any acquisition system.

// A refused recording is built once per read: the error's size costs nothing.
#![allow(clippy::result_large_err)]

mod check;
mod csvread;
mod fast;
mod manifest;
mod scan;
mod validate;

pub use manifest::parse_manifest;

use crate::error::RecordingError;
use crate::{ImuStream, Recording, TableStream};
use csvread::{Columns, read_columns};
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
    let (imu, table) = fast::fast_streams(&imu_path, &table_path)?;
    let imu = match imu {
        Some(s) => s,
        None => parse_imu(&imu_path)?,
    };
    let table = match table {
        Some(s) => s,
        None => parse_table(&table_path)?,
    };
    check::check_time(&imu_path, &imu.t)?;
    check::check_time(&table_path, &table.t)?;
    check::check_segments(&manifest_name, &manifest_text, &manifest, &imu, &table)?;
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
