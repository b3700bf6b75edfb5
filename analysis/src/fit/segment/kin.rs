//! The kinematic signals of a segment at each IMU stamp, from the table feedback.

use crate::fit::prep;
use crate::recording::{Segment, SegmentKind, TableStream};
use ratecal_physics::effects::Signals;
use ratecal_physics::{AxisMotion, DEG, Geometry, Site, TableState};

/// The kinematic signals of one segment at any stamp, the feedback cursor kept between
/// calls (stamps come in order).
pub(super) struct Kin<'a> {
    pub tab: &'a TableStream,
    geo: &'a Geometry,
    site: Site,
    /// At rest with known angles: the one set of signals.
    pub rest: Option<Signals>,
    /// At rest without feedback inside: rates and accelerations are zero.
    pub still: bool,
    /// A rate segment's steady rates, rad/s.
    steady: Option<(f64, f64)>,
    /// The table time of an IMU stamp.
    retime: Retime,
    j: usize,
}

/// A known timing error of the samples against the table's feedback: the sample stamped
/// `t` saw the motion of table time `t / (1 + eps) - tau_s` (the simulator's `time_offset`
/// and `clock_rate`, docs/effects.md). The fit's timing columns then measure what is left
/// about it, so that a long recording's growing lag is taken exactly, not to first order.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Retime {
    /// Time offset, s.
    pub tau_s: f64,
    /// Clock rate, `ppm * 1e-6`.
    pub eps: f64,
}

impl Retime {
    /// From the registry's parameters, `[time_offset.tau_ms, clock_rate.ppm]`.
    pub fn from_registry([tau_ms, ppm]: [f64; 2]) -> Retime {
        Retime {
            tau_s: tau_ms * 1e-3,
            eps: ppm * 1e-6,
        }
    }

    /// The registry's parameters, `[time_offset.tau_ms, clock_rate.ppm]`.
    pub fn registry(&self) -> [f64; 2] {
        [self.tau_s * 1e3, self.eps * 1e6]
    }

    /// The table time of the sample stamped `t`.
    pub fn table_time(&self, t: f64) -> f64 {
        if *self == Retime::default() {
            t
        } else {
            t / (1.0 + self.eps) - self.tau_s
        }
    }
}

impl<'a> Kin<'a> {
    pub(super) fn new(
        tab: &'a TableStream,
        seg: &Segment,
        geo: &'a Geometry,
        site: Site,
        retime: Retime,
    ) -> Self {
        let still = seg.kind == SegmentKind::Static;
        let rest = still
            .then(|| prep::rest_angles(tab, seg.t_start, seg.t_end))
            .flatten()
            .map(|(o, i)| {
                let at = |angle: f64| AxisMotion {
                    angle: angle * DEG,
                    rate: 0.0,
                    accel: 0.0,
                };
                let state = TableState {
                    outer: at(o),
                    inner: at(i),
                };
                Signals::new(&state.snapshot(geo, &site), &site, 0.0)
            });
        let steady = (seg.kind == SegmentKind::Rate).then(|| {
            let (o, i) = prep::steady_rates(tab, seg.t_start, seg.t_end);
            (o * DEG, i * DEG)
        });
        let mut kin = Kin {
            tab,
            geo,
            site,
            rest,
            still,
            steady,
            retime,
            j: 0,
        };
        kin.seek(seg.t_start);
        kin
    }

    /// Puts the cursor at the feedback step holding `t` (a window's first stamp: a window
    /// read with a margin starts before where the last one ended).
    pub(super) fn seek(&mut self, t: f64) {
        let t = self.retime.table_time(t);
        self.j = self.tab.t.partition_point(|&x| x <= t).saturating_sub(1);
    }

    /// Moves the cursor to the feedback step holding the table time of stamp `t`; the
    /// step `j..j + 1` and the fraction of it.
    pub(super) fn advance(&mut self, t: f64) -> (usize, f64) {
        let t = self.retime.table_time(t);
        let tab = &self.tab.t;
        let last = tab.len().saturating_sub(2);
        while self.j < last && tab[self.j + 1] <= t {
            self.j += 1;
        }
        let j = self.j.min(last);
        let w = ((t - tab[j]) / (tab[j + 1] - tab[j])).clamp(0.0, 1.0);
        (j, w)
    }

    /// Signals at step `j`, fraction `w` (temperature offset zero, stamp `t`).
    pub(super) fn signals(&self, j: usize, w: f64, t: f64) -> Signals {
        if let Some(s) = self.rest {
            return s.at(t);
        }
        let tab = self.tab;
        let (t0, t1) = (tab.t[j], tab.t[j + 1]);
        let lerp = |x: &[f64]| x[j] + w * (x[j + 1] - x[j]);
        let angle = |x: &[f64]| x[j] + w * prep::unwrap(x[j + 1] - x[j]);
        let slope = |x: &[f64]| (x[j + 1] - x[j]) / (t1 - t0);
        let mut state = TableState {
            outer: AxisMotion {
                angle: angle(&tab.outer) * DEG,
                rate: lerp(&tab.outer_rate) * DEG,
                accel: slope(&tab.outer_rate) * DEG,
            },
            inner: AxisMotion {
                angle: angle(&tab.inner) * DEG,
                rate: lerp(&tab.inner_rate) * DEG,
                accel: slope(&tab.inner_rate) * DEG,
            },
        };
        // At rest or turning steadily, the feedback's rate ripple is the table's
        // measurement noise, not motion the IMU felt: rates are zero or the steady ones.
        let fixed = if self.still {
            Some((0.0, 0.0))
        } else {
            self.steady
        };
        if let Some((o, i)) = fixed {
            state.outer.rate = o;
            state.inner.rate = i;
            state.outer.accel = 0.0;
            state.inner.accel = 0.0;
        }
        Signals::new(&state.snapshot(self.geo, &self.site), &self.site, 0.0).at(t)
    }
}
