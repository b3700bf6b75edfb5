//! Static intervals found from the IMU signal alone, as imu_tk does (Tedaldi, Pretto,
//! Menegatti, ICRA 2014): the variance of the specific force over short windows, against
//! the noise of the quietest windows; and the mean rate, which must be the rest's (a steady
//! turn is quiet too). The up axis of each interval comes from
//! gravity when one body axis is within 10 deg of vertical; other intervals are oblique.

use super::{Found, Stretch, Thinned};
use crate::map::{Detect, Turn, Up};
use crate::read::RowAt;
use ratecal_recording::SegmentKind;

/// Within this angle of vertical, a body axis is the up axis (deg).
pub const UP_WITHIN_DEG: f64 = 10.0;

/// A window whose mean rate differs from the rest's by more than this (plus three noise
/// deviations) is turning, however steadily, deg/s.
pub const REST_RATE_DPS: f64 = 1.0;

/// The stream cut into windows, each kept as sums (memory: a few numbers per window).
pub struct Blocks {
    window_s: f64,
    cur: Stretch,
    done: Vec<Stretch>,
}

impl Blocks {
    /// Windows of `window_s` seconds.
    pub fn new(window_s: f64) -> Self {
        Blocks {
            window_s,
            cur: Stretch::default(),
            done: Vec::new(),
        }
    }

    /// One sample.
    #[inline]
    pub fn add(&mut self, at: RowAt, t: f64, f: &[f64; 3], w: &[f64; 3]) {
        if self.cur.n > 0 && t - self.cur.t.0 >= self.window_s {
            self.close();
        }
        self.cur.add(at.sample, at.line, t, f, w);
    }

    fn close(&mut self) {
        let mut b = std::mem::take(&mut self.cur);
        b.mag_f = Thinned::default();
        b.mag_w = Thinned::default();
        self.done.push(b);
    }

    /// The static intervals of at least `d.static_min_s`, in time order.
    pub fn detect(mut self, d: &Detect) -> Vec<Found> {
        if self.cur.n > 0 {
            self.close();
        }
        let blocks = self.done;
        let noise_f = quiet(blocks.iter().map(Stretch::var_f));
        let noise_w = quiet(blocks.iter().map(Stretch::var_w));
        // The rate's variance is no test: a hand holding a pose still wobbles it by a
        // deg/s or so (the MPU-6050 session), as imu_tk found.
        let quiet_enough = |b: &Stretch| b.n >= 2 && b.var_f() <= d.threshold * noise_f;
        // A steady turn is quiet too: its mean rate must also be the rest's (the gyro bias).
        let w0: [f64; 3] = std::array::from_fn(|k| {
            let mut v: Vec<f64> = blocks
                .iter()
                .filter(|b| quiet_enough(b))
                .map(|b| b.mean_w()[k])
                .collect();
            v.sort_by(f64::total_cmp);
            v.get(v.len() / 2).copied().unwrap_or(0.0)
        });
        let w_tol = REST_RATE_DPS + 3.0 * noise_w.sqrt();
        let still = |b: &Stretch| {
            let m = b.mean_w();
            quiet_enough(b) && super::norm(&std::array::from_fn(|k| m[k] - w0[k])) <= w_tol
        };
        let mut out: Vec<Found> = Vec::new();
        let mut run: Option<Stretch> = None;
        let flush = |run: &mut Option<Stretch>, out: &mut Vec<Found>| {
            if let Some(s) = run.take()
                && s.t.1 - s.t.0 >= d.static_min_s
            {
                let up = up_of(&s.mean_f());
                out.push(Found {
                    id: format!("static/{:02}", out.len() + 1),
                    kind: SegmentKind::Static,
                    stretch: s,
                    up: Some(up),
                    rate: None,
                    turn: None,
                    attitude: d.attitude,
                    decl: None,
                });
            }
        };
        for b in &blocks {
            if still(b) {
                let r = run.get_or_insert_with(Stretch::default);
                merge(r, b);
            } else {
                flush(&mut run, &mut out);
            }
        }
        flush(&mut run, &mut out);
        with_turns(out)
    }
}

/// The poses with a free `turn` between each two (the motion between them: its own
/// samples, no axis, no nominal angle).
fn with_turns(poses: Vec<Found>) -> Vec<Found> {
    let mut out = Vec::with_capacity(2 * poses.len());
    for p in poses {
        if let Some(prev) = out
            .last()
            .filter(|f: &&Found| f.kind == SegmentKind::Static)
        {
            let (a, b) = (&prev.stretch, &p.stretch);
            if b.samples.0 > a.samples.1 + 1 {
                let stretch = Stretch {
                    n: b.samples.0 - a.samples.1 - 1,
                    samples: (a.samples.1 + 1, b.samples.0 - 1),
                    lines: (a.lines.1 + 1, b.lines.0.saturating_sub(1)),
                    t: (a.t.1, b.t.0),
                    ..Stretch::default()
                };
                let n = out.iter().filter(|f| f.kind == SegmentKind::Turn).count();
                out.push(Found {
                    id: format!("turn/{:02}", n + 1),
                    kind: SegmentKind::Turn,
                    stretch,
                    up: None,
                    rate: None,
                    turn: Some(Turn::default()),
                    attitude: None,
                    decl: None,
                });
            }
        }
        out.push(p);
    }
    out
}

/// Adds block `b` (sums only) to the interval `r`.
fn merge(r: &mut Stretch, b: &Stretch) {
    if r.n == 0 {
        r.samples.0 = b.samples.0;
        r.lines.0 = b.lines.0;
        r.t.0 = b.t.0;
    }
    r.samples.1 = b.samples.1;
    r.lines.1 = b.lines.1;
    r.t.1 = b.t.1;
    r.n += b.n;
    for k in 0..3 {
        r.sum_f[k] += b.sum_f[k];
        r.sum_f2[k] += b.sum_f2[k];
        r.sum_w[k] += b.sum_w[k];
        r.sum_w2[k] += b.sum_w2[k];
    }
    r.sum_mag_f += b.sum_mag_f;
    // The median of the interval's magnitude, from its windows' means.
    r.mag_f.push(b.sum_mag_f / b.n as f64);
    r.mag_w.push(super::norm(&b.mean_w()));
}

/// The noise variance: the 10th percentile of the windows' variances (a calibration
/// session rests far more than a tenth of the time), never zero.
fn quiet(vars: impl Iterator<Item = f64>) -> f64 {
    let mut v: Vec<f64> = vars.filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return f64::INFINITY;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 10].max(1e-12)
}

/// The body axis within [`UP_WITHIN_DEG`] of the specific force, else oblique.
pub fn up_of(f: &[f64; 3]) -> Up {
    let m = super::norm(f);
    let (k, c) = (0..3)
        .map(|k| (k, f[k]))
        .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
        .unwrap_or((2, 0.0));
    if m > 0.0 && c.abs() >= m * UP_WITHIN_DEG.to_radians().cos() {
        Up::Axis(k, c.signum())
    } else {
        Up::Oblique
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn up_axis_within_ten_degrees() {
        let g = 9.8;
        let tilt = |deg: f64| [g * deg.to_radians().sin(), 0.0, -g * deg.to_radians().cos()];
        assert_eq!(up_of(&tilt(9.0)), Up::Axis(2, -1.0));
        assert_eq!(up_of(&tilt(11.0)), Up::Oblique);
        assert_eq!(up_of(&[0.0, g, 0.1]), Up::Axis(1, 1.0));
    }

    #[test]
    fn finds_rests_between_turns() {
        // 100 Hz: 10 s rest (z up), 2 s turning, 5 s rest (x up), 1 s turning, 1 s rest.
        let mut b = Blocks::new(0.5);
        let mut i = 0u64;
        let mut push = |b: &mut Blocks, secs: f64, f: [f64; 3], w: f64| {
            for _ in 0..(secs * 100.0) as usize {
                let n = ((i * 7919) % 13) as f64 * 0.001;
                let t = i as f64 / 100.0;
                let ff = [f[0] + n, f[1] - n, f[2] + n];
                let ww = [w * (t * 3.0).sin() + n, n, w];
                b.add(
                    RowAt {
                        sample: i,
                        line: i + 2,
                    },
                    t,
                    &ff,
                    &ww,
                );
                i += 1;
            }
        };
        push(&mut b, 10.0, [0.0, 0.0, 9.8], 0.0);
        push(&mut b, 2.0, [4.0, 3.0, 5.0], 90.0);
        push(&mut b, 5.0, [9.8, 0.0, 0.0], 0.0);
        push(&mut b, 1.0, [4.0, 3.0, 5.0], 90.0);
        push(&mut b, 1.0, [0.0, 9.8, 0.0], 0.0);
        let d = Detect {
            static_min_s: 2.0,
            threshold: 6.0,
            window_s: 0.5,
            attitude: None,
            at: 0..0,
        };
        let found = b.detect(&d);
        let ups: Vec<_> = found
            .iter()
            .filter_map(|f| f.up)
            .map(|u| u.name())
            .collect();
        assert_eq!(ups, ["+z", "+x"]);
        assert!(found[0].stretch.t.1 < 10.0 && found[0].stretch.t.1 > 9.0);
        assert!(found[2].stretch.t.0 >= 12.0 && found[2].stretch.t.0 < 12.6);
        // The motion between the two poses is a turn from the first's end to the second's start.
        assert_eq!(found[1].kind, SegmentKind::Turn);
        assert_eq!(
            found[1].stretch.t,
            (found[0].stretch.t.1, found[2].stretch.t.0)
        );
    }
}
