//! Differences in limits and rules: station requirements, environment bands, abort rules,
//! fits, acceptance thresholds and verification points.

use super::pair::{Pair, pair};
use crate::change::{
    Change, ChangeKind, fmt_internal, fmt_num, fmt_q, fmt_s, signal_dim, signal_name,
};
use crate::direction::{self, op_str};
use ratecal_plan::{
    AbortAction, AbortCondition, AbortRule, Accept, Axis, DecisionRule, EnvCondition, FitSpec,
    Outliers, Requirement, Verification, VerifyPoint,
};

/// Pushes a change of one value when `kind` says it changed.
fn push(out: &mut Vec<Change>, path: String, kind: Option<ChangeKind>, old: String, new: String) {
    if let Some(k) = kind {
        out.push(Change::value(path, k, old, new));
    }
}

pub(super) fn requirements(old: &[Requirement], new: &[Requirement], out: &mut Vec<Change>) {
    let show = |r: &Requirement| format!("{} {}", op_str(r.op), fmt_q(&r.limit));
    for p in pair(old, new, |r| r.name.clone()) {
        match p {
            Pair::Old(r) => {
                out.push(Change::removed(format!("requires {}", r.name), show(r)).alerting())
            }
            Pair::New(r) => out.push(Change::added(format!("requires {}", r.name), show(r))),
            Pair::Both(_, o, _, n) => {
                let k = direction::threshold(o.op, o.limit.value, n.op, n.limit.value);
                push(out, format!("requires {}", n.name), k, show(o), show(n));
            }
        }
    }
}

pub(super) fn environment(old: &[EnvCondition], new: &[EnvCondition], out: &mut Vec<Change>) {
    let show = |e: &EnvCondition| {
        let side = |q: &Option<ratecal_plan::Quantity>| q.as_ref().map_or("-".to_string(), fmt_q);
        format!("{} .. {}", side(&e.min), side(&e.max))
    };
    for p in pair(old, new, |e| e.name.clone()) {
        match p {
            Pair::Old(e) => {
                out.push(Change::removed(format!("environment {}", e.name), show(e)).alerting())
            }
            Pair::New(e) => out.push(Change::added(format!("environment {}", e.name), show(e))),
            Pair::Both(_, o, _, n) => {
                let v = |q: &Option<ratecal_plan::Quantity>| q.as_ref().map(|q| q.value);
                let shown = |q: &Option<ratecal_plan::Quantity>| {
                    q.as_ref().map_or("none".to_string(), fmt_q)
                };
                let path = format!("environment {}", n.name);
                let k = direction::optional_lower(v(&o.min), v(&n.min));
                push(
                    out,
                    format!("{path} / min"),
                    k,
                    shown(&o.min),
                    shown(&n.min),
                );
                let k = direction::optional_upper(v(&o.max), v(&n.max));
                push(
                    out,
                    format!("{path} / max"),
                    k,
                    shown(&o.max),
                    shown(&n.max),
                );
            }
        }
    }
}

/// The label of an abort rule, stable across changes of its limits (`abort when
/// table.attitude_error >`).
fn abort_label(r: &AbortRule) -> String {
    match &r.condition {
        AbortCondition::Above { signal, .. } => format!("abort when {} >", signal_name(*signal)),
        AbortCondition::Outside { signal, .. } => {
            format!("abort when {} outside", signal_name(*signal))
        }
        AbortCondition::Drifts { signal, .. } => {
            format!("abort when {} drifts", signal_name(*signal))
        }
        AbortCondition::ImuAbnormal => "abort when imu abnormal".to_string(),
    }
}

fn action_str(a: AbortAction) -> String {
    match a {
        AbortAction::Abort => "abort".into(),
        AbortAction::Warn => "warn".into(),
    }
}

/// Abort rules of one scope (`prefix` is `""` or `"step gyro_bias / "`): added, removed
/// (an alert), weakened (`Loosened`) or strengthened (`Tightened`), field by field. A
/// larger limit, a wider band, a longer persistence or `abort` turned into `warn` weakens.
pub(super) fn aborts(prefix: &str, old: &[AbortRule], new: &[AbortRule], out: &mut Vec<Change>) {
    for p in pair(old, new, abort_label) {
        match p {
            Pair::Old(r) => out.push(
                Change::removed(format!("{prefix}{}", abort_label(r)), r.text.clone()).alerting(),
            ),
            Pair::New(r) => out.push(Change::added(
                format!("{prefix}{}", abort_label(r)),
                r.text.clone(),
            )),
            Pair::Both(_, o, _, n) => {
                let path = format!("{prefix}{}", abort_label(n));
                match (&o.condition, &n.condition) {
                    (
                        AbortCondition::Above { signal, limit: a },
                        AbortCondition::Above { limit: b, .. },
                    )
                    | (
                        AbortCondition::Drifts { signal, limit: a },
                        AbortCondition::Drifts { limit: b, .. },
                    ) => {
                        let d = signal_dim(*signal);
                        let k = direction::upper(*a, *b);
                        push(
                            out,
                            format!("{path} / limit"),
                            k,
                            fmt_internal(d, *a),
                            fmt_internal(d, *b),
                        );
                    }
                    (
                        AbortCondition::Outside {
                            signal,
                            lo: ol,
                            hi: oh,
                        },
                        AbortCondition::Outside { lo: nl, hi: nh, .. },
                    ) => {
                        let d = signal_dim(*signal);
                        let k = direction::lower(*ol, *nl);
                        push(
                            out,
                            format!("{path} / low"),
                            k,
                            fmt_internal(d, *ol),
                            fmt_internal(d, *nl),
                        );
                        let k = direction::upper(*oh, *nh);
                        push(
                            out,
                            format!("{path} / high"),
                            k,
                            fmt_internal(d, *oh),
                            fmt_internal(d, *nh),
                        );
                    }
                    _ => {}
                }
                let k = direction::upper(o.persistence_s, n.persistence_s);
                push(
                    out,
                    format!("{path} / persistence"),
                    k,
                    fmt_s(o.persistence_s),
                    fmt_s(n.persistence_s),
                );
                let k = direction::abort_action(o.action, n.action);
                push(
                    out,
                    format!("{path} / action"),
                    k,
                    action_str(o.action),
                    action_str(n.action),
                );
            }
        }
    }
}

fn axes_str(axes: &[usize]) -> String {
    axes.iter()
        .map(|a| ["x", "y", "z"].get(*a).copied().unwrap_or("?"))
        .collect::<Vec<_>>()
        .join(", ")
}

fn outliers_str(o: &Option<Outliers>) -> String {
    match o {
        None => "none".into(),
        Some(Outliers::Sigma(k)) => format!("{} sigma", fmt_num(*k)),
        Some(Outliers::Grubbs(a)) => format!("grubbs alpha {}", fmt_num(*a)),
    }
}

fn model_str(f: &FitSpec) -> String {
    serde_json::to_value(&f.model)
        .ok()
        .and_then(|v| v.as_str().map(str::to_string))
        .unwrap_or_default()
}

fn fit_summary(f: &FitSpec) -> String {
    format!(
        "{} from {} (axes {})",
        model_str(f),
        f.segments.join(", "),
        axes_str(&f.axes)
    )
}

/// Fit statements of one step, paired by model.
pub(super) fn fits(step_path: &str, old: &[FitSpec], new: &[FitSpec], out: &mut Vec<Change>) {
    for p in pair(old, new, model_str) {
        match p {
            Pair::Old(f) => out.push(Change::removed(
                format!("{step_path} / fit {}", model_str(f)),
                fit_summary(f),
            )),
            Pair::New(f) => out.push(Change::added(
                format!("{step_path} / fit {}", model_str(f)),
                fit_summary(f),
            )),
            Pair::Both(_, o, _, n) => {
                let path = format!("{step_path} / fit {}", model_str(n));
                let mut field = |name: &str, a: String, b: String| {
                    if a != b {
                        out.push(Change::value(
                            format!("{path} / {name}"),
                            ChangeKind::Changed,
                            a,
                            b,
                        ));
                    }
                };
                field("axes", axes_str(&o.axes), axes_str(&n.axes));
                field("segments", o.segments.join(", "), n.segments.join(", "));
                field(
                    "outliers",
                    outliers_str(&o.outliers),
                    outliers_str(&n.outliers),
                );
                let lp = |l: &Option<(u32, f64)>| {
                    l.map_or("none".to_string(), |(ord, fc)| {
                        format!("order {ord}, {} Hz", fmt_num(fc))
                    })
                };
                field("lowpass", lp(&o.lowpass), lp(&n.lowpass));
                let using = |u: &Option<String>| u.clone().unwrap_or_else(|| "none".into());
                field("using", using(&o.using), using(&n.using));
                let with = |e: &[String]| {
                    if e.is_empty() {
                        "none".to_string()
                    } else {
                        e.join(", ")
                    }
                };
                field("effects", with(&o.effects), with(&n.effects));
            }
        }
    }
}

fn accept_str(a: &Accept) -> String {
    let runs = a
        .over_runs
        .map(|n| format!(" over {n} runs"))
        .unwrap_or_default();
    let rule = if a.rule == DecisionRule::GuardBanded {
        " (guard-banded)"
    } else {
        ""
    };
    if a.within {
        return format!("within +-{}{runs}{rule}", fmt_q(&a.limit));
    }
    format!("{} {}{runs}{rule}", op_str(a.op), fmt_q(&a.limit))
}

/// Acceptance thresholds declared by `step` (`None`: procedure level), paired by quantity.
pub(super) fn accepts(step: Option<&str>, old: &[Accept], new: &[Accept], out: &mut Vec<Change>) {
    let mine = |l: &[Accept]| {
        l.iter()
            .filter(|a| a.step.as_deref() == step)
            .cloned()
            .collect::<Vec<_>>()
    };
    let prefix = step.map(|s| format!("step {s} / ")).unwrap_or_default();
    limit_list(&prefix, &mine(old), &mine(new), out);
}

/// A list of `quantity op limit` checks under a path prefix.
fn limit_list(prefix: &str, old: &[Accept], new: &[Accept], out: &mut Vec<Change>) {
    for p in pair(old, new, |a| a.quantity.clone()) {
        match p {
            Pair::Old(a) => out.push(
                Change::removed(format!("{prefix}accept {}", a.quantity), accept_str(a)).alerting(),
            ),
            Pair::New(a) => out.push(Change::added(
                format!("{prefix}accept {}", a.quantity),
                accept_str(a),
            )),
            Pair::Both(_, o, _, n) => {
                let k = direction::combine([
                    direction::threshold(o.op, o.limit.value, n.op, n.limit.value),
                    direction::decision_rule(o.rule, n.rule),
                    (o.over_runs != n.over_runs).then_some(ChangeKind::Changed),
                    // `<= L` and `within +-L` bound different things (|x| for a parameter
                    // either way, but a derived or signed quantity not).
                    (o.within != n.within).then_some(ChangeKind::Changed),
                ]);
                push(
                    out,
                    format!("{prefix}accept {}", n.quantity),
                    k,
                    accept_str(o),
                    accept_str(n),
                );
            }
        }
    }
}

fn axis_str(a: Axis) -> &'static str {
    match a {
        Axis::Outer => "outer",
        Axis::Inner => "inner",
    }
}

/// A verification point as a path (`verify at pitch 45 deg, roll 30 deg`).
fn point_str(p: &VerifyPoint) -> String {
    match p {
        VerifyPoint::Attitude {
            outer_deg,
            inner_deg,
        } => {
            format!(
                "verify at pitch {} deg, roll {} deg",
                fmt_num(*outer_deg),
                fmt_num(*inner_deg)
            )
        }
        VerifyPoint::Rate { axis, rate_dps } => {
            format!("verify at {} {} deg/s", axis_str(*axis), fmt_num(*rate_dps))
        }
    }
}

pub(super) fn verifications(old: &[Verification], new: &[Verification], out: &mut Vec<Change>) {
    let show = |v: &Verification| {
        v.limits
            .iter()
            .map(|a| format!("{} {}", a.quantity, accept_str(a)))
            .collect::<Vec<_>>()
            .join("; ")
    };
    for p in pair(old, new, |v| point_str(&v.point)) {
        match p {
            Pair::Old(v) => out.push(Change::removed(point_str(&v.point), show(v)).alerting()),
            Pair::New(v) => out.push(Change::added(point_str(&v.point), show(v))),
            Pair::Both(_, o, _, n) => {
                let path = point_str(&n.point);
                if o.segments != n.segments {
                    out.push(Change::value(
                        format!("{path} / from"),
                        ChangeKind::Changed,
                        o.segments.join(", "),
                        n.segments.join(", "),
                    ));
                }
                limit_list(&format!("{path} / "), &o.limits, &n.limits, out)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ratecal_plan::{Cmp, Dim, Quantity, Signal};

    fn q(written: f64, unit: &str, value: f64) -> Quantity {
        Quantity {
            written,
            unit: unit.into(),
            dim: Dim::Accel,
            value,
        }
    }

    #[test]
    fn same_limit_in_another_unit_is_no_change() {
        let a = |w, u: &str, v| Accept {
            step: None,
            quantity: "accel.residual.std".into(),
            op: Cmp::Le,
            limit: q(w, u, v),
            over_runs: None,
            rule: DecisionRule::Simple,
            within: false,
        };
        let mut out = vec![];
        limit_list(
            "",
            &[a(0.002, "g", 0.002 * 9.80665)],
            &[a(2.0, "mg", 2.0 * 9.80665e-3)],
            &mut out,
        );
        assert!(out.is_empty(), "{out:?}");
        limit_list(
            "",
            &[a(0.002, "g", 0.002 * 9.80665)],
            &[a(3.0, "mg", 3.0 * 9.80665e-3)],
            &mut out,
        );
        assert_eq!(out[0].kind, ChangeKind::Loosened);
        assert_eq!(out[0].old.as_deref(), Some("<= 0.002 g"));
        assert_eq!(out[0].new.as_deref(), Some("<= 3 mg"));
    }

    #[test]
    fn longer_persistence_and_warn_weaken_a_rule() {
        let rule = |limit: f64, persistence_s, action| AbortRule {
            text: "t".into(),
            condition: AbortCondition::Above {
                signal: Signal::AttitudeError,
                limit,
            },
            persistence_s,
            action,
            unit: String::new(),
        };
        let mut out = vec![];
        aborts(
            "",
            &[rule(5.0 / 3600.0, 1.0, AbortAction::Abort)],
            &[rule(4.0 / 3600.0, 2.0, AbortAction::Warn)],
            &mut out,
        );
        let kinds: Vec<_> = out.iter().map(|c| (c.path.as_str(), c.kind)).collect();
        assert_eq!(
            kinds,
            vec![
                (
                    "abort when table.attitude_error > / limit",
                    ChangeKind::Tightened
                ),
                (
                    "abort when table.attitude_error > / persistence",
                    ChangeKind::Loosened
                ),
                (
                    "abort when table.attitude_error > / action",
                    ChangeKind::Loosened
                ),
            ]
        );
        assert_eq!(out[0].old.as_deref(), Some("5 arcsec"));
        let mut out = vec![];
        aborts(
            "step s / ",
            &[rule(1.0, 1.0, AbortAction::Abort)],
            &[],
            &mut out,
        );
        assert_eq!(out[0].kind, ChangeKind::Removed);
        assert!(out[0].alert);
    }
}
