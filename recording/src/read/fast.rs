//! Both streams by the fast path (`scan`): the IMU file split over two threads, the table
//! file on the second.

use super::io_error;
use super::scan::{self, Layout, MAX_SLOTS, RowSink, SKIP};
use super::{IMU_COLS, TABLE_COLS};
use crate::error::RecordingError;
use crate::{ImuStream, TableStream};
use std::path::Path;

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
pub(super) fn fast_streams(
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
