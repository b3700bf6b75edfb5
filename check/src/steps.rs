//! Steps: walking statements into plan nodes, expanding `for` loops, following the table's
//! motion (for observability and duration), recording segments and station limits.

use super::values::{RVal, Val, suggest};
use super::{Ck, MAX_EXPANDED_ACTIONS, mount_up};
use ratecal_grammar::Diagnostic;
use ratecal_grammar::ast::{self, Block, Span, Stmt, Value, ValueKind};
use ratecal_physics::Mat3;
use ratecal_plan::{Acquire, Action, Axis, Dim, Node, OnTimeout, Plan, Settle, Step};

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
    pub manual: super::manual::ManualWalk,
    /// A statement that records segments could not be checked (a loop over a list with
    /// a wrong unit, a segment name naming nothing): which segments exist is unknown, so
    /// matching fits and verifications against them would only repeat that error.
    pub incomplete: bool,
    /// The table statement no settle has followed yet.
    pub unsettled: Option<Span>,
    /// The attitude limit (deg) of the settle since the last table statement, and where.
    pub settle_attitude: Option<(f64, Span)>,
    /// Static acquisitions, for the check of their settles against the attitude aborts.
    pub static_acquires: Vec<StaticAcquire>,
}

/// A static acquisition and how the table was brought to rest before it.
#[derive(Debug, Clone)]
pub(crate) struct StaticAcquire {
    /// The acquisition.
    pub span: Span,
    /// The table statement it follows with no settle between them.
    pub unsettled: Option<Span>,
    /// The settle's attitude limit, deg, and where it is written.
    pub settle_attitude: Option<(f64, Span)>,
    /// The step's own attitude abort limit, deg, and its rule.
    pub step_limit: Option<(f64, String)>,
}

pub(crate) fn move_time(dist_deg: f64, v: f64, a: f64) -> f64 {
    let d = dist_deg.abs();
    if d >= v * v / a {
        d / v + v / a
    } else {
        2.0 * (d / a).sqrt()
    }
}

impl Ck<'_> {
    /// Registers segment `id` (an acquisition or a hand turn) at the walk's motion, with
    /// the repeat variables (count > 1) that enclose it.
    pub(crate) fn register_segment(&mut self, id: &str, span: Span) {
        let repeats = self
            .walk
            .repeats
            .iter()
            .filter(|(_, n)| *n > 1)
            .map(|(v, _)| v.clone())
            .collect();
        self.walk.segments.push(SegInfo {
            id: id.to_string(),
            span,
            motion: self.walk.motion.clone(),
            repeats,
        });
    }

    pub(crate) fn table_limits(&self) -> (f64, f64) {
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
        aborts: &mut Vec<ratecal_plan::AbortRule>,
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
        aborts: &mut Vec<ratecal_plan::AbortRule>,
        out: &mut Vec<Node>,
    ) {
        match s {
            Stmt::Move(..) | Stmt::Spin { .. } | Stmt::Stop(..) | Stmt::Oscillate { .. } => {
                self.table_statement(span);
                self.walk.unsettled = Some(span);
                self.walk.settle_attitude = None;
            }
            Stmt::SettleFor(..) | Stmt::Settle(..) => self.walk.unsettled = None,
            Stmt::Acquire { .. } => self.rest_missing(),
            _ => {}
        }
        match s {
            Stmt::Place {
                face,
                within,
                message,
            } => out.extend(
                self.place(face.as_ref(), within.as_ref(), message.as_ref(), span)
                    .map(Node::Do),
            ),
            Stmt::Turn { about, segment } => {
                out.extend(self.turn(about.as_ref(), segment, span).map(Node::Do))
            }
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
                self.walk.settle_attitude = st.attitude_error_deg.map(|a| (a, span));
                self.settled(&st);
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
                if self.walk.motion.is_static() {
                    let step_limit = attitude_limit(aborts);
                    self.walk.static_acquires.push(StaticAcquire {
                        span,
                        unsettled: self.walk.unsettled,
                        settle_attitude: self.walk.settle_attitude,
                        step_limit,
                    });
                }
                let id = self.segment_id(&segment.node, segment.span);
                let Some(id) = id else {
                    self.walk.incomplete = true;
                    return;
                };
                // Registered even when its duration or rate is wrong, so that fits naming
                // it do not report a second, spurious error.
                self.register_segment(&id, segment.span);
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
        aborts: &mut Vec<ratecal_plan::AbortRule>,
        out: &mut Vec<Node>,
    ) {
        let Some(r) = self.resolve(list, None) else {
            self.walk.incomplete = true;
            return;
        };
        let Val::List(items) = r.v else {
            self.walk.incomplete = true;
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
                        self.walk.incomplete = true;
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
}

/// The tightest attitude-error abort limit among `rules` (deg), with its rule's text.
pub(crate) fn attitude_limit(rules: &[ratecal_plan::AbortRule]) -> Option<(f64, String)> {
    rules
        .iter()
        .filter_map(|r| match r.condition {
            ratecal_plan::AbortCondition::Above {
                signal: ratecal_plan::Signal::AttitudeError,
                limit,
            } if r.action == ratecal_plan::AbortAction::Abort => Some((limit, r.text.clone())),
            _ => None,
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))
}

impl Ck<'_> {
    /// Every static acquisition starts with the table within the procedure's attitude
    /// limit (its abort rules on `table.attitude_error`): a settle must come between the
    /// table statement and the acquisition, and its own attitude limit must not be looser.
    pub(crate) fn settles_against_aborts(&mut self, plan: &Plan) {
        let global = attitude_limit(&plan.aborts);
        for a in std::mem::take(&mut self.walk.static_acquires) {
            let limit = match (&global, &a.step_limit) {
                (Some(g), Some(s)) => Some(if s.0 < g.0 { s.clone() } else { g.clone() }),
                (g, s) => g.clone().or_else(|| s.clone()),
            };
            let Some((limit, rule)) = limit else { continue };
            if let Some(moved) = a.unsettled {
                self.err(
                    Diagnostic::error(
                        "check::unsettled",
                        format!(
                            "this static acquisition may start before the table is within `{rule}`"
                        ),
                    )
                    .label(a.span, "acquires with no settle since the table last moved")
                    .label(moved, "the table moves here")
                    .help(format!(
                        "settle between the two, e.g. `settle {{ at least 30 s  table.attitude_error <= {}  timeout 120 s -> abort }}`",
                        limit_text(&rule)
                    )),
                );
            } else if let Some((settle, at)) = a.settle_attitude
                && settle > limit * (1.0 + 1e-9)
            {
                self.err(
                    Diagnostic::error(
                        "check::unsettled",
                        format!("this settle cannot bring the table within `{rule}`"),
                    )
                    .label(at, "its attitude limit is looser than the abort rule's")
                    .label(a.span, "the acquisition after it")
                    .help(format!(
                        "settle to `table.attitude_error <= {}` or tighter",
                        limit_text(&rule)
                    )),
                );
            }
        }
    }
}

/// The limit of an abort rule's text as written (`5 arcsec` of
/// `table.attitude_error > 5 arcsec for 1 s`).
fn limit_text(rule: &str) -> String {
    let after = rule.split_once('>').map_or(rule, |x| x.1).trim();
    after
        .split(" for ")
        .next()
        .unwrap_or(after)
        .trim()
        .to_string()
}
