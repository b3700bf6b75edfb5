//! Table motion as the plan leaves it: moves, spins, stops, oscillations, with their
//! durations and the station's rate, acceleration and gyro-range limits.

use super::Ck;
use super::steps::move_time;
use super::values::{Val, suggest};
use ratecal_grammar::Diagnostic;
use ratecal_grammar::ast::{self, Span, Value};
use ratecal_physics::TableState;
use ratecal_plan::{Action, Axis, Dim};

impl Ck<'_> {
    pub(crate) fn move_to(&mut self, angles: &[ast::Angle], span: Span) -> Option<Action> {
        let (mut outer, mut inner) = (None, None);
        let mut origin: Option<Span> = None;
        let mut pitch_roll = false;
        let mut ok = true;
        for a in angles {
            let (slot, index) = match a.axis.node.as_str() {
                "pitch" | "outer" => (&mut outer, 0),
                "roll" | "inner" => (&mut inner, 1),
                other => {
                    self.err(
                        Diagnostic::error(
                            "check::unknown_name",
                            format!("unknown table angle `{other}`"),
                        )
                        .label(a.axis.span, "not an angle name")
                        .help(suggest(other, &["pitch", "roll", "outer", "inner"])),
                    );
                    ok = false;
                    continue;
                }
            };
            pitch_roll |= matches!(a.axis.node.as_str(), "pitch" | "roll");
            if slot.is_some() {
                self.err(
                    Diagnostic::error(
                        "check::structure",
                        format!("`{}` is given twice", a.axis.node),
                    )
                    .label(a.axis.span, "second value for the same axis")
                    .help("pitch is the outer axis, roll the inner one"),
                );
                ok = false;
                continue;
            }
            let Some(r) = self.resolve(&a.value, None) else {
                ok = false;
                continue;
            };
            origin = Some(origin.map_or(
                r.span,
                |o: Span| if o == r.span { o } else { o.join(r.span) },
            ));
            match self.as_quantity(&r, &a.value, Dim::Angle, "a table angle") {
                Some(q) => {
                    self.travel_check(index, &q, r.span);
                    *slot = Some(q.value);
                }
                None => ok = false,
            }
        }
        if !ok {
            return None;
        }
        let m = &self.walk.motion;
        let outer_deg = outer.or(m.outer).unwrap_or(0.0);
        let inner_deg = inner.or(m.inner).unwrap_or(0.0);
        let (v, a) = self.table_limits();
        let stop_t = (m.outer_rate.abs().max(m.inner_rate.abs())) / a;
        let t = move_time(outer_deg - m.outer.unwrap_or(0.0), v, a).max(move_time(
            inner_deg - m.inner.unwrap_or(0.0),
            v,
            a,
        ));
        self.walk.time_s += stop_t + t;
        let mount = m.mount;
        self.walk.motion = super::steps::Motion {
            outer: Some(outer_deg),
            inner: Some(inner_deg),
            mount,
            origin: origin.unwrap_or(span),
            pitch_roll,
            ..Default::default()
        };
        Some(Action::MoveTo {
            outer_deg,
            inner_deg,
        })
    }

    pub(crate) fn axis(&mut self, v: &Value) -> Option<Axis> {
        let r = self.resolve(v, None)?;
        match &r.v {
            Val::Sym(s) | Val::Str(s) => match s.as_str() {
                "outer" | "pitch" => Some(Axis::Outer),
                "inner" | "roll" => Some(Axis::Inner),
                other => {
                    let mut names = vec!["outer", "inner", "pitch", "roll"];
                    let known = self.known_names();
                    names.extend(known.iter().map(String::as_str));
                    self.err(
                        Diagnostic::error("check::unknown_name", format!("unknown axis `{other}`"))
                            .label(v.span, "not a table axis")
                            .help(suggest(other, &names)),
                    );
                    None
                }
            },
            _ => {
                self.err(
                    Diagnostic::error("check::type_mismatch", "expected a table axis")
                        .label(r.span, "not an axis")
                        .help("write `outer` (pitch) or `inner` (roll)"),
                );
                None
            }
        }
    }

    /// An angle within the station's travel of that axis (`index` 0 outer, 1 inner).
    fn travel_check(&mut self, index: usize, q: &ratecal_plan::Quantity, span: Span) {
        let Some((lo, hi)) = self.station.as_ref().and_then(|s| s.travel_deg[index]) else {
            return;
        };
        if q.value >= lo - 1e-9 && q.value <= hi + 1e-9 {
            return;
        }
        let (axis, key) = [("outer", "outer_travel"), ("inner", "inner_travel")][index];
        self.err(
            Diagnostic::error(
                "check::station_limit",
                format!("angle beyond the travel of the table's {axis} axis"),
            )
            .label(
                span,
                format!(
                    "{} {}, the station's `table.{key}` is {lo} deg .. {hi} deg",
                    q.written, q.unit
                ),
            )
            .help("write the attitude within the axis's travel (an angle and the angle 360 deg away name the same attitude)"),
        );
    }

    /// A spin or oscillation needs an axis that may turn that far: a spin one without end.
    fn travel_spin(&mut self, ax: Axis, span: Span) {
        let index = usize::from(ax == Axis::Inner);
        let Some((lo, hi)) = self.station.as_ref().and_then(|s| s.travel_deg[index]) else {
            return;
        };
        let (axis, key) = [("outer", "outer_travel"), ("inner", "inner_travel")][index];
        self.err(
            Diagnostic::error(
                "check::station_limit",
                format!("the table's {axis} axis cannot spin: its travel is limited"),
            )
            .label(
                span,
                format!("the station's `table.{key}` is {lo} deg .. {hi} deg"),
            )
            .help("spin an axis that turns without end, or run on a station whose table can"),
        );
    }

    pub(crate) fn spin(&mut self, ax: Axis, rate: f64, span: Span) {
        if rate != 0.0 {
            self.travel_spin(ax, span);
        }
        let (_, a) = self.table_limits();
        let m = &mut self.walk.motion;
        let cur = match ax {
            Axis::Outer => &mut m.outer_rate,
            Axis::Inner => &mut m.inner_rate,
        };
        let dt = (rate - *cur).abs() / a;
        *cur = rate;
        match ax {
            Axis::Outer => m.outer = None,
            Axis::Inner => m.inner = None,
        }
        m.osc = None;
        self.walk.time_s += dt;
        self.rate_limits(span);
    }

    pub(crate) fn stop(&mut self, ax: Option<Axis>) {
        let (_, a) = self.table_limits();
        let m = &mut self.walk.motion;
        let mut dt: f64 = 0.0;
        if ax != Some(Axis::Inner) {
            dt = dt.max(m.outer_rate.abs() / a);
            if m.outer_rate != 0.0 || matches!(m.osc, Some((Axis::Outer, ..))) {
                m.outer = None;
            }
            m.outer_rate = 0.0;
        }
        if ax != Some(Axis::Outer) {
            dt = dt.max(m.inner_rate.abs() / a);
            if m.inner_rate != 0.0 || matches!(m.osc, Some((Axis::Inner, ..))) {
                m.inner = None;
            }
            m.inner_rate = 0.0;
        }
        if ax.is_none() || m.osc.is_some_and(|o| Some(o.0) == ax) {
            m.osc = None;
        }
        self.walk.time_s += dt;
    }

    pub(crate) fn oscillate(
        &mut self,
        ax: Axis,
        amp_deg: f64,
        period_s: f64,
        center: Option<f64>,
        span: Span,
    ) {
        let m = &mut self.walk.motion;
        match ax {
            Axis::Outer => m.outer = center.or(m.outer),
            Axis::Inner => m.inner = center.or(m.inner),
        }
        m.osc = Some((ax, amp_deg, period_s));
        let w = 2.0 * std::f64::consts::PI / period_s;
        let (peak_rate, peak_acc) = (amp_deg.abs() * w, amp_deg.abs() * w * w);
        if let Some(st) = self.station.clone()
            && peak_acc > st.max_accel_dps2
        {
            {
                self.err(
                    Diagnostic::error(
                        "check::station_limit",
                        "the oscillation exceeds the table's angular acceleration",
                    )
                    .label(
                        span,
                        format!(
                            "peak {peak_acc:.1} deg/s^2, the table allows {} deg/s^2",
                            st.max_accel_dps2
                        ),
                    )
                    .help("lower the amplitude or lengthen the period"),
                );
            }
        }
        self.rate_check(ax, peak_rate, span);
    }

    pub(crate) fn rate_limits(&mut self, span: Span) {
        let m = self.walk.motion.clone();
        if m.outer_rate != 0.0 {
            self.rate_check(Axis::Outer, m.outer_rate, span);
        }
        if m.inner_rate != 0.0 {
            self.rate_check(Axis::Inner, m.inner_rate, span);
        }
    }

    /// Compares a rate about an axis with the table's maximum and, projected on the body
    /// axes, with the gyro range.
    pub(crate) fn rate_check(&mut self, ax: Axis, rate: f64, span: Span) {
        let Some(st) = self.station.clone() else {
            return;
        };
        if rate.abs() > st.max_rate_dps {
            self.err(
                Diagnostic::error("check::station_limit", "rate above the table's maximum")
                    .label(
                        span,
                        format!(
                            "{} deg/s, the table allows {} deg/s",
                            rate.abs(),
                            st.max_rate_dps
                        ),
                    )
                    .help("lower the rate or use a faster table"),
            );
        }
        let m = &self.walk.motion;
        let mut state = TableState::at_rest_deg(m.outer.unwrap_or(0.0), m.inner.unwrap_or(0.0));
        let r = rate.to_radians();
        match ax {
            Axis::Outer => state.outer.rate = r,
            Axis::Inner => state.inner.rate = r,
        }
        let w_b = state
            .w_b(&st.geometry.with_mount(m.mount))
            .map(f64::to_degrees);
        if let Some(i) = (0..3).find(|&i| w_b[i].abs() > st.gyro_range_dps * (1.0 + 1e-9)) {
            self.err(
                Diagnostic::error("check::station_limit", "rate above the IMU's gyro range")
                    .label(
                        span,
                        format!(
                            "{:.1} deg/s on {}, the gyro range is {} deg/s",
                            w_b[i].abs(),
                            ["X", "Y", "Z"][i],
                            st.gyro_range_dps
                        ),
                    )
                    .help("lower the rate below the gyro range"),
            );
        }
    }
}
