//! Where the analysis reads a recording from: a [`Recording`] held in memory, or a
//! recording folder read span by span ([`Streamed`]) so that a long 1 kHz run is analysed
//! in bounded memory. Either way the analysis sees the manifest, the table feedback (small:
//! tens of hertz) and the IMU rows of one time span at a time ([`ImuView`]).

use crate::recording::{
    CadenceReport, Manifest, OpenRecording, Recording, RecordingError, TableStream,
};
use std::borrow::Cow;
use std::convert::Infallible;
use std::path::Path;

/// The IMU rows of one span, borrowed column by column.
#[derive(Debug, Clone, Copy)]
pub struct ImuView<'a> {
    /// Stamps, s.
    pub t: &'a [f64],
    /// Accelerometer outputs per axis, m/s^2.
    pub accel: [&'a [f64]; 3],
    /// Gyro outputs per axis, deg/s.
    pub gyro: [&'a [f64]; 3],
    /// IMU internal temperature, degC.
    pub temp: Option<&'a [f64]>,
}

impl<'a> ImuView<'a> {
    /// The first `n` rows of a view.
    fn of_view(v: &ImuView<'a>, n: usize) -> Self {
        ImuView {
            t: &v.t[..n],
            accel: v.accel.map(|x| &x[..n]),
            gyro: v.gyro.map(|x| &x[..n]),
            temp: v.temp.map(|x| &x[..n]),
        }
    }

    /// Rows `a..b` of a stream.
    pub fn of(s: &'a crate::recording::ImuStream, a: usize, b: usize) -> Self {
        ImuView {
            t: &s.t[a..b],
            accel: std::array::from_fn(|k| &s.accel[k][a..b]),
            gyro: std::array::from_fn(|k| &s.gyro[k][a..b]),
            temp: s.temp.as_ref().map(|x| &x[a..b]),
        }
    }
}

/// The IMU rows of one span to work on: the stamps and temperatures borrowed, the six
/// outputs (`ax ay az gx gy gz`) the span's own when the source read them for it (a filter
/// then writes them in place), else borrowed (copied on the first write).
#[derive(Debug)]
pub struct ImuWork<'a> {
    /// Stamps, s.
    pub t: &'a [f64],
    /// IMU internal temperature, degC.
    pub temp: Option<&'a [f64]>,
    /// The outputs, accelerometers (m/s^2) then gyros (deg/s).
    pub outputs: [Cow<'a, [f64]>; 6],
}

impl<'a> ImuWork<'a> {
    /// The rows of a view, borrowed.
    fn borrowed(v: ImuView<'a>) -> Self {
        ImuWork {
            t: v.t,
            temp: v.temp,
            outputs: std::array::from_fn(|c| {
                Cow::Borrowed(if c < 3 { v.accel[c] } else { v.gyro[c - 3] })
            }),
        }
    }
}

/// A recording as the analysis reads it.
pub trait Source: Sync {
    /// Why a span could not be read.
    type Error: Send;
    /// The manifest.
    fn manifest(&self) -> &Manifest;
    /// The whole table feedback stream.
    fn table(&self) -> &TableStream;
    /// IMU rows in the recording.
    fn imu_rows(&self) -> usize;
    /// First and last IMU stamp, s.
    fn imu_extent(&self) -> (f64, f64);
    /// Gaps, jitter and order of the IMU stamps.
    fn imu_cadence(&self) -> CadenceReport;
    /// Whether the IMU stream has the temperature column.
    fn has_temp(&self) -> bool;
    /// The mean of its finite temperatures over every row, degC (0 without any).
    fn mean_temp(&self) -> Result<f64, Self::Error>;
    /// Hands `f` the IMU rows with `t0 <= t <= t1`.
    fn rows<R>(&self, t0: f64, t1: f64, f: impl FnOnce(ImuView<'_>) -> R)
    -> Result<R, Self::Error>;
    /// The whole recording in memory: for the analyses that navigate the raw stream (the
    /// size effect's cycles, from the static blocks before them).
    fn recording(&self) -> Result<Cow<'_, Recording>, Self::Error>;

    /// Hands `f` the IMU rows with `t0 <= t <= t1` to work on ([`ImuWork`]); by default
    /// borrowed from [`Source::rows`].
    fn rows_to_work<R>(
        &self,
        t0: f64,
        t1: f64,
        f: impl FnOnce(ImuWork<'_>) -> R,
    ) -> Result<R, Self::Error>
    where
        Self: Sized,
    {
        self.rows(t0, t1, |v| f(ImuWork::borrowed(v)))
    }

    /// Every `every`-th IMU row's `(t, temp)`, counting from the first row: empty without
    /// the column. As [`Source::windows`] sees them; a source may read the two cells alone.
    fn temp_every(&self, every: usize) -> Result<Vec<(f64, f64)>, Self::Error>
    where
        Self: Sized,
    {
        let every = every.max(1);
        let (mut kept, mut row) = (Vec::new(), 0usize);
        if self.has_temp() {
            self.windows(super::WINDOW_ROWS, |v| {
                if let Some(temp) = v.temp {
                    for (t, c) in v.t.iter().zip(temp) {
                        if row.is_multiple_of(every) {
                            kept.push((*t, *c));
                        }
                        row += 1;
                    }
                }
            })?;
        }
        Ok(kept)
    }

    /// Hands `f` every IMU row once, in order, a window of about `rows` rows at a time.
    fn windows(&self, rows: usize, mut f: impl FnMut(ImuView<'_>)) -> Result<(), Self::Error>
    where
        Self: Sized,
    {
        let (n, (t0, t1)) = (self.imu_rows(), self.imu_extent());
        if n == 0 {
            return Ok(());
        }
        let k = n.div_ceil(rows.max(1)).max(1);
        let at = |i: usize| t0 + (t1 - t0) * i as f64 / k as f64;
        for i in 0..k {
            let (a, b, last) = (at(i), at(i + 1), i + 1 == k);
            self.rows(a, if last { t1 } else { b }, |v| {
                // A window owns the rows before its end (the last one, its end too).
                let own = if last {
                    v.t.len()
                } else {
                    v.t.partition_point(|&t| t < b)
                };
                f(ImuView::of_view(&v, own));
            })?;
        }
        Ok(())
    }
}

impl Source for Recording {
    type Error = Infallible;

    fn manifest(&self) -> &Manifest {
        &self.manifest
    }

    fn table(&self) -> &TableStream {
        &self.table
    }

    fn imu_rows(&self) -> usize {
        self.imu.t.len()
    }

    fn imu_extent(&self) -> (f64, f64) {
        let t = &self.imu.t;
        (
            t.first().copied().unwrap_or(0.0),
            t.last().copied().unwrap_or(0.0),
        )
    }

    fn imu_cadence(&self) -> CadenceReport {
        CadenceReport::of(&self.imu.t)
    }

    fn has_temp(&self) -> bool {
        self.imu.temp.is_some()
    }

    fn mean_temp(&self) -> Result<f64, Infallible> {
        let (s, n) = self
            .imu
            .temp
            .iter()
            .flatten()
            .filter(|x| x.is_finite())
            .fold((0.0, 0usize), |(s, n), x| (s + x, n + 1));
        Ok(if n == 0 { 0.0 } else { s / n as f64 })
    }

    fn rows<R>(&self, t0: f64, t1: f64, f: impl FnOnce(ImuView<'_>) -> R) -> Result<R, Infallible> {
        let t = &self.imu.t;
        let a = t.partition_point(|&x| x < t0);
        let b = t.partition_point(|&x| x <= t1).max(a);
        Ok(f(ImuView::of(&self.imu, a, b)))
    }

    fn recording(&self) -> Result<Cow<'_, Recording>, Infallible> {
        Ok(Cow::Borrowed(self))
    }
}

/// A recording folder opened for reading by time span (its table feedback in memory).
#[derive(Debug, Clone)]
pub struct Streamed {
    open: OpenRecording,
    /// The IMU's mean temperature once read: a whole pass over the stream, which explain's
    /// accumulation and the twin's comparison both ask for.
    mean_temp: std::sync::OnceLock<f64>,
}

impl Streamed {
    /// Opens `dir`: the manifest, an index of the IMU stream by time, the table feedback.
    /// The IMU cells outside the time column are checked when their span is read.
    #[allow(clippy::result_large_err)]
    pub fn open(dir: &Path) -> Result<Self, RecordingError> {
        Ok(Streamed {
            open: Recording::open(dir)?,
            mean_temp: std::sync::OnceLock::new(),
        })
    }
}

impl Source for Streamed {
    type Error = RecordingError;

    fn manifest(&self) -> &Manifest {
        self.open.manifest()
    }

    fn table(&self) -> &TableStream {
        self.open.table()
    }

    fn imu_rows(&self) -> usize {
        self.open.imu_rows()
    }

    fn imu_extent(&self) -> (f64, f64) {
        self.open.imu_extent()
    }

    fn imu_cadence(&self) -> CadenceReport {
        self.open.imu_cadence()
    }

    fn has_temp(&self) -> bool {
        self.open.imu_has_temp()
    }

    fn mean_temp(&self) -> Result<f64, RecordingError> {
        if let Some(&t) = self.mean_temp.get() {
            return Ok(t);
        }
        let t = self.open.imu_mean_temp()?.unwrap_or(0.0);
        Ok(*self.mean_temp.get_or_init(|| t))
    }

    fn temp_every(&self, every: usize) -> Result<Vec<(f64, f64)>, RecordingError> {
        Ok(self.open.imu_temp_every(every)?.unwrap_or_default())
    }

    fn rows<R>(
        &self,
        t0: f64,
        t1: f64,
        f: impl FnOnce(ImuView<'_>) -> R,
    ) -> Result<R, RecordingError> {
        let s = self.open.read_imu_span(t0, t1)?;
        Ok(f(ImuView::of(&s, 0, s.t.len())))
    }

    /// The span read is the work's: its outputs are handed over, not copied.
    fn rows_to_work<R>(
        &self,
        t0: f64,
        t1: f64,
        f: impl FnOnce(ImuWork<'_>) -> R,
    ) -> Result<R, RecordingError> {
        let s = self.open.read_imu_span(t0, t1)?;
        let [ax, ay, az] = s.accel;
        let [gx, gy, gz] = s.gyro;
        Ok(f(ImuWork {
            t: &s.t,
            temp: s.temp.as_deref(),
            outputs: [ax, ay, az, gx, gy, gz].map(Cow::Owned),
        }))
    }

    fn recording(&self) -> Result<Cow<'_, Recording>, RecordingError> {
        Ok(Cow::Owned(Recording {
            manifest: self.open.manifest().clone(),
            imu: self.open.read_imu_span(f64::NEG_INFINITY, f64::INFINITY)?,
            table: self.open.table().clone(),
        }))
    }
}
