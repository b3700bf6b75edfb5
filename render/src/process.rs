//! The "process" section of the context: the attitude and rate-point plan (from the
//! manifest's segments, i.e. what was actually acquired), the acquisition parameters, error
//! models and algorithms (from the plan, when there is one).

use ratecal_plan::{
    Accept, Action, Cmp, DecisionRule, FitModel, Node, Outliers, Plan, Quantity, VerifyPoint,
};
use serde_json::{Map, Value, json};

/// The process description as JSON. Segments come from the manifest (or, without one,
/// from results.json), each with what the analysis did with it (`used_for`,
/// `outliers_removed`, `imu_samples`) when results.json says.
pub fn describe(
    manifest: Option<&Map<String, Value>>,
    plan: Option<&Plan>,
    results: &Value,
) -> Value {
    let empty = vec![];
    let used = results
        .get("segments")
        .and_then(Value::as_array)
        .unwrap_or(&empty);
    let segments: Vec<Value> = manifest
        .and_then(|m| m.get("segments"))
        .and_then(Value::as_array)
        .unwrap_or(used)
        .iter()
        .map(|s| {
            let mut s = with_duration(s);
            let id = s.get("id").cloned();
            if let (Some(m), Some(u)) = (
                s.as_object_mut(),
                used.iter().find(|u| u.get("id") == id.as_ref()),
            ) {
                for k in ["used_for", "outliers_removed", "imu_samples"] {
                    if let Some(v) = u.get(k) {
                        m.entry(k).or_insert(v.clone());
                    }
                }
            }
            s
        })
        .collect();
    let of_kind = |kind: &str| -> Vec<Value> {
        segments
            .iter()
            .filter(|s| s.get("kind").and_then(Value::as_str) == Some(kind))
            .cloned()
            .collect()
    };
    let total: f64 = segments.iter().map(duration).sum();
    let model = results.get("model");
    let mut out = json!({
        "segments": segments,
        "selection": model.and_then(|m| m.get("selection")),
        "applied_fits": model.and_then(|m| m.get("fits")).cloned().unwrap_or(json!([])),
        "static_points": of_kind("static"),
        "rate_points": of_kind("rate"),
        "oscillations": of_kind("oscillation"),
        "total_acquired_s": total,
        "acquisitions": [],
        "sample_rates_hz": [],
        "steps": [],
        "fits": [],
        "requirements": [],
        "environment_conditions": [],
        "planned_checks": [],
        "verification_points": [],
        "estimated_duration_s": null,
    });
    let Some(plan) = plan else { return out };
    let mut acquisitions = vec![];
    for step in &plan.steps {
        walk(&step.name, &step.body, &mut acquisitions);
    }
    let mut rates: Vec<f64> = acquisitions
        .iter()
        .filter_map(|a| a["rate_hz"].as_f64())
        .collect();
    rates.sort_by(f64::total_cmp);
    rates.dedup();
    out["acquisitions"] = json!(acquisitions);
    out["sample_rates_hz"] = json!(rates);
    out["steps"] = json!(
        plan.steps
            .iter()
            .map(|s| json!({
                "name": s.name, "title": s.title, "estimated_duration_s": s.estimated_duration_s
            }))
            .collect::<Vec<_>>()
    );
    out["fits"] = json!(plan.fits.iter().map(|f| {
        let (title, model, algorithm) = model_text(&f.model);
        json!({
            "step": f.step,
            "model": f.model,
            "title": title,
            "error_model": model,
            "algorithm": algorithm,
            "axes": f.axes.iter().map(|a| ["x", "y", "z"].get(*a).copied().unwrap_or("?")).collect::<Vec<_>>(),
            "segments": f.segments,
            "outliers": f.outliers.map(|o| match o {
                Outliers::Sigma(k) => format!("{k}-sigma criterion, per segment"),
                Outliers::Grubbs(a) => format!("Grubbs test at alpha = {a}, per segment"),
            }),
            "lowpass": f.lowpass.map(|(n, fc)| format!(
                "Butterworth low-pass, order {n}, cutoff {fc} Hz, zero-phase")),
            "using": f.using,
        })
    }).collect::<Vec<_>>());
    out["requirements"] = json!(
        plan.requirements
            .iter()
            .map(|r| json!({
                "name": r.name, "op": op(r.op), "limit": quantity(&r.limit)
            }))
            .collect::<Vec<_>>()
    );
    out["environment_conditions"] = json!(
        plan.environment
            .iter()
            .map(|e| json!({
                "name": e.name,
                "min": e.min.as_ref().map(quantity),
                "max": e.max.as_ref().map(quantity),
            }))
            .collect::<Vec<_>>()
    );
    out["planned_checks"] = json!(plan.accepts.iter().map(accept).collect::<Vec<_>>());
    out["verification_points"] = json!(
        plan.verifications
            .iter()
            .map(|v| json!({
                "point": match &v.point {
                    VerifyPoint::Attitude { outer_deg, inner_deg } =>
                        format!("attitude: outer {outer_deg} deg, inner {inner_deg} deg"),
                    VerifyPoint::Rate { axis, rate_dps } =>
                        format!("rate: {rate_dps} deg/s about the {} axis", axis_name(*axis)),
                },
                "limits": v.limits.iter().map(accept).collect::<Vec<_>>(),
            }))
            .collect::<Vec<_>>()
    );
    out["estimated_duration_s"] = json!(plan.estimated_duration_s);
    out
}

fn duration(s: &Value) -> f64 {
    let t = |k| s.get(k).and_then(Value::as_f64);
    match (t("t_start"), t("t_end")) {
        (Some(a), Some(b)) => b - a,
        _ => 0.0,
    }
}

fn with_duration(s: &Value) -> Value {
    let mut s = s.clone();
    if let Some(m) = s.as_object_mut() {
        m.insert(
            "duration_s".into(),
            json!(duration(&Value::Object(m.clone()))),
        );
    }
    s
}

fn walk(step: &str, nodes: &[Node], out: &mut Vec<Value>) {
    for n in nodes {
        match n {
            Node::Do(Action::Acquire(a)) => out.push(json!({
                "step": step, "segment": a.segment, "duration_s": a.duration_s,
                "rate_hz": a.rate_hz, "channels": a.channels,
            })),
            Node::Do(_) => {}
            Node::Repeat { count, body, .. } => {
                let start = out.len();
                walk(step, body, out);
                for a in &mut out[start..] {
                    a["repeat"] = json!(count);
                }
            }
        }
    }
}

fn axis_name(a: ratecal_plan::Axis) -> &'static str {
    match a {
        ratecal_plan::Axis::Outer => "outer",
        ratecal_plan::Axis::Inner => "inner",
    }
}

/// Comparison as printed: `<=` becomes `≤`.
pub fn op(c: Cmp) -> &'static str {
    match c {
        Cmp::Le => "≤",
        Cmp::Lt => "<",
        Cmp::Ge => "≥",
        Cmp::Gt => ">",
    }
}

fn quantity(q: &Quantity) -> Value {
    let text = if q.unit.is_empty() {
        format!("{}", q.written)
    } else {
        format!("{} {}", q.written, q.unit)
    };
    json!({ "text": text, "written": q.written, "unit": q.unit, "value": q.value })
}

fn accept(a: &Accept) -> Value {
    json!({
        "step": a.step,
        "quantity": a.quantity,
        "op": op(a.op),
        "limit": quantity(&a.limit),
        "over_runs": a.over_runs,
        "rule": match a.rule {
            DecisionRule::Simple => "simple acceptance",
            DecisionRule::GuardBanded => "guard-banded (w = U, the budget's k)",
        },
    })
}

/// Title, error model and algorithm of a fit model, as the report prints them.
fn model_text(m: &FitModel) -> (&'static str, &'static str, &'static str) {
    match m {
        FitModel::AccelBiasScale => (
            "Accelerometer bias and scale factor",
            "a_i = K_i (a_ref,i + b_i), i = x, y, z; a_ref from the table's measured attitude",
            "linear least squares per axis over the static attitudes; covariance scaled by the residual variance",
        ),
        FitModel::AccelFull => (
            "Accelerometer full model",
            "a = K_a (a_ref + b_a), K_a a 3x3 matrix (scale factors and misalignments)",
            "linear least squares over the static attitudes; covariance scaled by the residual variance",
        ),
        FitModel::GyroBias => (
            "Gyroscope static bias",
            "w_i = b_i + noise at zero input rate (Earth rate removed through the kinematics)",
            "mean of the static block after outlier removal; noise as the standard deviation",
        ),
        FitModel::GyroScale => (
            "Gyroscope scale factor",
            "w_i = K_i (w_ref,i + b_i), i = x, y; b_i held fixed from the static bias",
            "least squares over the rate points, reference rates from the table feedback",
        ),
        FitModel::GyroFull => (
            "Gyroscope full model",
            "w = K_g (w_ref + b_g), K_g a 3x3 matrix (scale factors and misalignments)",
            "linear least squares over the rate points; covariance scaled by the residual variance",
        ),
        FitModel::TempCompensation => (
            "Temperature compensation",
            "bias and scale as polynomials of the IMU temperature",
            "least squares across the temperature points",
        ),
        FitModel::Allan => (
            "Allan deviation",
            "overlapping Allan deviation of the static block",
            "angle random walk at tau = 1 s, bias instability at the curve's minimum",
        ),
        FitModel::SizeEffect => (
            "Size effect (lever arms)",
            "centripetal and tangential accelerations of each accelerometer's offset from the rotation centre",
            "least squares over the oscillation segments",
        ),
    }
}
