//! The sums a verification segment keeps of each output channel against its reference.

use crate::fit::stats::Inflation;

/// Means and spread of one output channel against its reference over kept samples.
#[derive(Debug, Clone, Default)]
pub(crate) struct ChannelStats {
    /// Kept samples.
    pub n: usize,
    /// Sum of the outputs.
    pub sum_out: f64,
    /// Sum of the references.
    pub sum_ref: f64,
    /// Mean and sum of squared deviations of `out - ref` (merged by Chan's rule).
    pub mean_d: f64,
    /// Sum of squared deviations of `out - ref`.
    pub m2_d: f64,
    /// Correlation of `out - ref` (batch means).
    pub inflation: Inflation,
}

impl ChannelStats {
    pub(super) fn add_window(&mut self, out: &[f64], refs: &[f64], keep: &[bool]) {
        let d: Vec<f64> = out.iter().zip(refs).map(|(o, r)| o - r).collect();
        let (mut n, mut so, mut sr, mut sd) = (0usize, 0.0, 0.0, 0.0);
        for i in 0..d.len() {
            if keep[i] {
                n += 1;
                so += out[i];
                sr += refs[i];
                sd += d[i];
            }
        }
        if n == 0 {
            return;
        }
        let m = sd / n as f64;
        let m2: f64 = (0..d.len())
            .filter(|&i| keep[i])
            .map(|i| (d[i] - m).powi(2))
            .sum();
        let (na, nb) = (self.n as f64, n as f64);
        let delta = m - self.mean_d;
        self.m2_d += m2 + delta * delta * na * nb / (na + nb);
        self.mean_d += delta * nb / (na + nb);
        self.n += n;
        self.sum_out += so;
        self.sum_ref += sr;
        self.inflation.add(&d, keep);
    }

    /// Adds the sums of later samples of the same channel (Chan's rule for the spread).
    pub(super) fn merge(&mut self, later: &ChannelStats) {
        if later.n == 0 {
            return;
        }
        let (na, nb) = (self.n as f64, later.n as f64);
        let delta = later.mean_d - self.mean_d;
        self.m2_d += later.m2_d + delta * delta * na * nb / (na + nb);
        self.mean_d += delta * nb / (na + nb);
        self.n += later.n;
        self.sum_out += later.sum_out;
        self.sum_ref += later.sum_ref;
        self.inflation.merge(&later.inflation);
    }

    /// Sample standard deviation of `out - ref`.
    pub(crate) fn std_d(&self) -> f64 {
        if self.n < 2 {
            0.0
        } else {
            (self.m2_d / (self.n - 1) as f64).sqrt()
        }
    }
}

/// Sums of a segment's raw outputs (no outlier removal, no low-pass) against their
/// references, per channel (`ax ay az gx gy gz`), over every row: what the sanity checks
/// read (means, and the mismatch `out - b - ref` for any bias `b`).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct RawSums {
    /// Rows.
    pub n: usize,
    /// Sum of the outputs.
    pub so: [f64; 6],
    /// Sum of the references.
    pub sr: [f64; 6],
    /// Sum of the squared outputs.
    pub soo: [f64; 6],
    /// Sum of output times reference.
    pub sor: [f64; 6],
    /// Sum of the squared references.
    pub srr: [f64; 6],
}

impl RawSums {
    /// One row.
    #[inline]
    pub(super) fn add(&mut self, out: [f64; 6], refs: [f64; 6]) {
        self.n += 1;
        for c in 0..6 {
            let (o, r) = (out[c], refs[c]);
            self.so[c] += o;
            self.sr[c] += r;
            self.soo[c] += o * o;
            self.sor[c] += o * r;
            self.srr[c] += r * r;
        }
    }

    /// Adds the sums of later rows.
    pub(super) fn merge(&mut self, later: &RawSums) {
        self.n += later.n;
        for c in 0..6 {
            self.so[c] += later.so[c];
            self.sr[c] += later.sr[c];
            self.soo[c] += later.soo[c];
            self.sor[c] += later.sor[c];
            self.srr[c] += later.srr[c];
        }
    }

    /// Mean output of channel `c`.
    pub(crate) fn mean_out(&self, c: usize) -> f64 {
        self.so[c] / self.n.max(1) as f64
    }

    /// Mean reference of channel `c`.
    pub(crate) fn mean_ref(&self, c: usize) -> f64 {
        self.sr[c] / self.n.max(1) as f64
    }

    /// Mean square of `out - b - ref` on channel `c`.
    pub(crate) fn mismatch_ms(&self, c: usize, b: f64) -> f64 {
        let n = self.n.max(1) as f64;
        let s = self.soo[c] - 2.0 * self.sor[c] + self.srr[c] - 2.0 * b * (self.so[c] - self.sr[c])
            + n * b * b;
        (s / n).max(0.0)
    }

    /// Mean square reference of channel `c`.
    pub(crate) fn ref_ms(&self, c: usize) -> f64 {
        self.srr[c] / self.n.max(1) as f64
    }

    /// Least-squares gain of `out - b` on the reference of channel `c` (NaN without one).
    pub(crate) fn gain(&self, c: usize, b: f64) -> f64 {
        (self.sor[c] - b * self.sr[c]) / self.srr[c]
    }
}
