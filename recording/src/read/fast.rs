//! Both streams by the fast path (`scan`): the IMU file split over two threads, the table
//! file on the second.

use super::io_error;
use super::scan::{self, Layout, SKIP};
use super::stream::Stream;
use crate::error::RecordingError;
use crate::{ImuStream, TableStream};
use std::path::Path;

/// Where the columns of stream `S` are in a header, and whether it has the optional one;
/// `None` when a required one is missing (the exact reader then says so, located).
pub(super) fn layout<S: Stream>(names: &[String], data_start: u64) -> Option<(Layout, bool)> {
    let mut want = vec![SKIP; names.len()];
    for (slot, c) in S::REQUIRED.iter().enumerate() {
        let i = names.iter().position(|n| n == c)?;
        want[i] = slot;
    }
    let opt = names.iter().position(|n| n == S::OPTIONAL);
    if let Some(i) = opt {
        want[i] = S::REQUIRED.len();
    }
    Some((Layout::new(want, data_start), opt.is_some()))
}

/// The header of `path` (names, where the data starts) and the file's length.
pub(super) fn head(p: &Path) -> Result<(Vec<String>, u64, u64), RecordingError> {
    // A FIFO or device is refused before it is opened (opening a FIFO blocks).
    crate::files::regular(p).map_err(|e| io_error(p, e))?;
    let (names, start) = scan::header(p).map_err(|e| io_error(p, e))?;
    let len = std::fs::metadata(p).map_err(|e| io_error(p, e))?.len();
    Ok((names, start, len))
}

/// One stream by the fast path, on this thread; `None` when the exact reader must read it.
pub(super) fn fast_one<S: Stream>(path: &Path) -> Result<Option<S>, RecordingError> {
    let (names, start, len) = head(path)?;
    let Some((l, optional)) = layout::<S>(&names, start) else {
        return Ok(None);
    };
    let rows = scan::rows_for(scan::line_density(path, start, len), len - start);
    let mut all = S::with_capacity(optional, rows);
    Ok(scan::scan_range(path, &l, start, len, &mut all)
        .ok()
        .map(|_| all))
}

/// Both streams by the fast path (`scan`), the IMU file split over two threads with the
/// table file on the second; `None` for a stream the exact reader must read instead.
#[allow(clippy::type_complexity)]
pub(super) fn fast_streams(
    imu_path: &Path,
    table_path: &Path,
) -> Result<(Option<ImuStream>, Option<TableStream>), RecordingError> {
    let (imu_names, imu_start, imu_len) = head(imu_path)?;
    let (table_names, table_start, table_len) = head(table_path)?;
    let imu_layout = layout::<ImuStream>(&imu_names, imu_start);
    let table_layout = layout::<TableStream>(&table_names, table_start);
    // Columns are sized once from the line density, so that they neither grow by doubling
    // nor move when the second part is appended to the first (at 1 kHz that is hundreds of
    // megabytes).
    let imu_density = scan::line_density(imu_path, imu_start, imu_len);
    let imu_rows = |from: u64| scan::rows_for(imu_density, imu_len - from);
    let new_imu = ImuStream::with_capacity;
    let table_density = scan::line_density(table_path, table_start, table_len);
    let table_rows = scan::rows_for(table_density, table_len - table_start);
    let new_table = |amb: bool| TableStream::with_capacity(amb, table_rows);
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
