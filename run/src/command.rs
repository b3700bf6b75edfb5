//! What the table was last told to do, per axis: the reference for the table's attitude
//! and rate errors, and what an acquisition's segment says about the motion.

use ratecal_drivers::{TableAxisId, TableSample};
use ratecal_plan::Axis;
use ratecal_recording::{Segment, SegmentKind};

/// The command an axis is under.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum AxisCmd {
    /// Holding a position (`None`: wherever it stopped, no angle reference).
    Hold(Option<f64>),
    /// Constant rate, deg/s.
    Rate(f64),
    /// Sinusoidal sway.
    Osc {
        /// Centre, deg.
        center: f64,
        /// Amplitude, deg.
        amplitude: f64,
        /// Period, s.
        period: f64,
    },
}

/// Both axes' commands.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct CmdState {
    pub outer: AxisCmd,
    pub inner: AxisCmd,
    /// Axis of the last rate or oscillation command (names the segment's axis when both
    /// axes are in rate mode).
    pub last_axis: Option<Axis>,
}

impl Default for CmdState {
    fn default() -> Self {
        CmdState {
            outer: AxisCmd::Hold(None),
            inner: AxisCmd::Hold(None),
            last_axis: None,
        }
    }
}

/// Driver axis id of a plan axis.
pub(crate) fn axis_id(a: Axis) -> TableAxisId {
    match a {
        Axis::Outer => TableAxisId::Outer,
        Axis::Inner => TableAxisId::Inner,
    }
}

/// Angle difference wrapped to (-180, 180], deg.
pub(crate) fn wrap180(d: f64) -> f64 {
    let w = (d + 180.0).rem_euclid(360.0) - 180.0;
    if w == -180.0 { 180.0 } else { w }
}

impl CmdState {
    /// The command of an axis.
    pub fn axis(&self, a: Axis) -> AxisCmd {
        match a {
            Axis::Outer => self.outer,
            Axis::Inner => self.inner,
        }
    }

    /// Sets the command of an axis.
    pub fn set(&mut self, a: Axis, c: AxisCmd) {
        match a {
            Axis::Outer => self.outer = c,
            Axis::Inner => self.inner = c,
        }
        if matches!(c, AxisCmd::Rate(_) | AxisCmd::Osc { .. }) {
            self.last_axis = Some(a);
        }
    }

    /// `(attitude error, rate error)` of a feedback sample against the commands: the
    /// largest absolute error over the axes where it is defined (position for holding
    /// axes with a target, rate for holding and rate axes; a swaying axis has none), deg
    /// and deg/s.
    pub fn errors(&self, s: &TableSample) -> (f64, f64) {
        let mut att: f64 = 0.0;
        let mut rate: f64 = 0.0;
        for (c, angle, r) in [
            (self.outer, s.outer_deg, s.outer_rate_dps),
            (self.inner, s.inner_deg, s.inner_rate_dps),
        ] {
            match c {
                AxisCmd::Hold(target) => {
                    if let Some(t) = target {
                        att = att.max(wrap180(angle - t).abs());
                    }
                    rate = rate.max(r.abs());
                }
                AxisCmd::Rate(w) => rate = rate.max((r - w).abs()),
                AxisCmd::Osc { .. } => {}
            }
        }
        (att, rate)
    }

    /// Whether a sample shows the motion commanded as done, with loose tolerances (the
    /// procedure's own settle conditions say how tight): holding axes within 0.05 deg of
    /// their target and below 0.5 deg/s, rate axes within 1 deg/s of their rate.
    pub fn reached(&self, s: &TableSample) -> bool {
        [
            (self.outer, s.outer_deg, s.outer_rate_dps),
            (self.inner, s.inner_deg, s.inner_rate_dps),
        ]
        .into_iter()
        .all(|(c, angle, r)| match c {
            AxisCmd::Hold(t) => {
                t.is_none_or(|t| wrap180(angle - t).abs() <= 0.05) && r.abs() <= 0.5
            }
            AxisCmd::Rate(w) => (r - w).abs() <= 1.0,
            AxisCmd::Osc { .. } => true,
        })
    }

    /// The segment an acquisition records under the current commands: oscillation if an
    /// axis sways, rate if an axis is in rate mode (0 deg/s included), else static with the
    /// nominal attitude (the target, or the feedback angle when the axis stopped freely).
    pub fn segment(
        &self,
        id: String,
        t_start: f64,
        t_end: f64,
        last: Option<&TableSample>,
    ) -> Segment {
        let mut seg = Segment::new(id, SegmentKind::Static, t_start, t_end);
        let pick = |want: fn(&AxisCmd) -> bool| -> Option<Axis> {
            match self.last_axis {
                Some(a) if want(&self.axis(a)) => Some(a),
                _ => [Axis::Outer, Axis::Inner]
                    .into_iter()
                    .find(|&a| want(&self.axis(a))),
            }
        };
        if let Some(a) = pick(|c| matches!(c, AxisCmd::Osc { .. })) {
            if let AxisCmd::Osc {
                center,
                amplitude,
                period,
            } = self.axis(a)
            {
                seg.kind = SegmentKind::Oscillation;
                seg.axis = Some(axis_name(a).into());
                seg.amplitude_deg = Some(amplitude);
                seg.period_s = Some(period);
                seg.center_deg = Some(center);
            }
        } else if let Some(a) = pick(|c| matches!(c, AxisCmd::Rate(_))) {
            if let AxisCmd::Rate(w) = self.axis(a) {
                seg.kind = SegmentKind::Rate;
                seg.axis = Some(axis_name(a).into());
                seg.rate_dps = Some(w);
            }
        } else {
            let nominal = |c: AxisCmd, fb: Option<f64>| match c {
                AxisCmd::Hold(Some(t)) => Some(t),
                _ => fb.map(wrap180),
            };
            seg.pitch_deg = nominal(self.outer, last.map(|s| s.outer_deg));
            seg.roll_deg = nominal(self.inner, last.map(|s| s.inner_deg));
        }
        seg
    }
}

/// `outer` / `inner`.
pub(crate) fn axis_name(a: Axis) -> &'static str {
    match a {
        Axis::Outer => "outer",
        Axis::Inner => "inner",
    }
}

/// Substitutes `{var}` with repeat indices (innermost binding wins); other braces stay.
pub(super) fn substitute(template: &str, vars: &[(String, u64)]) -> String {
    let mut out = String::with_capacity(template.len());
    let mut rest = template;
    while let Some(open) = rest.find('{') {
        out.push_str(&rest[..open]);
        let after = &rest[open + 1..];
        match after.find('}') {
            Some(close) => {
                let name = &after[..close];
                match vars.iter().rev().find(|(n, _)| n == name) {
                    Some((_, v)) => out.push_str(&v.to_string()),
                    None => out.push_str(&rest[open..open + close + 2]),
                }
                rest = &after[close + 1..];
            }
            None => {
                out.push_str(&rest[open..]);
                rest = "";
            }
        }
    }
    out.push_str(rest);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(outer: f64, inner: f64, wo: f64, wi: f64) -> TableSample {
        TableSample {
            t: 0.0,
            outer_deg: outer,
            inner_deg: inner,
            outer_rate_dps: wo,
            inner_rate_dps: wi,
            ambient_c: None,
            t_host: None,
        }
    }

    #[test]
    fn wrap_and_errors() {
        assert_eq!(wrap180(359.0), -1.0);
        assert_eq!(wrap180(-180.0), 180.0);
        let mut c = CmdState {
            outer: AxisCmd::Hold(Some(90.0)),
            inner: AxisCmd::Hold(Some(-90.0)),
            last_axis: None,
        };
        let (att, rate) = c.errors(&sample(90.001, 270.0005, 0.02, -0.01));
        assert!((att - 0.001).abs() < 1e-9 && (rate - 0.02).abs() < 1e-12);
        c.set(Axis::Inner, AxisCmd::Rate(50.0));
        let (att, rate) = c.errors(&sample(90.0, 1234.0, 0.0, 49.7));
        assert!(att.abs() < 1e-9 && (rate - 0.3).abs() < 1e-9);
    }

    #[test]
    fn segment_kinds() {
        let mut c = CmdState {
            outer: AxisCmd::Hold(Some(0.0)),
            inner: AxisCmd::Hold(None),
            last_axis: None,
        };
        let s = c.segment("a".into(), 1.0, 2.0, Some(&sample(0.0, 270.0, 0.0, 0.0)));
        assert_eq!(
            (s.kind, s.pitch_deg, s.roll_deg),
            (SegmentKind::Static, Some(0.0), Some(-90.0))
        );
        c.set(Axis::Outer, AxisCmd::Rate(0.0));
        let s = c.segment("b".into(), 1.0, 2.0, None);
        assert_eq!(
            (s.kind, s.axis.as_deref(), s.rate_dps),
            (SegmentKind::Rate, Some("outer"), Some(0.0))
        );
        c.set(
            Axis::Inner,
            AxisCmd::Osc {
                center: 10.0,
                amplitude: 90.0,
                period: 5.0,
            },
        );
        let s = c.segment("c".into(), 1.0, 2.0, None);
        assert_eq!(
            (s.kind, s.axis.as_deref(), s.center_deg),
            (SegmentKind::Oscillation, Some("inner"), Some(10.0))
        );
    }

    #[test]
    fn substitutes_repeat_indices() {
        let vars = vec![("run".to_string(), 2), ("k".to_string(), 7)];
        assert_eq!(substitute("bias/{run}/{k}", &vars), "bias/2/7");
        assert_eq!(substitute("a/{other}/{k", &vars), "a/{other}/{k");
    }
}
