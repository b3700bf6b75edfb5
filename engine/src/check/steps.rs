//! Steps: walking statements into plan nodes, expanding `for` loops, following the table's
//! motion (for observability and duration), recording segments and station limits.

use super::values::{RVal, Val, suggest};
use super::{Ck, MAX_EXPANDED_ACTIONS, mount_up};
use crate::plan::{
    Acquire, Action, Axis, Dim, Node, OnTimeout, Plan, Settle, Signal, Stability, Step,
};
use ratecal_grammar::Diagnostic;
use ratecal_grammar::ast::{self, Block, Span, Stmt, Value, ValueKind};
use ratecal_physics::{Mat3, TableState};

/// Table rate used for the duration estimate when no station is given, deg/s.
pub const DEFAULT_MAX_RATE_DPS: f64 = 300.0;
/// Table angular acceleration used for the duration estimate when no station is given, deg/s^2.
pub const DEFAULT_MAX_ACCEL_DPS2: f64 = 100.0;
/// Time an operator is assumed to need for a remount, s.
const REMOUNT_S: f64 = 300.0;

/// The table's state as the plan leaves it.
#[derive(Debug, Clone)]
pub(crate) struct Motion {
    pub outer: Option<f64>,
    pub inner: Option<f64>,
    pub outer_rate: f64,
    pub inner_rate: f64,
    /// Oscillating axis, amplitude deg, period s.
    pub osc: Option<(Axis, f64, f64)>,
    pub mount: Mat3,
    /// Where the current attitude was written.
    pub origin: Span,
    /// Whether the attitude was written as pitch/roll.
    pub pitch_roll: bool,
}

impl Default for Motion {
    fn default() -> Self {
        Motion {
            outer: Some(0.0),
            inner: Some(0.0),
            outer_rate: 0.0,
            inner_rate: 0.0,
            osc: None,
            mount: Mat3::identity(),
            origin: Span::default(),
            pitch_roll: false,
        }
    }
}

impl Motion {
    /// Whether the table is at rest at a known attitude.
    pub fn is_static(&self) -> bool {
        self.outer_rate == 0.0
            && self.inner_rate == 0.0
            && self.osc.is_none()
            && self.outer.is_some()
            && self.inner.is_some()
    }
}

/// A recorded segment as planned.
#[derive(Debug, Clone)]
pub(crate) struct SegInfo {
    pub id: String,
    pub span: Span,
    pub motion: Motion,
    /// Repeat variables (count > 1) enclosing the acquisition.
    pub repeats: Vec<String>,
}

/// A fit waiting for the observability check.
#[derive(Debug, Clone)]
pub(crate) struct FitCheck {
    pub index: usize,
    pub span: Span,
    pub axes: Vec<(usize, Span)>,
    pub from: Vec<ast::Spanned<String>>,
    pub using: Option<ast::Spanned<String>>,
}

/// What the walk accumulates across steps.
#[derive(Debug, Default)]
pub(crate) struct Walk {
    pub segments: Vec<SegInfo>,
    pub motion: Motion,
    pub repeats: Vec<(String, u64)>,
    pub time_s: f64,
    pub fits: Vec<FitCheck>,
    pub step: String,
    pub max_list_len: u64,
    pub verify_from: Vec<ast::Spanned<String>>,
}

fn move_time(dist_deg: f64, v: f64, a: f64) -> f64 {
    let d = dist_deg.abs();
    if d >= v * v / a {
        d / v + v / a
    } else {
        2.0 * (d / a).sqrt()
    }
}

impl Ck<'_> {
    fn table_limits(&self) -> (f64, f64) {
        self.station
            .as_ref()
            .map_or((DEFAULT_MAX_RATE_DPS, DEFAULT_MAX_ACCEL_DPS2), |s| {
                (s.max_rate_dps, s.max_accel_dps2)
            })
    }

    pub(crate) fn step(&mut self, s: &ast::Step, plan: &mut Plan) -> Step {
        self.walk.step = s.name.node.clone();
        let t0 = self.walk.time_s;
        let mut aborts = Vec::new();
        let n = self.count_actions(&s.body);
        let body = if n > MAX_EXPANDED_ACTIONS {
            self.err(
                Diagnostic::error(
                    "check::expansion_too_large",
                    format!("step `{}` would expand to {n} actions", s.name.node),
                )
                .label(
                    s.name.span,
                    format!(
                        "more than {MAX_EXPANDED_ACTIONS} actions once its `for` loops are expanded"
                    ),
                )
                .help("use `repeat N` for repetitions (it is not expanded) or shorten the lists"),
            );
            Vec::new()
        } else {
            self.stmts(&s.body, plan, &mut aborts)
        };
        Step {
            name: s.name.node.clone(),
            title: s.title.as_ref().map(|t| t.node.clone()),
            aborts,
            body,
            estimated_duration_s: self.walk.time_s - t0,
        }
    }

    /// Actions a block expands to, computed without expanding.
    fn count_actions(&mut self, b: &Block<Stmt>) -> u64 {
        let mut n: u64 = 0;
        for item in &b.items {
            let k = match &item.node {
                Stmt::For { list, body, .. } => {
                    self.list_len(list).saturating_mul(self.count_actions(body))
                }
                Stmt::Repeat { body, .. } => self.count_actions(body).saturating_add(1),
                _ => 1,
            };
            n = n.saturating_add(k);
        }
        n
    }

    fn list_len(&mut self, v: &Value) -> u64 {
        match &v.kind {
            ValueKind::List { items, .. } => items.len() as u64,
            ValueKind::Name(n) => match self.params.get(n) {
                Some((
                    RVal {
                        v: Val::List(items),
                        ..
                    },
                    _,
                )) => items.len() as u64,
                // A loop variable holding a list: bound by the longest list written anywhere.
                _ => self.walk.max_list_len.max(1),
            },
            _ => 1,
        }
    }

    fn stmts(
        &mut self,
        b: &Block<Stmt>,
        plan: &mut Plan,
        aborts: &mut Vec<crate::plan::AbortRule>,
    ) -> Vec<Node> {
        let mut out = Vec::new();
        for item in &b.items {
            self.stmt(&item.node, item.span, plan, aborts, &mut out);
        }
        out
    }

    fn stmt(
        &mut self,
        s: &Stmt,
        span: Span,
        plan: &mut Plan,
        aborts: &mut Vec<crate::plan::AbortRule>,
        out: &mut Vec<Node>,
    ) {
        match s {
            Stmt::Move(angles) => {
                if let Some(a) = self.move_to(angles, span) {
                    out.push(Node::Do(a));
                }
            }
            Stmt::Spin { axis, rate } => {
                let ax = self.axis(axis);
                // Limits are reported on the value as written (a list element in a loop).
                let rv = self.resolve(rate, None);
                let at = rv.as_ref().map_or(rate.span, |r| r.span);
                let r = rv.and_then(|r| self.as_quantity(&r, rate, Dim::Rate, "a spin rate"));
                if let (Some(ax), Some(r)) = (ax, r) {
                    self.spin(ax, r.value, at);
                    out.push(Node::Do(Action::Spin {
                        axis: ax,
                        rate_dps: r.value,
                    }));
                }
            }
            Stmt::Stop(axis) => {
                let ax = match axis {
                    Some(a) => match self.axis(a) {
                        Some(x) => Some(x),
                        None => return,
                    },
                    None => None,
                };
                self.stop(ax);
                out.push(Node::Do(Action::Stop { axis: ax }));
            }
            Stmt::Oscillate {
                axis,
                amplitude,
                period,
                center,
                duration,
            } => {
                let ax = self.axis(axis);
                let amp = self.quantity(amplitude, Dim::Angle, "an oscillation amplitude");
                let per = self.quantity(period, Dim::Time, "an oscillation period");
                let cen = center
                    .as_ref()
                    .map(|c| self.quantity(c, Dim::Angle, "an oscillation centre"));
                let dur = self.quantity(duration, Dim::Time, "an oscillation duration");
                let (Some(ax), Some(amp), Some(per), Some(dur)) = (ax, amp, per, dur) else {
                    return;
                };
                let center_deg = match cen {
                    Some(Some(c)) => Some(c.value),
                    Some(None) => return,
                    None => None,
                };
                if per.value <= 0.0 {
                    self.err(
                        Diagnostic::error("check::bad_number", "the period must be positive")
                            .label(period.span, "not positive"),
                    );
                    return;
                }
                self.oscillate(ax, amp.value, per.value, center_deg, span);
                out.push(Node::Do(Action::Oscillate {
                    axis: ax,
                    amplitude_deg: amp.value,
                    period_s: per.value,
                    center_deg,
                    duration_s: dur.value,
                }));
            }
            Stmt::Hold(v) => {
                if let Some(t) = self.quantity(v, Dim::Time, "a hold") {
                    self.walk.time_s += t.value;
                    out.push(Node::Do(Action::Hold {
                        duration_s: t.value,
                    }));
                }
            }
            Stmt::SettleFor(v) => {
                if let Some(t) = self.quantity(v, Dim::Time, "`settle for`") {
                    self.walk.time_s += t.value;
                    out.push(Node::Do(Action::Settle(Settle {
                        min_time_s: t.value,
                        stable: Vec::new(),
                        attitude_error_deg: None,
                        rate_error_dps: None,
                        timeout_s: None,
                        on_timeout: OnTimeout::Abort,
                    })));
                }
            }
            Stmt::Settle(b) => {
                let st = self.settle(b);
                self.walk.time_s += st.min_time_s;
                out.push(Node::Do(Action::Settle(st)));
            }
            Stmt::Acquire {
                channels,
                duration,
                rate,
                segment,
            } => {
                for c in channels {
                    if !["accel", "gyro", "table", "temp"].contains(&c.node.as_str()) {
                        self.err(
                            Diagnostic::error(
                                "check::unknown_name",
                                format!("unknown channel `{}`", c.node),
                            )
                            .label(c.span, "not a channel")
                            .help(suggest(&c.node, &["accel", "gyro", "table", "temp"])),
                        );
                    }
                }
                let d = self.quantity(duration, Dim::Time, "an acquisition duration");
                let r = self.quantity(rate, Dim::Frequency, "a sample rate");
                let id = self.segment_id(&segment.node, segment.span);
                let Some(id) = id else { return };
                let repeats = self
                    .walk
                    .repeats
                    .iter()
                    .filter(|(_, n)| *n > 1)
                    .map(|(v, _)| v.clone())
                    .collect();
                // Registered even when its duration or rate is wrong, so that fits naming
                // it do not report a second, spurious error.
                self.walk.segments.push(SegInfo {
                    id: id.clone(),
                    span: segment.span,
                    motion: self.walk.motion.clone(),
                    repeats,
                });
                let (Some(d), Some(r)) = (d, r) else { return };
                self.walk.time_s += d.value;
                out.push(Node::Do(Action::Acquire(Acquire {
                    segment: id,
                    channels: channels.iter().map(|c| c.node.clone()).collect(),
                    duration_s: d.value,
                    rate_hz: r.value,
                })));
            }
            Stmt::For {
                vars,
                tuple,
                list,
                body,
            } => self.for_loop(vars, *tuple, list, body, plan, aborts, out),
            Stmt::Repeat { count, var, body } => {
                let Some(n) = self.count(count, "a repeat count") else {
                    return;
                };
                let name = var.as_ref().map(|v| v.node.clone());
                self.walk
                    .repeats
                    .push((name.clone().unwrap_or_default(), n));
                let t0 = self.walk.time_s;
                let inner = self.stmts(body, plan, aborts);
                self.walk.repeats.pop();
                let once = self.walk.time_s - t0;
                self.walk.time_s = t0 + once * n as f64;
                out.push(Node::Repeat {
                    count: n,
                    var: name,
                    body: inner,
                });
            }
            Stmt::Fit(f) => self.fit(f, span, plan),
            Stmt::Accept(a) => {
                let step = Some(self.walk.step.clone());
                if let Some(acc) = self.accept(a, step) {
                    plan.accepts.push(acc);
                }
            }
            Stmt::Verify(v) => {
                if let Some(v) = self.verify(v) {
                    plan.verifications.push(v);
                }
            }
            Stmt::Abort(a) => {
                if let Some(r) = self.abort(a) {
                    aborts.push(r);
                }
            }
            Stmt::Remount { axis, message } => {
                // The axis may be a loop variable (`for axis in [z, x, y] { remount axis up }`).
                let bound = self
                    .scopes
                    .iter()
                    .rev()
                    .flat_map(|s| s.iter())
                    .find(|(n, _)| *n == axis.node)
                    .map(|(_, v)| v.v.clone());
                let name = match bound {
                    Some(Val::Sym(s)) | Some(Val::Str(s)) => s,
                    _ => axis.node.clone(),
                };
                let k = match name.as_str() {
                    "x" => 0,
                    "y" => 1,
                    "z" => 2,
                    other => {
                        self.err(
                            Diagnostic::error(
                                "check::unknown_name",
                                format!("unknown body axis `{other}`"),
                            )
                            .label(axis.span, "not a body axis")
                            .help(suggest(other, &["x", "y", "z"])),
                        );
                        return;
                    }
                };
                let m = mount_up(k);
                self.walk.motion.mount = m;
                self.walk.time_s += REMOUNT_S;
                let rotation = [
                    [m[(0, 0)], m[(0, 1)], m[(0, 2)]],
                    [m[(1, 0)], m[(1, 1)], m[(1, 2)]],
                    [m[(2, 0)], m[(2, 1)], m[(2, 2)]],
                ];
                let message = message.as_ref().map_or_else(
                    || format!("Remount the IMU with its {} axis up", name.to_uppercase()),
                    |m| m.node.clone(),
                );
                out.push(Node::Do(Action::Remount { rotation, message }));
            }
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn for_loop(
        &mut self,
        vars: &[ast::Ident],
        tuple: bool,
        list: &Value,
        body: &Block<Stmt>,
        plan: &mut Plan,
        aborts: &mut Vec<crate::plan::AbortRule>,
        out: &mut Vec<Node>,
    ) {
        let Some(r) = self.resolve(list, None) else {
            return;
        };
        let Val::List(items) = r.v else {
            self.err(
                Diagnostic::error("check::type_mismatch", "a `for` loop runs over a list")
                    .label(list.span, "not a list")
                    .help("write a list, e.g. `[1, 2, 3]`, or name a parameter holding one"),
            );
            return;
        };
        for el in items {
            let mut scope = Vec::new();
            if tuple || vars.len() > 1 {
                let parts = match &el.v {
                    Val::Tuple(p) if p.len() == vars.len() => p.clone(),
                    _ => {
                        self.err(
                            Diagnostic::error(
                                "check::loop_arity",
                                format!("each element must be a tuple of {} values", vars.len()),
                            )
                            .label(el.span, "does not match the loop variables")
                            .help(format!(
                                "write elements as ({})",
                                vars.iter()
                                    .map(|v| v.node.as_str())
                                    .collect::<Vec<_>>()
                                    .join(", ")
                            )),
                        );
                        continue;
                    }
                };
                // Each variable remembers the whole tuple: diagnostics point at the row.
                for (v, p) in vars.iter().zip(parts) {
                    scope.push((
                        v.node.clone(),
                        RVal {
                            v: p.v,
                            span: el.span,
                        },
                    ));
                }
            } else {
                scope.push((vars[0].node.clone(), el));
            }
            self.scopes.push(scope);
            let nodes = self.stmts(body, plan, aborts);
            self.scopes.pop();
            out.extend(nodes);
        }
    }

    fn move_to(&mut self, angles: &[ast::Angle], span: Span) -> Option<Action> {
        let (mut outer, mut inner) = (None, None);
        let mut origin: Option<Span> = None;
        let mut pitch_roll = false;
        let mut ok = true;
        for a in angles {
            let slot = match a.axis.node.as_str() {
                "pitch" | "outer" => &mut outer,
                "roll" | "inner" => &mut inner,
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
                Some(q) => *slot = Some(q.value),
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

    fn spin(&mut self, ax: Axis, rate: f64, span: Span) {
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

    fn stop(&mut self, ax: Option<Axis>) {
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

    fn oscillate(
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

    fn rate_limits(&mut self, span: Span) {
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
    fn rate_check(&mut self, ax: Axis, rate: f64, span: Span) {
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

    fn settle(&mut self, b: &Block<ast::SettleItem>) -> Settle {
        let mut st = Settle {
            min_time_s: 0.0,
            stable: Vec::new(),
            attitude_error_deg: None,
            rate_error_dps: None,
            timeout_s: None,
            on_timeout: OnTimeout::Abort,
        };
        for item in &b.items {
            match &item.node {
                ast::SettleItem::AtLeast(v) => {
                    if let Some(q) = self.quantity(v, Dim::Time, "a settle time") {
                        st.min_time_s = q.value;
                    }
                }
                ast::SettleItem::Timeout(v, act) => {
                    if let Some(q) = self.quantity(v, Dim::Time, "a timeout") {
                        st.timeout_s = Some(q.value);
                    }
                    if let Some(a) = act {
                        st.on_timeout = match a.node.as_str() {
                            "abort" => OnTimeout::Abort,
                            "warn" => OnTimeout::Warn,
                            "continue" => OnTimeout::Continue,
                            other => {
                                self.err(
                                    Diagnostic::error(
                                        "check::unknown_name",
                                        format!("unknown timeout action `{other}`"),
                                    )
                                    .label(a.span, "not an action")
                                    .help(suggest(other, &["abort", "warn", "continue"])),
                                );
                                OnTimeout::Abort
                            }
                        };
                    }
                }
                ast::SettleItem::Fluctuation {
                    signal,
                    value,
                    window,
                    ..
                } => {
                    let (sig, dim) = match signal.node.as_str() {
                        "accel" => (Signal::Accel, Dim::Accel),
                        "gyro" => (Signal::Gyro, Dim::Rate),
                        other => {
                            self.err(
                                Diagnostic::error(
                                    "check::unknown_name",
                                    format!("unknown signal `{other}`"),
                                )
                                .label(signal.span, "no fluctuation limit on this signal")
                                .help(suggest(other, &["accel", "gyro"])),
                            );
                            continue;
                        }
                    };
                    let q = self.quantity(value, dim, "a fluctuation limit");
                    let w = self.quantity(window, Dim::Time, "a stability window");
                    if let (Some(q), Some(w)) = (q, w) {
                        st.stable.push(Stability {
                            signal: sig,
                            max_fluctuation: q.value,
                            window_s: w.value,
                        });
                    }
                }
                ast::SettleItem::Limit(l) => match l.name.node.as_str() {
                    "table.attitude_error" => {
                        st.attitude_error_deg = self
                            .quantity(&l.value, Dim::Angle, "an attitude error limit")
                            .map(|q| q.value)
                    }
                    "table.rate_error" => {
                        st.rate_error_dps = self
                            .quantity(&l.value, Dim::Rate, "a rate error limit")
                            .map(|q| q.value)
                    }
                    other => self.err(
                        Diagnostic::error(
                            "check::unknown_name",
                            format!("unknown settle condition `{other}`"),
                        )
                        .label(l.name.span, "not a settle condition")
                        .help(suggest(
                            other,
                            &[
                                "table.attitude_error",
                                "table.rate_error",
                                "accel fluctuation",
                                "gyro fluctuation",
                            ],
                        )),
                    ),
                },
            }
        }
        st
    }

    /// Expands `{var}` / `{var:+}` in a segment name; repeat indices stay as `{var}`.
    fn segment_id(&mut self, template: &str, span: Span) -> Option<String> {
        let mut out = String::new();
        let mut rest = template;
        while let Some(open) = rest.find('{') {
            out.push_str(&rest[..open]);
            let Some(close) = rest[open..].find('}') else {
                self.err(
                    Diagnostic::error("check::bad_segment_name", "unclosed `{` in a segment name")
                        .label(span, "here")
                        .help("write `{name}` to insert a loop variable"),
                );
                return None;
            };
            let inner = &rest[open + 1..open + close];
            let (name, plus) = match inner.strip_suffix(":+") {
                Some(n) => (n, true),
                None => (inner, false),
            };
            if self.walk.repeats.iter().any(|(v, _)| v == name) {
                out.push_str(&rest[open..open + close + 1]);
            } else {
                let found = self
                    .scopes
                    .iter()
                    .rev()
                    .flat_map(|s| s.iter())
                    .find(|(n, _)| n == name)
                    .map(|(_, v)| v.clone());
                match found.map(|v| v.v) {
                    Some(Val::Num { text, q }) => {
                        if plus && !text.starts_with(['+', '-']) {
                            out.push('+');
                        }
                        let _ = q;
                        out.push_str(&text);
                    }
                    Some(Val::Sym(s)) | Some(Val::Str(s)) => out.push_str(&s),
                    Some(_) => {
                        self.err(
                            Diagnostic::error(
                                "check::type_mismatch",
                                format!("`{name}` cannot go in a segment name"),
                            )
                            .label(span, "a list or tuple")
                            .help("insert a number or a name"),
                        );
                        return None;
                    }
                    None => {
                        let mut names: Vec<String> = self
                            .scopes
                            .iter()
                            .flatten()
                            .map(|(n, _)| n.clone())
                            .collect();
                        names.extend(self.walk.repeats.iter().map(|(v, _)| v.clone()));
                        let refs: Vec<&str> = names.iter().map(String::as_str).collect();
                        self.err(
                            Diagnostic::error(
                                "check::unknown_name",
                                format!("unknown name `{name}` in a segment name"),
                            )
                            .label(span, "not a loop variable here")
                            .help(if refs.is_empty() {
                                "no loop variable is in scope here".to_string()
                            } else {
                                suggest(name, &refs)
                            }),
                        );
                        return None;
                    }
                }
            }
            rest = &rest[open + close + 1..];
        }
        out.push_str(rest);
        Some(out)
    }

    /// Duplicate segments, and segments inside repeats that do not use the index.
    pub(crate) fn finish_segments(&mut self) {
        let segs = std::mem::take(&mut self.walk.segments);
        let mut seen: std::collections::HashMap<&str, Span> = std::collections::HashMap::new();
        for s in &segs {
            for v in &s.repeats {
                if v.is_empty() || !s.id.contains(&format!("{{{v}}}")) {
                    self.err(
                        Diagnostic::error("check::segment_in_repeat", format!("segment `{}` would be recorded once per repetition under the same name", s.id))
                            .label(s.span, "inside a `repeat`")
                            .help("name the index (`repeat 3 as run`) and use it: \"name/{run}\""),
                    );
                }
            }
            if let Some(first) = seen.get(s.id.as_str()) {
                let mut d = Diagnostic::error(
                    "check::duplicate_segment",
                    format!("segment `{}` is recorded twice", s.id),
                )
                .label(s.span, "recorded again here");
                if *first != s.span {
                    d = d.label(*first, "first recorded here");
                }
                self.err(d.help(
                    "segment names must be unique: insert a loop variable, e.g. \"name/{n}\"",
                ));
            } else {
                seen.insert(&s.id, s.span);
            }
        }
        self.walk.segments = segs;
    }
}
