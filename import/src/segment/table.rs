//! The table stream a recording needs, synthesized when the lab has no feedback: each
//! segment's declared attitude held from halfway after the previous segment to halfway
//! before the next, and a rate segment's declared rate integrated over it.

use ratecal_recording::TableSample;

/// Rate of the synthesized stream, Hz (that of the seed station's feedback).
pub const TABLE_HZ: f64 = 50.0;

/// One segment's attitude.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// Segment start and end, s.
    pub t0: f64,
    /// End.
    pub t1: f64,
    /// (outer, inner) at the start, deg.
    pub att: (f64, f64),
    /// A turn: (outer axis?, rate in deg/s) over `[t0, t1]`.
    pub turn: Option<(bool, f64)>,
}

impl Pose {
    fn at(&self, t: f64) -> TableSample {
        let (mut o, mut i) = self.att;
        let (mut ro, mut ri) = (0.0, 0.0);
        if let Some((outer, r)) = self.turn {
            let angle = r * (t.clamp(self.t0, self.t1) - self.t0);
            let rate = if (self.t0..=self.t1).contains(&t) {
                r
            } else {
                0.0
            };
            if outer {
                o += angle;
                ro = rate;
            } else {
                i += angle;
                ri = rate;
            }
        }
        TableSample {
            t,
            outer_deg: o,
            inner_deg: i,
            outer_rate_dps: ro,
            inner_rate_dps: ri,
            ambient_c: None,
            t_host: None,
        }
    }
}

/// Calls `emit` for each table sample from `t_first` to at least `t_last` at
/// [`TABLE_HZ`]; `poses` in time order (none: a table at rest at zero).
pub fn synthesize(poses: &[Pose], t_first: f64, t_last: f64, mut emit: impl FnMut(TableSample)) {
    let rest = Pose {
        t0: t_first,
        t1: t_first,
        att: (0.0, 0.0),
        turn: None,
    };
    let mut k = 0usize;
    let mut n = 0u64;
    loop {
        let t = t_first + n as f64 / TABLE_HZ;
        while k + 1 < poses.len() && t >= 0.5 * (poses[k].t1 + poses[k + 1].t0) {
            k += 1;
        }
        emit(poses.get(k).unwrap_or(&rest).at(t));
        if t >= t_last {
            break;
        }
        n += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn holds_attitudes_and_integrates_turns() {
        let poses = [
            Pose {
                t0: 1.0,
                t1: 3.0,
                att: (90.0, 0.0),
                turn: None,
            },
            Pose {
                t0: 5.0,
                t1: 7.0,
                att: (0.0, 0.0),
                turn: Some((false, -90.0)),
            },
        ];
        let mut v = Vec::new();
        synthesize(&poses, 0.0, 9.0, |s| v.push(s));
        assert_eq!(v.len(), 451);
        let at = |t: f64| v[(t * TABLE_HZ).round() as usize];
        assert_eq!(at(3.9).outer_deg, 90.0);
        assert_eq!(at(4.0).outer_deg, 0.0);
        assert_eq!(at(6.0).inner_deg, -90.0);
        assert_eq!(at(6.0).inner_rate_dps, -90.0);
        assert_eq!(at(8.0).inner_deg, -180.0);
        assert_eq!(at(8.0).inner_rate_dps, 0.0);
    }
}
