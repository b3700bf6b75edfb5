//! Differences inside a step: title, scoped abort rules, attitudes, rate points and other
//! motions, settle conditions and acquisitions. A step body is flattened (`repeat` bodies
//! inline) and viewed as sets of meaningful elements; each settle belongs to the
//! acquisition that follows it. A change that applies to every settle (acquisition) of a
//! step is reported once (`step accel_static / settle / fluctuation`), otherwise per
//! acquisition (`step gyro_scale / settle before gyro_scale/outer/+100 / min time`).

use super::limits;
use super::pair::{Pair, moved_pairs, pair};
use crate::change::{Change, ChangeKind, fmt_internal, fmt_num, fmt_s, same, signal_dim};
use crate::direction;
use ratecal_plan::{Acquire, Action, Axis, Dim, Node, Settle, Step};

/// A step's body, flattened and sorted by kind of element.
#[derive(Default)]
struct View<'a> {
    attitudes: Vec<String>,
    rates: Vec<String>,
    motions: Vec<String>,
    acquires: Vec<&'a Acquire>,
    settles: Vec<(String, &'a Settle)>,
    repeats: Vec<(u64, Option<&'a str>)>,
}

fn axis_str(a: Axis) -> &'static str {
    match a {
        Axis::Outer => "outer",
        Axis::Inner => "inner",
    }
}

impl<'a> View<'a> {
    fn of(step: &'a Step) -> Self {
        let mut v = View::default();
        let mut pending: Vec<&'a Settle> = Vec::new();
        v.walk(&step.body, &mut pending);
        v.settles
            .extend(pending.into_iter().map(|s| ("end of step".to_string(), s)));
        v
    }

    fn walk(&mut self, nodes: &'a [Node], pending: &mut Vec<&'a Settle>) {
        for n in nodes {
            match n {
                Node::Repeat { count, var, body } => {
                    self.repeats.push((*count, var.as_deref()));
                    self.walk(body, pending);
                }
                Node::Do(a) => self.action(a, pending),
            }
        }
    }

    fn action(&mut self, a: &'a Action, pending: &mut Vec<&'a Settle>) {
        match a {
            Action::MoveTo {
                outer_deg,
                inner_deg,
            } => self.attitudes.push(format!(
                "pitch {} deg, roll {} deg",
                fmt_num(*outer_deg),
                fmt_num(*inner_deg)
            )),
            Action::Spin { axis, rate_dps } => {
                self.rates
                    .push(format!("{} {} deg/s", axis_str(*axis), fmt_num(*rate_dps)))
            }
            Action::Oscillate {
                axis,
                amplitude_deg,
                period_s,
                center_deg,
                duration_s,
            } => {
                let c = center_deg
                    .map(|c| format!(" about {} deg", fmt_num(c)))
                    .unwrap_or_default();
                self.motions.push(format!(
                    "oscillate {} {} deg, period {}{c}, for {}",
                    axis_str(*axis),
                    fmt_num(*amplitude_deg),
                    fmt_s(*period_s),
                    fmt_s(*duration_s)
                ))
            }
            Action::Hold { duration_s } => {
                self.motions.push(format!("hold {}", fmt_s(*duration_s)))
            }
            Action::Remount { rotation, message } => {
                self.motions
                    .push(format!("remount {rotation:?} \"{message}\""));
            }
            Action::Place(p) => self.attitudes.push(match &p.up {
                Some(up) => format!(
                    "place {up} up within {} deg",
                    fmt_num(p.tolerance_deg.unwrap_or(0.0))
                ),
                None => "place free".into(),
            }),
            Action::Turn(t) => self.motions.push(match (&t.axis, t.angle_deg) {
                (Some(a), Some(d)) => {
                    format!("turn about {a} by {} deg as {}", fmt_num(d), t.segment)
                }
                _ => format!("turn free as {}", t.segment),
            }),
            Action::Stop { .. } => {}
            Action::Settle(s) => pending.push(s),
            Action::Acquire(q) => {
                self.settles
                    .extend(pending.drain(..).map(|s| (q.segment.clone(), s)));
                self.acquires.push(q);
            }
        }
    }
}

/// Segment templates of a step's acquisitions, in order.
pub(super) fn segments(step: &Step) -> Vec<String> {
    View::of(step)
        .acquires
        .iter()
        .map(|a| a.segment.clone())
        .collect()
}

pub(super) fn step(o: &Step, n: &Step, out: &mut Vec<Change>) {
    let path = format!("step {}", n.name);
    match (&o.title, &n.title) {
        (a, b) if a == b => {}
        (a, b) => out.push(Change::new(
            format!("{path} / title"),
            ChangeKind::Changed,
            a.clone().or(Some(String::new())),
            b.clone().or(Some(String::new())),
        )),
    }
    limits::aborts(&format!("{path} / "), &o.aborts, &n.aborts, out);
    let before = out.len();
    let (ov, nv) = (View::of(o), View::of(n));
    elements(
        &format!("{path} / attitude"),
        &ov.attitudes,
        &nv.attitudes,
        true,
        out,
    );
    elements(
        &format!("{path} / rate point"),
        &ov.rates,
        &nv.rates,
        true,
        out,
    );
    elements(
        &format!("{path} / motion"),
        &ov.motions,
        &nv.motions,
        false,
        out,
    );
    repeats(&path, &ov.repeats, &nv.repeats, out);
    acquires(&path, &ov.acquires, &nv.acquires, out);
    settles(&path, &ov.settles, &nv.settles, out);
    // Safety net: a difference none of the views above names is still a change.
    if out.len() == before
        && !values_same(
            &serde_json::to_value(&o.body).ok(),
            &serde_json::to_value(&n.body).ok(),
        )
    {
        out.push(Change::value(
            format!("{path} / body"),
            ChangeKind::Changed,
            format!("{} node(s)", o.body.len()),
            format!("{} node(s)", n.body.len()),
        ));
    }
}

/// Whether two JSON trees are equal, numbers up to unit-conversion rounding.
fn values_same(a: &Option<serde_json::Value>, b: &Option<serde_json::Value>) -> bool {
    use serde_json::Value as V;
    fn eq(a: &V, b: &V) -> bool {
        match (a, b) {
            (V::Number(x), V::Number(y)) => match (x.as_f64(), y.as_f64()) {
                (Some(x), Some(y)) => same(x, y),
                _ => x == y,
            },
            (V::Array(x), V::Array(y)) => {
                x.len() == y.len() && x.iter().zip(y).all(|(x, y)| eq(x, y))
            }
            (V::Object(x), V::Object(y)) => {
                x.len() == y.len() && x.iter().all(|(k, v)| y.get(k).is_some_and(|w| eq(v, w)))
            }
            _ => a == b,
        }
    }
    match (a, b) {
        (Some(a), Some(b)) => eq(a, b),
        _ => a == b,
    }
}

/// Added, removed and (when `order` matters) moved elements of a multiset. An edited list
/// (elements both out and in, more than one of each, as one edit of a `for` list gives on
/// every axis) is one change: the list as it was and as it is, as a procedure writes it.
fn elements(path: &str, old: &[String], new: &[String], order: bool, out: &mut Vec<Change>) {
    let pairs = pair(old, new, |s| s.clone());
    let gone = pairs.iter().filter(|p| matches!(p, Pair::Old(..))).count();
    let came = pairs.iter().filter(|p| matches!(p, Pair::New(..))).count();
    if order && gone > 0 && came > 0 && gone + came > 2 {
        out.push(Change::value(
            format!("{path}s"),
            ChangeKind::Changed,
            compact(old),
            compact(new),
        ));
        return;
    }
    let mut flags = moved_pairs(&pairs).into_iter();
    for p in pairs {
        match p {
            Pair::Old(s) => out.push(Change::removed(format!("{path} {s}"), s.clone())),
            Pair::New(s) => out.push(Change::added(format!("{path} {s}"), s.clone())),
            Pair::Both(i, _, j, s) => {
                if flags.next().unwrap_or(false) && order {
                    out.push(Change::value(
                        format!("{path} {s}"),
                        ChangeKind::Moved,
                        format!("position {}", i + 1),
                        format!("position {}", j + 1),
                    ));
                }
            }
        }
    }
}

/// A list of elements as a procedure's `for` list reads: consecutive elements that share
/// their first and last word (`outer 50 deg/s`, `outer 100 deg/s`) as one group
/// (`outer 50, 100 deg/s`), groups separated by `; `.
fn compact(items: &[String]) -> String {
    let split = |s: &str| -> Option<(String, String, String)> {
        let w: Vec<&str> = s.split(' ').collect();
        (w.len() == 3).then(|| (w[0].into(), w[1].into(), w[2].into()))
    };
    let mut groups: Vec<(String, Vec<String>, String)> = Vec::new();
    for it in items {
        match (split(it), groups.last_mut()) {
            (Some((h, v, u)), Some(g)) if g.0 == h && g.2 == u && !g.1.is_empty() => g.1.push(v),
            (Some((h, v, u)), _) => groups.push((h, vec![v], u)),
            (None, _) => groups.push((it.clone(), Vec::new(), String::new())),
        }
    }
    if groups.is_empty() {
        return "none".into();
    }
    (groups.iter())
        .map(|(h, v, u)| match v.is_empty() {
            true => h.clone(),
            false => format!("{h} {} {u}", v.join(", ")),
        })
        .collect::<Vec<_>>()
        .join("; ")
}

fn repeats(
    path: &str,
    old: &[(u64, Option<&str>)],
    new: &[(u64, Option<&str>)],
    out: &mut Vec<Change>,
) {
    let one = old.len() == 1 && new.len() == 1;
    let label = |i: usize| {
        if one {
            format!("{path} / repeat")
        } else {
            format!("{path} / repeat {}", i + 1)
        }
    };
    let show = |r: &(u64, Option<&str>)| format!("{} times", r.0);
    for i in 0..old.len().max(new.len()) {
        match (old.get(i), new.get(i)) {
            (Some(a), Some(b)) if a.0 != b.0 => out.push(Change::value(
                label(i),
                ChangeKind::Changed,
                show(a),
                show(b),
            )),
            (Some(a), None) => out.push(Change::removed(label(i), show(a))),
            (None, Some(b)) => out.push(Change::added(label(i), show(b))),
            _ => {}
        }
    }
}

fn acquire_str(a: &Acquire) -> String {
    format!(
        "{} at {} Hz ({})",
        fmt_s(a.duration_s),
        fmt_num(a.rate_hz),
        a.channels.join(", ")
    )
}

/// One field's change for one anchored item (settle or acquisition).
struct FieldChange {
    anchor: String,
    field: String,
    kind: ChangeKind,
    old: String,
    new: String,
}

/// Reports field changes once when they hold for every paired item, else per item.
fn collapse(
    prefix: &str,
    item: impl Fn(&str) -> String,
    paired: usize,
    changes: Vec<FieldChange>,
    out: &mut Vec<Change>,
) {
    let mut done = vec![false; changes.len()];
    for i in 0..changes.len() {
        if done[i] {
            continue;
        }
        let c = &changes[i];
        let same_change: Vec<usize> = (i..changes.len())
            .filter(|&j| {
                let d = &changes[j];
                !done[j]
                    && d.field == c.field
                    && d.kind == c.kind
                    && d.old == c.old
                    && d.new == c.new
            })
            .collect();
        if same_change.len() == paired {
            out.push(Change::value(
                format!("{prefix} / {}", c.field),
                c.kind,
                c.old.clone(),
                c.new.clone(),
            ));
            same_change.iter().for_each(|&j| done[j] = true);
        } else {
            out.push(Change::value(
                format!("{} / {}", item(&c.anchor), c.field),
                c.kind,
                c.old.clone(),
                c.new.clone(),
            ));
            done[i] = true;
        }
    }
}

/// Acquisitions that went out and came in alike but for their segment's name, in order:
/// what an edited rate or attitude list renames. `None` when any differs in more.
fn renamed(pairs: &[Pair<'_, &Acquire>]) -> Option<(Vec<String>, Vec<String>)> {
    let gone: Vec<&Acquire> = (pairs.iter())
        .filter_map(|p| {
            if let Pair::Old(a) = p {
                Some(**a)
            } else {
                None
            }
        })
        .collect();
    let came: Vec<&Acquire> = (pairs.iter())
        .filter_map(|p| {
            if let Pair::New(a) = p {
                Some(**a)
            } else {
                None
            }
        })
        .collect();
    let alike = gone.len() == came.len()
        && gone.len() > 1
        && gone
            .iter()
            .zip(&came)
            .all(|(o, n)| acquire_str(o) == acquire_str(n));
    let names = |v: &[&Acquire]| v.iter().map(|a| a.segment.clone()).collect();
    alike.then(|| (names(&gone), names(&came)))
}

fn acquires(path: &str, old: &[&Acquire], new: &[&Acquire], out: &mut Vec<Change>) {
    let mut changes = Vec::new();
    let mut paired = 0;
    let pairs = pair(old, new, |a| a.segment.clone());
    let renamed = renamed(&pairs);
    if let Some((gone, came)) = &renamed {
        out.push(Change::value(
            format!("{path} / acquisitions renamed"),
            ChangeKind::Changed,
            gone.join(", "),
            came.join(", "),
        ));
    }
    for p in pairs {
        if renamed.is_some() && !matches!(p, Pair::Both(..)) {
            continue;
        }
        match p {
            Pair::Old(a) => out.push(Change::removed(
                format!("{path} / acquire {}", a.segment),
                acquire_str(a),
            )),
            Pair::New(a) => out.push(Change::added(
                format!("{path} / acquire {}", a.segment),
                acquire_str(a),
            )),
            Pair::Both(_, o, _, n) => {
                paired += 1;
                let mut f = |field: &str, kind: Option<ChangeKind>, old: String, new: String| {
                    if let Some(kind) = kind {
                        changes.push(FieldChange {
                            anchor: n.segment.clone(),
                            field: field.into(),
                            kind,
                            old,
                            new,
                        });
                    }
                };
                f(
                    "duration",
                    direction::plain(o.duration_s, n.duration_s),
                    fmt_s(o.duration_s),
                    fmt_s(n.duration_s),
                );
                let hz = |v: f64| format!("{} Hz", fmt_num(v));
                f(
                    "sample rate",
                    direction::plain(o.rate_hz, n.rate_hz),
                    hz(o.rate_hz),
                    hz(n.rate_hz),
                );
                let ch_kind = (o.channels != n.channels).then_some(ChangeKind::Changed);
                f(
                    "channels",
                    ch_kind,
                    o.channels.join(", "),
                    n.channels.join(", "),
                );
            }
        }
    }
    collapse(
        &format!("{path} / acquire"),
        |a| format!("{path} / acquire {a}"),
        paired,
        changes,
        out,
    );
}

fn settle_str(s: &Settle) -> String {
    let mut parts = vec![format!("at least {}", fmt_s(s.min_time_s))];
    for st in &s.stable {
        parts.push(format!(
            "fluctuation {} over {}",
            fmt_internal(signal_dim(st.signal), st.max_fluctuation),
            fmt_s(st.window_s)
        ));
    }
    parts.join("; ")
}

fn settles(
    path: &str,
    old: &[(String, &Settle)],
    new: &[(String, &Settle)],
    out: &mut Vec<Change>,
) {
    let acquired_in_both =
        |a: &str| old.iter().any(|(o, _)| o == a) && new.iter().any(|(n, _)| n == a);
    let mut changes = Vec::new();
    let mut paired = 0;
    for p in pair(old, new, |(anchor, _)| anchor.clone()) {
        match p {
            // A settle that comes or goes with its acquisition is part of that change.
            Pair::Old((a, s)) if acquired_in_both(a) => out.push(
                Change::removed(format!("{path} / settle before {a}"), settle_str(s)).alerting(),
            ),
            Pair::New((a, s)) if acquired_in_both(a) => out.push(Change::added(
                format!("{path} / settle before {a}"),
                settle_str(s),
            )),
            Pair::Old(_) | Pair::New(_) => {}
            Pair::Both(_, (_, o), _, (anchor, n)) => {
                paired += 1;
                settle_fields(anchor, o, n, &mut changes);
            }
        }
    }
    collapse(
        &format!("{path} / settle"),
        |a| format!("{path} / settle before {a}"),
        paired,
        changes,
        out,
    );
}

fn settle_fields(anchor: &str, o: &Settle, n: &Settle, changes: &mut Vec<FieldChange>) {
    let mut f = |field: String, kind: Option<ChangeKind>, old: String, new: String| {
        if let Some(kind) = kind {
            changes.push(FieldChange {
                anchor: anchor.to_string(),
                field,
                kind,
                old,
                new,
            });
        }
    };
    f(
        "min time".into(),
        direction::lower(o.min_time_s, n.min_time_s),
        fmt_s(o.min_time_s),
        fmt_s(n.min_time_s),
    );
    let single = o.stable.len() <= 1 && n.stable.len() <= 1;
    for p in pair(&o.stable, &n.stable, |s| s.signal) {
        let show = |s: &ratecal_plan::Stability| {
            format!(
                "{} over {}",
                fmt_internal(signal_dim(s.signal), s.max_fluctuation),
                fmt_s(s.window_s)
            )
        };
        let name = |s: &ratecal_plan::Stability| {
            let sig = serde_json::to_value(s.signal)
                .ok()
                .and_then(|v| v.as_str().map(str::to_string))
                .unwrap_or_default();
            if single {
                "fluctuation".to_string()
            } else {
                format!("fluctuation {sig}")
            }
        };
        match p {
            Pair::Old(s) => f(name(s), Some(ChangeKind::Loosened), show(s), "none".into()),
            Pair::New(s) => f(name(s), Some(ChangeKind::Tightened), "none".into(), show(s)),
            Pair::Both(_, a, _, b) => {
                let k = direction::combine([
                    direction::upper(a.max_fluctuation, b.max_fluctuation),
                    direction::lower(a.window_s, b.window_s),
                ]);
                f(name(b), k, show(a), show(b));
            }
        }
    }
    let opt = |v: Option<f64>, d: Dim| v.map_or("none".to_string(), |v| fmt_internal(d, v));
    let k = direction::optional_upper(o.attitude_error_deg, n.attitude_error_deg);
    f(
        "attitude error".into(),
        k,
        opt(o.attitude_error_deg, Dim::Angle),
        opt(n.attitude_error_deg, Dim::Angle),
    );
    let k = direction::optional_upper(o.rate_error_dps, n.rate_error_dps);
    f(
        "rate error".into(),
        k,
        opt(o.rate_error_dps, Dim::Rate),
        opt(n.rate_error_dps, Dim::Rate),
    );
    let k = match (o.timeout_s, n.timeout_s) {
        (Some(a), Some(b)) => direction::plain(a, b),
        (a, b) => (a.is_some() != b.is_some()).then_some(ChangeKind::Changed),
    };
    f(
        "timeout".into(),
        k,
        opt(o.timeout_s, Dim::Time),
        opt(n.timeout_s, Dim::Time),
    );
    let t = |t: ratecal_plan::OnTimeout| {
        serde_json::to_value(t)
            .ok()
            .and_then(|v| v.as_str().map(str::to_string))
            .unwrap_or_default()
    };
    f(
        "on timeout".into(),
        direction::on_timeout(o.on_timeout, n.on_timeout),
        t(o.on_timeout),
        t(n.on_timeout),
    );
}
