//! How regularly a stream was sampled: gaps (dropped samples) and jitter of its time
//! stamps, seen one stamp at a time in bounded memory (the nominal step is the median of
//! the first [`HEAD`] steps), so that the reader can count them on its one pass over a long
//! file and the analysis can warn where they are.

use serde::{Deserialize, Serialize};

/// Steps whose median is taken as the nominal step.
pub const HEAD: usize = 1000;
/// A step longer than this many nominal steps is a gap (samples dropped).
pub const GAP_STEPS: f64 = 1.5;
/// A step off the nominal by more than this fraction (and not a gap) is jitter.
pub const JITTER_FRACTION: f64 = 0.10;

/// What the time stamps of a stream say about its sampling.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct CadenceReport {
    /// Rows seen.
    pub rows: usize,
    /// Nominal step, s (the median of the first steps; NaN with fewer than two rows).
    pub nominal_step_s: f64,
    /// Steps longer than [`GAP_STEPS`] nominal steps.
    pub gaps: usize,
    /// Samples those gaps miss (each gap's length in nominal steps, less one).
    pub dropped: usize,
    /// The longest gap: the stamp it starts at and its length, s.
    pub longest_gap: Option<(f64, f64)>,
    /// Steps off the nominal by more than [`JITTER_FRACTION`] that are not gaps.
    pub jittered: usize,
    /// The worst of those: the stamp it starts at and its step, s.
    pub worst_jitter: Option<(f64, f64)>,
    /// The first stamp not after the one before it: `(previous, this)`, s (a reader
    /// refuses such a stream; a stream built in memory may hold one).
    pub backwards: Option<(f64, f64)>,
}

impl CadenceReport {
    /// The report of a whole stream of stamps.
    pub fn of(t: &[f64]) -> Self {
        let mut c = Cadence::default();
        t.iter().for_each(|&x| c.see(x));
        c.report()
    }
}

/// A [`CadenceReport`] built one stamp at a time.
#[derive(Debug, Clone, Default)]
pub struct Cadence {
    /// `(start, step)` of the first steps, until the nominal step is known.
    head: Vec<(f64, f64)>,
    /// Whether the nominal step is known (the head was full).
    settled: bool,
    prev: Option<f64>,
    report: CadenceReport,
}

impl Cadence {
    /// One more stamp (a stamp not after the previous one is not a step: the reader
    /// refuses such a stream on its own).
    #[inline]
    pub fn see(&mut self, t: f64) {
        self.report.rows += 1;
        let Some(prev) = self.prev.replace(t) else {
            return;
        };
        let step = t - prev;
        // NaN steps cannot come from a read stream; they count as not increasing.
        if step.is_nan() || step <= 0.0 {
            self.report.backwards.get_or_insert((prev, t));
            return;
        }
        if self.settled {
            classify(&mut self.report, prev, step);
            return;
        }
        self.head.push((prev, step));
        if self.head.len() == HEAD {
            let head = std::mem::take(&mut self.head);
            self.settle(&head);
            self.settled = true;
        }
    }

    /// The report so far.
    pub fn report(&self) -> CadenceReport {
        if self.settled {
            return self.report;
        }
        let mut c = self.clone();
        let head = std::mem::take(&mut c.head);
        c.settle(&head);
        c.report
    }

    /// Takes the nominal step from the head's steps and classifies them.
    fn settle(&mut self, head: &[(f64, f64)]) {
        let mut steps: Vec<f64> = head.iter().map(|s| s.1).collect();
        if steps.is_empty() {
            self.report.nominal_step_s = f64::NAN;
            return;
        }
        steps.sort_by(f64::total_cmp);
        self.report.nominal_step_s = steps[steps.len() / 2];
        for &(t, step) in head {
            classify(&mut self.report, t, step);
        }
    }
}

/// Counts one step of `step` s starting at `t` against the nominal step.
#[inline]
fn classify(r: &mut CadenceReport, t: f64, step: f64) {
    let nominal = r.nominal_step_s;
    if step > GAP_STEPS * nominal {
        r.gaps += 1;
        r.dropped += ((step / nominal).round() as usize).saturating_sub(1).max(1);
        if r.longest_gap.is_none_or(|g| step > g.1) {
            r.longest_gap = Some((t, step));
        }
    } else if (step - nominal).abs() > JITTER_FRACTION * nominal {
        r.jittered += 1;
        let off = |s: f64| (s - nominal).abs();
        if r.worst_jitter.is_none_or(|j| off(step) > off(j.1)) {
            r.worst_jitter = Some((t, step));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_gaps_and_jitter_where_they_are() {
        let mut t: Vec<f64> = (0..3000).map(|i| i as f64 * 0.01).collect();
        t.retain(|x| !(10.0..10.05).contains(x)); // 5 samples dropped at 9.99 s
        t[2000] += 0.003; // one stamp late: two steps off by 30 %
        let r = CadenceReport::of(&t);
        assert!((r.nominal_step_s - 0.01).abs() < 1e-12);
        assert_eq!((r.gaps, r.dropped), (1, 5), "{r:?}");
        let (at, len) = r.longest_gap.unwrap();
        assert!((at - 9.99).abs() < 1e-9 && (len - 0.06).abs() < 1e-9);
        assert_eq!(r.jittered, 2, "{r:?}");
        let clean = CadenceReport::of(&(0..50).map(|i| i as f64 / 102.4).collect::<Vec<_>>());
        assert_eq!((clean.gaps, clean.jittered, clean.rows), (0, 0, 50));
    }
}
