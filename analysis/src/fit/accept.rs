//! Accuracy verification at segments no fit used, and evaluation of the procedure's
//! thresholds: value, limit, margin, expanded uncertainty, decision rule. A calibrated
//! parameter, or a function of several, is judged with its full budget's `U` and `k`
//! (results.json `budgets`, when the station states its Type B figures); anything else
//! with the run's Type A uncertainty at k = 2.

use super::Out;
use super::segment::{ChannelStats, Summary};
use super::select::Selection;
use crate::plan::{Accept, Cmp, DecisionRule, Plan, Quantity, VerifyPoint};
use crate::recording::{Manifest, SegmentKind};
use crate::results::{Acceptance, Results, Verdict, VerificationPoint};
use ratecal_physics::{Mat3, Vec3};

/// The coverage factor of a value with no budget (the run's Type A uncertainty).
const K_TYPE_A: f64 = 2.0;
use std::collections::{BTreeMap, HashMap};

/// Where a verification segment was: mean feedback angles (deg) or axis and nominal rate.
#[derive(Debug, Clone)]
pub(crate) enum Where {
    /// Static, at (outer, inner) deg.
    Attitude(f64, f64),
    /// Rate segment: axis name and nominal rate, deg/s.
    Rate(String, f64),
}

/// Compensated output against the reference at every segment no fit used.
pub(crate) fn verify(
    sel: &Selection,
    sums: &[Summary],
    out: &Out,
    m: &Manifest,
) -> (Vec<VerificationPoint>, HashMap<String, Where>) {
    let mut pts = Vec::new();
    let mut wh = HashMap::new();
    for i in &sel.unused {
        let Some(s) = sums.iter().find(|s| s.seg == *i && s.prepared) else {
            continue;
        };
        let seg = &m.segments[*i];
        let w = match (seg.kind, &seg.axis, seg.rate_dps) {
            (SegmentKind::Rate, Some(ax), Some(r)) => Where::Rate(ax.clone(), r),
            _ => {
                let (outer, inner) = s.mean_angles_deg();
                Where::Attitude(outer, inner)
            }
        };
        wh.insert(seg.id.clone(), w);
        if seg.kind == SegmentKind::Static
            && let Some(model) = &out.accel_model
        {
            pts.push(point(&seg.id, "accel", model, &s.channels[..3], "m/s^2"));
        }
        if let Some(model) = &out.gyro_model {
            pts.push(point(&seg.id, "gyro", model, &s.channels[3..], "deg/s"));
        }
    }
    (pts, wh)
}

/// The error of one sensor's compensated mean output against the mean reference.
fn point(
    id: &str,
    sensor: &str,
    model: &(Mat3, Vec3),
    ch: &[ChannelStats],
    unit: &str,
) -> VerificationPoint {
    let (k, b) = model;
    let n = |i: usize| ch[i].n.max(1) as f64;
    let om = Vec3::from_fn(|i, _| ch[i].sum_out / n(i));
    let rm = Vec3::from_fn(|i, _| ch[i].sum_ref / n(i));
    let comp = k.try_inverse().unwrap_or(Mat3::identity()) * (om - b);
    let err = comp - rm;
    let u = Vec3::from_fn(|i, _| ch[i].std_d() * (ch[i].inflation.factor() / n(i)).sqrt());
    let imax = (0..3)
        .max_by(|&a, &b| err[a].abs().total_cmp(&err[b].abs()))
        .unwrap_or(0);
    VerificationPoint {
        segment: id.to_string(),
        sensor: sensor.into(),
        max_error: err[imax].abs(),
        error: [err[0], err[1], err[2]],
        u: u[imax],
        unit: unit.into(),
    }
}

/// Evaluates every threshold of the procedure (procedure level, steps, verification points,
/// environment).
pub(crate) fn evaluate(
    plan: Option<&Plan>,
    res: &Results,
    q: &BTreeMap<String, (f64, f64)>,
    wh: &HashMap<String, Where>,
    warnings: &mut Vec<String>,
) -> Vec<Acceptance> {
    let Some(plan) = plan else { return Vec::new() };
    let mut out = Vec::new();
    for a in &plan.accepts {
        // A check over several runs is decided by the analysis of those runs, not one.
        if let Some(n) = a.over_runs {
            out.push(deferred(a, n));
            continue;
        }
        let measured = lookup(&a.quantity, a.within, res, q);
        out.push(match measured {
            Ok((v, u, k)) => judge(a, v, u, k, None),
            Err(why) => not_evaluated(a, &why),
        });
    }
    for v in &plan.verifications {
        for lim in &v.limits {
            let sensor = lim.quantity.split('.').next().unwrap_or("");
            let found = res
                .verification
                .iter()
                .filter(|p| p.sensor == sensor)
                .find(|p| {
                    // The procedure may name the segments that record the point.
                    if v.segments.is_empty() {
                        wh.get(&p.segment)
                            .is_some_and(|w| matches_point(&v.point, w))
                    } else {
                        v.segments
                            .iter()
                            .any(|pat| crate::plan::segment_matches(pat, &p.segment))
                    }
                });
            let where_ = match v.point {
                VerifyPoint::Attitude {
                    outer_deg,
                    inner_deg,
                } => format!("at outer {outer_deg} deg, inner {inner_deg} deg"),
                VerifyPoint::Rate { axis, rate_dps } => {
                    format!(
                        "at {rate_dps} deg/s about the {} axis",
                        format!("{axis:?}").to_lowercase()
                    )
                }
            };
            out.push(match found {
                Some(p) => judge(
                    lim,
                    p.max_error,
                    p.u,
                    K_TYPE_A,
                    Some(format!(
                        "{} ({where_}, segment {})",
                        lim_name(lim),
                        p.segment
                    )),
                ),
                None => {
                    let mut a = not_evaluated(
                        lim,
                        &format!("no segment of the recording {where_} outside the fits"),
                    );
                    a.name = format!("{} ({where_})", lim_name(lim));
                    a
                }
            });
        }
    }
    for c in &plan.environment {
        let value = env_value(&c.name, res);
        for (q, op) in [(&c.min, Cmp::Ge), (&c.max, Cmp::Le)] {
            let Some(q) = q else { continue };
            let a = Accept {
                step: None,
                quantity: format!("environment.{}", c.name),
                op,
                limit: q.clone(),
                over_runs: None,
                rule: DecisionRule::Simple,
                within: false,
            };
            out.push(match value {
                Some(v) => judge(&a, v, 0.0, K_TYPE_A, None),
                None => not_evaluated(&a, "the recording holds no lab conditions (no environment block, no ambient column)"),
            });
        }
    }
    if out.iter().any(|a| a.verdict == Verdict::NotEvaluated) {
        warnings.push("some acceptance checks could not be evaluated (see their reasons)".into());
    }
    out
}

/// Whether a segment is at a verification point: within 0.5 deg of the attitude
/// (angles modulo 360), or about the same axis at the same nominal rate.
fn matches_point(p: &VerifyPoint, w: &Where) -> bool {
    let close = |a: f64, b: f64| ((a - b + 180.0).rem_euclid(360.0) - 180.0).abs() <= 0.5;
    match (p, w) {
        (
            VerifyPoint::Attitude {
                outer_deg,
                inner_deg,
            },
            Where::Attitude(o, i),
        ) => close(*outer_deg, *o) && close(*inner_deg, *i),
        (VerifyPoint::Rate { axis, rate_dps }, Where::Rate(a, r)) => {
            let name = serde_json::to_value(axis)
                .ok()
                .and_then(|v| v.as_str().map(String::from))
                .unwrap_or_default();
            name == *a && (rate_dps - r).abs() <= 1e-6 * rate_dps.abs().max(1.0)
        }
        _ => false,
    }
}

fn env_value(name: &str, res: &Results) -> Option<f64> {
    let rec = res.environment.recorded.as_ref();
    let amb = res.environment.ambient.as_ref();
    match name {
        "temperature" => rec.and_then(|r| r.temperature_c).or(amb.map(|a| a.mean_c)),
        "temperature_drift" | "drift" => amb.map(|a| a.drift_c_per_h.abs()),
        "humidity" => rec.and_then(|r| r.humidity_pct).map(|v| v / 100.0),
        "pressure" => rec.and_then(|r| r.pressure_kpa),
        "vibration" => rec
            .and_then(|r| r.vibration_g)
            .map(|v| v * ratecal_physics::STANDARD_GRAVITY),
        _ => None,
    }
}

/// Value, standard uncertainty and coverage factor of a checked quantity, internal units.
fn lookup(
    name: &str,
    within: bool,
    res: &Results,
    q: &BTreeMap<String, (f64, f64)>,
) -> Result<(f64, f64, f64), String> {
    if let Some((v, u)) = q.get(name) {
        return Ok((*v, *u, K_TYPE_A));
    }
    let (func, arg) = crate::plan::derived::split(name);
    if let Ok(d) = crate::plan::derived::derived(func, arg) {
        return parameters(&d, res).map(|(v, u, k)| match (func, within) {
            // A bare parameter is judged by its magnitude (docs/language.md); `within`
            // keeps the sign for the report and judges the magnitude itself.
            (None, false) => (v.abs(), u, k),
            _ => (v, u, k),
        });
    }
    match name {
        "repeatability.cv" => Err("repeatability needs several complete runs (`ratecal analyze RUN1 RUN2 RUN3 --procedure PROCEDURE`); one was given".into()),
        "accel.error" | "gyro.error" => {
            let sensor = &name[..name.find('.').unwrap_or(0)];
            res.verification
                .iter()
                .filter(|p| p.sensor == sensor)
                .max_by(|a, b| a.max_error.total_cmp(&b.max_error))
                .map(|p| (p.max_error, p.u, K_TYPE_A))
                .ok_or_else(|| "no segment outside the fits to verify at".into())
        }
        "sync.error" => Ok((res.sync.max_sync_error_s, 0.0, K_TYPE_A)),
        _ => Err(format!("`{name}` is not a quantity the analysis computes")),
    }
}

/// Value, standard uncertainty (internal units) and coverage factor of a calibrated
/// parameter or a function of several, propagated through the fit's correlations
/// (`results.fits`): the components' full budgets when results.json has them, else the
/// fit's Type A uncertainties at k = 2.
fn parameters(d: &crate::plan::derived::Derived, res: &Results) -> Result<(f64, f64, f64), String> {
    let mut v = Vec::new();
    let mut u = Vec::new();
    let mut to_bases = Vec::new();
    for name in &d.parameters {
        let Some(p) = res.parameters.get(name) else {
            return Err(format!("the analysis gave no `{name}`"));
        };
        // A calibrated parameter is in its results unit (ppm, mrad); the limit in the
        // language's base unit of its dimension.
        let to_base = p.unit().map_or(1.0, |unit| {
            ratecal_physics::units::parse_quantity(&format!("1 {unit}")).map_or(1.0, |(_, f)| f)
        });
        let Some((pv, pu)) = p.value_u() else {
            return Err(format!("{name} is not observable in this recording"));
        };
        v.push(pv * to_base);
        u.push(pu * to_base);
        to_bases.push(to_base);
    }
    let n = v.len();
    let mut r = vec![0.0; n * n];
    for (i, a) in d.parameters.iter().enumerate() {
        for (j, b) in d.parameters.iter().enumerate() {
            r[i * n + j] = if i == j { 1.0 } else { correlation(res, a, b) };
        }
    }
    let budgets: Option<Vec<(&crate::budget::Budget, f64)>> = d
        .parameters
        .iter()
        .zip(&to_bases)
        .map(|(name, f)| Some((res.budgets.iter().find(|b| &b.quantity == name)?, *f)))
        .collect();
    if let Some(components) = budgets {
        return Ok(crate::budget::derived_budget(d.func, &components, &r));
    }
    let (value, u) = crate::plan::derived::evaluate(d.func, &v, &u, &r);
    Ok((value, u, K_TYPE_A))
}

/// The correlation of two parameters in the joint fit that gave both (0 when none did).
fn correlation(res: &Results, a: &str, b: &str) -> f64 {
    res.fits
        .values()
        .find_map(|f| {
            let i = f.parameters.iter().position(|p| p == a)?;
            let j = f.parameters.iter().position(|p| p == b)?;
            f.correlation.get(i)?.get(j).copied()
        })
        .unwrap_or(0.0)
}

fn lim_name(a: &Accept) -> String {
    if a.within {
        return format!(
            "{} within +-{} {}",
            a.quantity,
            fmt_num(a.limit.written),
            a.limit.unit
        )
        .trim_end()
        .to_string();
    }
    format!(
        "{} {} {} {}",
        a.quantity,
        op_str(a.op),
        fmt_num(a.limit.written),
        a.limit.unit
    )
    .trim_end()
    .to_string()
}

fn op_str(op: Cmp) -> &'static str {
    match op {
        Cmp::Le => "<=",
        Cmp::Lt => "<",
        Cmp::Ge => ">=",
        Cmp::Gt => ">",
    }
}

/// The comparison as results.json writes it: `within` for a two-sided band.
fn op_name(a: &Accept) -> &'static str {
    if a.within { "within" } else { op_str(a.op) }
}

fn fmt_num(v: f64) -> String {
    format!("{v}")
}

/// Internal units per written unit of the limit.
fn factor(q: &Quantity) -> f64 {
    if q.written != 0.0 && q.value != 0.0 {
        q.value / q.written
    } else {
        ratecal_physics::units::unit(&q.unit).map_or(1.0, |u| u.1)
    }
}

/// Applies the decision rule to a value (internal units) with standard uncertainty `u` and
/// coverage factor `k`.
pub(crate) fn judge(a: &Accept, v: f64, u: f64, k: f64, name: Option<String>) -> Acceptance {
    let f = factor(&a.limit);
    let (value, limit, big_u) = (v / f, a.limit.written, k * u / f);
    let upper = matches!(a.op, Cmp::Le | Cmp::Lt);
    // `within +-L` bounds both sides: the margin is to the nearer one.
    let judged = if a.within { value.abs() } else { value };
    let margin = if upper {
        limit - judged
    } else {
        judged - limit
    };
    let meets = |m: f64| match a.op {
        Cmp::Le | Cmp::Ge => m >= 0.0,
        Cmp::Lt | Cmp::Gt => m > 0.0,
    };
    let verdict = match a.rule {
        DecisionRule::Simple => {
            if meets(margin) {
                Verdict::Pass
            } else {
                Verdict::Fail
            }
        }
        DecisionRule::GuardBanded => {
            if meets(margin - big_u) {
                Verdict::Pass
            } else if !meets(margin + big_u) {
                Verdict::Fail
            } else {
                Verdict::Indeterminate
            }
        }
    };
    Acceptance {
        name: name.unwrap_or_else(|| lim_name(a)),
        quantity: a.quantity.clone(),
        step: a.step.clone(),
        value: Some(value),
        op: op_name(a).into(),
        limit,
        unit: a.limit.unit.clone(),
        margin: Some(margin),
        expanded_u: Some(big_u),
        k: Some(k),
        rule: rule_str(a.rule).into(),
        verdict,
        reason: None,
    }
}

fn rule_str(r: DecisionRule) -> &'static str {
    match r {
        DecisionRule::Simple => "simple",
        DecisionRule::GuardBanded => "guard_banded",
    }
}

/// A threshold that could not be evaluated, with why.
pub(crate) fn not_evaluated(a: &Accept, why: &str) -> Acceptance {
    Acceptance {
        name: lim_name(a),
        quantity: a.quantity.clone(),
        step: a.step.clone(),
        value: None,
        op: op_name(a).into(),
        limit: a.limit.written,
        unit: a.limit.unit.clone(),
        margin: None,
        expanded_u: None,
        k: None,
        rule: rule_str(a.rule).into(),
        verdict: Verdict::NotEvaluated,
        reason: Some(why.into()),
    }
}

/// A check declared over `n` runs, left to the analysis of those runs.
fn deferred(a: &Accept, n: u32) -> Acceptance {
    let mut d = not_evaluated(
        a,
        &format!("decided over {n} runs: `ratecal analyze RUN1 ... RUN{n} --procedure PROCEDURE`"),
    );
    d.verdict = Verdict::Deferred;
    d
}
