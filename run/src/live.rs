//! The recent past of both streams, as the signals settle conditions and abort rules watch:
//! a bounded window (the longest stability window plus a margin), so memory does not grow
//! with the run.

use ratecal_plan::{Signal, Stability};
use std::collections::VecDeque;
use std::ops::Range;

/// One IMU sample as signals: accel x,y,z (m/s^2), gyro x,y,z (deg/s), temperature (degC,
/// NaN when not reported).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ImuRow {
    pub t: f64,
    pub v: [f64; 7],
}

/// One table sample as signals: attitude error (deg), rate error (deg/s), ambient (degC,
/// NaN when not measured), ambient drift (degC/h, NaN until estimable); and whether the
/// commanded motion is done.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct TableRow {
    pub t: f64,
    pub v: [f64; 4],
    pub reached: bool,
}

/// Which stream a signal comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Source {
    Imu,
    Table,
}

/// Stream and channel range of a signal.
pub(crate) fn channels(signal: Signal) -> (Source, Range<usize>) {
    match signal {
        Signal::Accel => (Source::Imu, 0..3),
        Signal::Gyro => (Source::Imu, 3..6),
        Signal::ImuTemperature => (Source::Imu, 6..7),
        Signal::AttitudeError => (Source::Table, 0..1),
        Signal::RateError => (Source::Table, 1..2),
        Signal::AmbientTemperature => (Source::Table, 2..3),
        Signal::AmbientDrift => (Source::Table, 3..4),
    }
}

/// Ambient drift estimate: least-squares slope of 1-second means over the last ten minutes
/// (at least one minute of data), degC/h.
#[derive(Debug, Default)]
struct Drift {
    bins: VecDeque<(f64, f64)>,
    bin_start: f64,
    sum: f64,
    n: u32,
    value: f64,
}

const DRIFT_WINDOW_S: f64 = 600.0;
const DRIFT_MIN_S: f64 = 60.0;

impl Drift {
    fn push(&mut self, t: f64, ambient: f64) -> f64 {
        if !ambient.is_finite() {
            return self.value_or_nan();
        }
        if self.n == 0 {
            self.bin_start = t;
        }
        self.sum += ambient;
        self.n += 1;
        if t - self.bin_start >= 1.0 {
            self.bins
                .push_back((0.5 * (self.bin_start + t), self.sum / f64::from(self.n)));
            self.sum = 0.0;
            self.n = 0;
            while self.bins.front().is_some_and(|b| t - b.0 > DRIFT_WINDOW_S) {
                self.bins.pop_front();
            }
            self.value = self.slope();
        }
        self.value_or_nan()
    }

    fn value_or_nan(&self) -> f64 {
        if self.bins.len() >= 2 {
            self.value
        } else {
            f64::NAN
        }
    }

    fn slope(&self) -> f64 {
        let (first, last) = match (self.bins.front(), self.bins.back()) {
            (Some(f), Some(l)) => (f.0, l.0),
            _ => return f64::NAN,
        };
        if last - first < DRIFT_MIN_S {
            return f64::NAN;
        }
        let n = self.bins.len() as f64;
        let mt = self.bins.iter().map(|b| b.0).sum::<f64>() / n;
        let my = self.bins.iter().map(|b| b.1).sum::<f64>() / n;
        let (mut sxy, mut sxx) = (0.0, 0.0);
        for &(t, y) in &self.bins {
            sxy += (t - mt) * (y - my);
            sxx += (t - mt) * (t - mt);
        }
        sxy / sxx * 3600.0
    }
}

/// IMU signals are watched as means over blocks of this length, s: a 10 Hz reading, like
/// an operator's display, so that a fluctuation limit means the same whatever the IMU's
/// sample rate (raw peak-to-peak of white noise grows with the bandwidth).
pub(crate) const IMU_BLOCK_S: f64 = 0.1;

/// One block of IMU samples: sums per channel (a NaN sample makes the mean NaN).
#[derive(Debug, Clone, Copy)]
struct Block {
    index: i64,
    first_t: f64,
    last_t: f64,
    n: u32,
    sum: [f64; 7],
}

impl Block {
    fn new(index: i64, row: &ImuRow) -> Self {
        Block {
            index,
            first_t: row.t,
            last_t: row.t,
            n: 1,
            sum: row.v,
        }
    }

    fn mean(&self, k: usize) -> f64 {
        self.sum[k] / f64::from(self.n)
    }
}

/// Recent samples of both streams.
#[derive(Debug)]
pub(crate) struct Live {
    /// Completed IMU blocks, oldest first.
    imu: VecDeque<Block>,
    /// The block being filled.
    current: Option<Block>,
    table: VecDeque<TableRow>,
    keep_s: f64,
    drift: Drift,
}

impl Live {
    /// A window long enough for every stability window of the plan (`longest_window_s`).
    pub fn new(longest_window_s: f64) -> Self {
        Live {
            imu: VecDeque::new(),
            current: None,
            table: VecDeque::new(),
            keep_s: longest_window_s + 2.0,
            drift: Drift::default(),
        }
    }

    pub fn push_imu(&mut self, row: ImuRow) {
        // Blocks are aligned on the stream clock; the small offset keeps a stamp that is a
        // multiple of the block length (0.30000000000000004) in its own block.
        let index = ((row.t + 1e-9) / IMU_BLOCK_S).floor() as i64;
        match &mut self.current {
            Some(b) if b.index == index => {
                b.n += 1;
                b.last_t = row.t;
                for (s, v) in b.sum.iter_mut().zip(row.v) {
                    *s += v;
                }
            }
            cur => {
                if let Some(done) = cur.replace(Block::new(index, &row)) {
                    self.imu.push_back(done);
                }
            }
        }
    }

    /// Adds a table row, filling in the ambient drift estimate; returns the row as stored.
    pub fn push_table(&mut self, mut row: TableRow) -> TableRow {
        row.v[3] = self.drift.push(row.t, row.v[2]);
        self.table.push_back(row);
        row
    }

    /// Drops what is older than the window.
    pub fn trim(&mut self, now: f64) {
        let cut = now - self.keep_s;
        while self.imu.front().is_some_and(|b| b.first_t < cut) {
            self.imu.pop_front();
        }
        while self.table.front().is_some_and(|r| r.t < cut) {
            self.table.pop_front();
        }
    }

    /// The latest table row.
    pub fn last_table(&self) -> Option<&TableRow> {
        self.table.back()
    }

    /// Peak-to-peak per channel of a signal over `[from, to]`, `None` with fewer than two
    /// samples; a NaN sample makes the channel's value NaN (never stable). IMU signals are
    /// taken as the means of the completed `IMU_BLOCK_S` blocks inside the window.
    pub fn peak_to_peak(&self, signal: Signal, from: f64, to: f64) -> Option<Vec<f64>> {
        let (src, ch) = channels(signal);
        let mut lo = vec![f64::INFINITY; ch.len()];
        let mut hi = vec![f64::NEG_INFINITY; ch.len()];
        let mut n = 0usize;
        let mut nan = vec![false; ch.len()];
        let mut visit = |v: &[f64]| {
            n += 1;
            for (k, &x) in v[ch.clone()].iter().enumerate() {
                if x.is_nan() {
                    nan[k] = true;
                }
                lo[k] = lo[k].min(x);
                hi[k] = hi[k].max(x);
            }
        };
        match src {
            Source::Imu => self
                .imu
                .iter()
                .rev()
                .skip_while(|b| b.last_t > to)
                .take_while(|b| b.first_t >= from)
                .for_each(|b| visit(&std::array::from_fn::<f64, 7, _>(|k| b.mean(k)))),
            Source::Table => self
                .table
                .iter()
                .rev()
                .skip_while(|r| r.t > to)
                .take_while(|r| r.t >= from)
                .for_each(|r| visit(&r.v)),
        }
        if n < 2 {
            return None;
        }
        Some(
            (0..lo.len())
                .map(|k| if nan[k] { f64::NAN } else { hi[k] - lo[k] })
                .collect(),
        )
    }

    /// Mean accelerometer vector over the completed blocks inside `[from, to]` (`None`
    /// without any).
    pub fn accel_mean(&self, from: f64, to: f64) -> Option<[f64; 3]> {
        let (mut sum, mut n) = ([0.0; 3], 0u32);
        for b in self
            .imu
            .iter()
            .filter(|b| b.first_t >= from && b.last_t <= to)
        {
            for (k, s) in sum.iter_mut().enumerate() {
                *s += b.sum[k];
            }
            n += b.n;
        }
        (n > 0).then(|| sum.map(|s| s / f64::from(n)))
    }

    /// Largest value of a table channel over `[from, to]` (`None` without samples).
    pub fn table_max(&self, channel: usize, from: f64, to: f64) -> Option<f64> {
        let mut it = self
            .table
            .iter()
            .rev()
            .skip_while(|r| r.t > to)
            .take_while(|r| r.t >= from)
            .peekable();
        it.peek()?;
        Some(it.fold(f64::NEG_INFINITY, |m, r| {
            if r.v[channel].is_nan() {
                f64::NAN
            } else {
                m.max(r.v[channel])
            }
        }))
    }
}

/// Whether a stability condition holds over the window ending at `now`; the window must
/// lie after `since` (the settle's start). Returns the unmet description otherwise.
pub(crate) fn stability_unmet(live: &Live, s: &Stability, since: f64, now: f64) -> Option<String> {
    if now - s.window_s < since - 1e-9 {
        return Some(format!(
            "{:?} window of {} s not yet filled",
            s.signal, s.window_s
        ));
    }
    match live.peak_to_peak(s.signal, now - s.window_s, now) {
        None => Some(format!("{:?}: no samples over {} s", s.signal, s.window_s)),
        Some(p2p) if p2p.iter().all(|&v| v <= s.max_fluctuation) => None,
        Some(p2p) => Some(format!(
            "{:?} peak-to-peak {:?} > {}",
            s.signal, p2p, s.max_fluctuation
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn drift_slope_of_a_ramp() {
        let mut d = Drift::default();
        let mut last = f64::NAN;
        // 0.3 degC/h ramp sampled at 10 Hz for 5 minutes.
        for k in 0..3000 {
            let t = k as f64 * 0.1;
            last = d.push(t, 20.0 + 0.3 * t / 3600.0);
        }
        assert!((last - 0.3).abs() < 1e-6, "{last}");
    }

    #[test]
    fn peak_to_peak_over_window() {
        let mut l = Live::new(5.0);
        for k in 0..100 {
            let t = k as f64 * 0.1;
            let a = if k == 20 { 1.0 } else { 0.0 };
            l.push_imu(ImuRow {
                t,
                v: [a, 0.0, 9.8, 0.0, 0.0, 0.0, f64::NAN],
            });
        }
        let p = l.peak_to_peak(Signal::Accel, 1.5, 2.5).unwrap();
        assert_eq!(p, vec![1.0, 0.0, 0.0]);
        let p = l.peak_to_peak(Signal::Accel, 3.0, 9.9).unwrap();
        assert_eq!(p, vec![0.0, 0.0, 0.0]);
        assert!(l.peak_to_peak(Signal::ImuTemperature, 3.0, 9.9).unwrap()[0].is_nan());
    }

    /// White noise of one density read at 100 Hz and at 1 kHz: the raw peak-to-peak grows
    /// about sqrt(10) = 3.2 times, the watched fluctuation (0.1 s means) stays the same.
    #[test]
    fn fluctuation_does_not_depend_on_the_sample_rate() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand::rngs::ChaCha8Rng::seed_from_u64(7);
        let density = 2e-5; // per sqrt(Hz)
        let mut reading = |fs: f64| {
            let sigma = density * (fs / 2.0).sqrt();
            let mut l = Live::new(5.0);
            let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
            let n = (10.0 * fs) as usize;
            for k in 0..n {
                let x: f64 = sigma * rng.sample::<f64, _>(rand_distr::StandardNormal);
                let t = k as f64 / fs;
                if t >= 4.0 {
                    (lo, hi) = (lo.min(x), hi.max(x));
                }
                l.push_imu(ImuRow {
                    t,
                    v: [x, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
                });
            }
            let p = l.peak_to_peak(Signal::Accel, 4.0, 9.95).unwrap()[0];
            (p, hi - lo)
        };
        // Averaged over repeats: a single peak-to-peak is itself a noisy number.
        let (mut w100, mut w1k, mut r100, mut r1k) = (0.0, 0.0, 0.0, 0.0);
        for _ in 0..20 {
            let (p, r) = reading(100.0);
            (w100, r100) = (w100 + p, r100 + r);
            let (p, r) = reading(1000.0);
            (w1k, r1k) = (w1k + p, r1k + r);
        }
        assert!(r1k / r100 > 2.5, "raw ratio {}", r1k / r100);
        assert!(
            (w1k / w100 - 1.0).abs() < 0.25,
            "watched ratio {}",
            w1k / w100
        );
    }
}
