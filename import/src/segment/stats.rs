//! What a stretch of samples holds, gathered while streaming: counts, first and last time,
//! mean specific force and rate, and the median magnitudes from a bounded sample of them.

/// Values kept for a median: when full, every other one is dropped and the stride doubles,
/// so memory stays bounded however long the stretch.
#[derive(Debug, Clone, Default)]
pub struct Thinned {
    kept: Vec<f64>,
    stride: u64,
    seen: u64,
}

const KEEP: usize = 4096;

impl Thinned {
    /// Offers one value.
    pub fn push(&mut self, x: f64) {
        if self.stride == 0 {
            self.stride = 1;
        }
        if self.seen.is_multiple_of(self.stride) {
            if self.kept.len() == KEEP {
                let mut i = 0;
                self.kept.retain(|_| {
                    i += 1;
                    i % 2 == 1
                });
                self.stride *= 2;
                if !self.seen.is_multiple_of(self.stride) {
                    self.seen += 1;
                    return;
                }
            }
            self.kept.push(x);
        }
        self.seen += 1;
    }

    /// The median of the kept values (NaN when empty).
    pub fn median(&self) -> f64 {
        let mut v = self.kept.clone();
        if v.is_empty() {
            return f64::NAN;
        }
        v.sort_by(f64::total_cmp);
        let n = v.len();
        if n % 2 == 1 {
            v[n / 2]
        } else {
            0.5 * (v[n / 2 - 1] + v[n / 2])
        }
    }
}

/// A stretch of samples.
#[derive(Debug, Clone, Default)]
pub struct Stretch {
    /// Samples.
    pub n: u64,
    /// First and last sample index (0-based).
    pub samples: (u64, u64),
    /// First and last 1-based line of the first source.
    pub lines: (u64, u64),
    /// First and last time, s.
    pub t: (f64, f64),
    /// Sums of the specific force and its squares, per axis.
    pub sum_f: [f64; 3],
    /// Sums of squares.
    pub sum_f2: [f64; 3],
    /// Sums of the rate, per axis.
    pub sum_w: [f64; 3],
    /// Sums of squares.
    pub sum_w2: [f64; 3],
    /// Sum of |f| (a block's mean magnitude once its median buffer is dropped).
    pub sum_mag_f: f64,
    /// |f| for the median.
    pub mag_f: Thinned,
    /// |w| for the median.
    pub mag_w: Thinned,
}

impl Stretch {
    /// Adds one sample.
    pub fn add(&mut self, sample: u64, line: u64, t: f64, f: &[f64; 3], w: &[f64; 3]) {
        if self.n == 0 {
            self.samples.0 = sample;
            self.lines.0 = line;
            self.t.0 = t;
        }
        self.samples.1 = sample;
        self.lines.1 = line;
        self.t.1 = t;
        self.n += 1;
        for k in 0..3 {
            self.sum_f[k] += f[k];
            self.sum_f2[k] += f[k] * f[k];
            self.sum_w[k] += w[k];
            self.sum_w2[k] += w[k] * w[k];
        }
        let m = norm(f);
        self.sum_mag_f += m;
        self.mag_f.push(m);
        self.mag_w.push(norm(w));
    }

    /// Mean specific force, m/s^2.
    pub fn mean_f(&self) -> [f64; 3] {
        self.sum_f.map(|s| s / self.n.max(1) as f64)
    }

    /// Mean rate, deg/s.
    pub fn mean_w(&self) -> [f64; 3] {
        self.sum_w.map(|s| s / self.n.max(1) as f64)
    }

    /// Sum over the axes of the specific force's variance, (m/s^2)^2.
    pub fn var_f(&self) -> f64 {
        var(&self.sum_f, &self.sum_f2, self.n)
    }

    /// Sum over the axes of the rate's variance, (deg/s)^2.
    pub fn var_w(&self) -> f64 {
        var(&self.sum_w, &self.sum_w2, self.n)
    }
}

fn var(s: &[f64; 3], s2: &[f64; 3], n: u64) -> f64 {
    if n < 2 {
        return f64::INFINITY;
    }
    let n = n as f64;
    (0..3)
        .map(|k| ((s2[k] - s[k] * s[k] / n) / (n - 1.0)).max(0.0))
        .sum()
}

/// Euclidean norm.
pub fn norm(v: &[f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thinned_median_stays_bounded_and_close() {
        let mut t = Thinned::default();
        for i in 0..1_000_001u64 {
            t.push((i % 1001) as f64);
        }
        assert!(t.kept.len() <= KEEP);
        assert!((t.median() - 500.0).abs() < 20.0, "{}", t.median());
        let mut s = Thinned::default();
        for x in [3.0, 1.0, 2.0] {
            s.push(x);
        }
        assert_eq!(s.median(), 2.0);
    }

    #[test]
    fn stretch_means_and_variance() {
        let mut s = Stretch::default();
        s.add(5, 7, 0.5, &[1.0, 0.0, 9.0], &[0.0; 3]);
        s.add(6, 8, 0.6, &[3.0, 0.0, 9.0], &[2.0, 0.0, 0.0]);
        assert_eq!(s.mean_f(), [2.0, 0.0, 9.0]);
        assert_eq!(s.var_f(), 2.0);
        assert_eq!(s.var_w(), 2.0);
        assert_eq!((s.samples, s.lines, s.t), ((5, 6), (7, 8), (0.5, 0.6)));
    }
}
