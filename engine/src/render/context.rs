//! Builds the data model templates see (documented field by field in
//! `docs/report-templates.md`) from results.json, the manifest and the plan. Every section
//! is tolerant: a recording from another system has no `run` or `procedure`, an older
//! results.json may lack residuals or Allan curves; the context then holds `null` or `[]`
//! and the templates say "not recorded".

use super::ReportInput;
use super::process;
use serde_json::{Map, Value, json};

/// Format tag of the context, for templates that want to check what they are given.
pub const CONTEXT_FORMAT: &str = "ratecal-report/1";

/// The context as JSON (plots are added by the caller as safe strings).
pub fn build(input: &ReportInput) -> Value {
    let manifest = input.manifest.as_ref().and_then(Value::as_object);
    let get = |k: &str| {
        manifest
            .and_then(|m| m.get(k))
            .cloned()
            .unwrap_or(Value::Null)
    };
    let run = get("run");
    let results = &input.results;
    let parameters = parameters(results);
    let acceptance = list(results, "acceptance");
    let verification = list(results, "verification");
    let repeatability = results.get("repeatability").cloned().unwrap_or(Value::Null);
    let summary = summary(&acceptance, &verification, &repeatability, &parameters);
    let imu_temp = stats(&input.temperature.imu);
    let ambient = stats(&input.temperature.ambient);
    let env = get("environment");
    let recorded = env
        .as_object()
        .is_some_and(|e| e.values().any(|v| !v.is_null()));

    let procedure = match get("procedure") {
        Value::Null => input.plan.as_ref().map_or(
            Value::Null,
            |p| json!({ "name": p.name, "version": p.version, "sha256": null }),
        ),
        p => p,
    };
    let traceability = json!({
        "procedure_name": procedure.get("name"),
        "procedure_version": procedure.get("version"),
        "procedure_sha256": procedure.get("sha256"),
        "station_sha256": run.get("station_sha256"),
        "ratecal_version": input.ratecal_version,
        "run_ratecal_version": run.get("ratecal_version"),
        "run_id": run.get("id"),
        "started": run.get("started"),
        "ended": run.get("ended"),
        "status": run.get("status"),
        "operator": run.get("operator"),
        "seed": run.get("seed"),
        "files_sha256": run.get("files_sha256").and_then(Value::as_object).map(|m| {
            m.iter().map(|(f, h)| json!({ "file": f, "sha256": h })).collect::<Vec<_>>()
        }).unwrap_or_default(),
        "results_format": results.get("format"),
    });
    let interval = input.plan.as_ref().and_then(|p| {
        p.meta
            .get("recalibration_interval")
            .or_else(|| p.meta.get("recalibration"))
    });
    let temp_model = results.get("temperature_model").filter(|v| !v.is_null());

    json!({
        "report": { "format": CONTEXT_FORMAT, "ratecal_version": input.ratecal_version },
        "dry_run": run.get("dry_run").and_then(Value::as_bool).unwrap_or(false),
        "run": run,
        "procedure": procedure,
        "traceability": traceability,
        "imu": get("imu"),
        "station": get("station"),
        "environment": {
            "recorded": recorded,
            "temperature_c": env.get("temperature_c"),
            "humidity_pct": env.get("humidity_pct"),
            "pressure_kpa": env.get("pressure_kpa"),
            "vibration_g": env.get("vibration_g"),
            "ambient": ambient,
            "imu_temperature": imu_temp,
        },
        "process": process::describe(manifest, input.plan.as_ref()),
        "plan": input.plan.as_ref().map(|p| serde_json::to_value(p).unwrap_or(Value::Null)),
        "results": results,
        "parameters": parameters,
        "calibration": calibration_rows(results),
        "other_parameters": other_parameters(results),
        "acceptance": acceptance,
        "verification": verification,
        "repeatability": repeatability,
        "residuals": list(results, "residuals"),
        "residual_table": residual_table(results),
        "allan": results.get("allan").cloned().unwrap_or(Value::Null),
        "warnings": list(results, "warnings"),
        "findings": list(results, "findings"),
        "summary": summary,
        "recommendations": {
            "temperature_span_c": imu_temp.get("span"),
            "temperature_compensation": temp_model.is_some(),
            "temperature_model": temp_model,
            "recalibration_interval": interval,
        },
    })
}

fn list(v: &Value, key: &str) -> Value {
    match v.get(key) {
        Some(Value::Array(a)) => Value::Array(a.clone()),
        _ => Value::Array(vec![]),
    }
}

/// Splits `accel.bias.x` into sensor, kind and axis (`accel.misalignment.xy`: axis `xy`).
fn split_name(name: &str) -> (String, String, String) {
    let mut it = name.splitn(3, '.');
    let a = it.next().unwrap_or_default().to_string();
    let b = it.next().unwrap_or_default().to_string();
    let c = it.next().unwrap_or_default().to_string();
    (a, b, c)
}

fn param_entry(name: &str, p: &Value) -> Value {
    let (sensor, kind, axis) = split_name(name);
    let observable = p.get("observable").and_then(Value::as_bool).unwrap_or(true)
        && p.get("value").is_some_and(|v| !v.is_null());
    let mut m = p.as_object().cloned().unwrap_or_default();
    m.insert("name".into(), json!(name));
    m.insert("sensor".into(), json!(sensor));
    m.insert("kind".into(), json!(kind));
    m.insert("axis".into(), json!(axis));
    m.insert("observable".into(), json!(observable));
    Value::Object(m)
}

fn parameters(results: &Value) -> Value {
    let Some(ps) = results.get("parameters").and_then(Value::as_object) else {
        return json!([]);
    };
    Value::Array(ps.iter().map(|(n, p)| param_entry(n, p)).collect())
}

/// One row per sensor and axis: `{sensor, axis, bias, scale}` (each a parameter entry).
fn calibration_rows(results: &Value) -> Value {
    let ps = results.get("parameters").and_then(Value::as_object);
    let mut rows = vec![];
    for sensor in ["accel", "gyro"] {
        for axis in ["x", "y", "z"] {
            let entry = |kind: &str| {
                let name = format!("{sensor}.{kind}.{axis}");
                let p = ps.and_then(|m| m.get(&name)).cloned();
                param_entry(&name, &p.unwrap_or(json!({ "observable": false })))
            };
            rows.push(json!({ "sensor": sensor, "axis": axis, "bias": entry("bias"), "scale": entry("scale") }));
        }
    }
    Value::Array(rows)
}

/// Parameters other than the per-axis bias and scale (misalignments, lever arms...).
fn other_parameters(results: &Value) -> Value {
    let Some(ps) = results.get("parameters").and_then(Value::as_object) else {
        return json!([]);
    };
    let main = |n: &str| {
        let (s, k, a) = split_name(n);
        matches!(s.as_str(), "accel" | "gyro")
            && matches!(k.as_str(), "bias" | "scale")
            && matches!(a.as_str(), "x" | "y" | "z")
    };
    Value::Array(
        ps.iter()
            .filter(|(n, _)| !main(n))
            .map(|(n, p)| param_entry(n, p))
            .collect(),
    )
}

/// Worst verdict over acceptance checks, verification points and repeatability parameters.
fn summary(acceptance: &Value, verification: &Value, repeat: &Value, params: &Value) -> Value {
    let mut counts = Map::new();
    let mut by: [Vec<Value>; 3] = Default::default(); // fail, indeterminate, not evaluated
    let empty = vec![];
    let rep = repeat
        .get("parameters")
        .and_then(Value::as_array)
        .unwrap_or(&empty);
    let all = acceptance
        .as_array()
        .unwrap_or(&empty)
        .iter()
        .map(|c| (c, "acceptance"));
    let all = all
        .chain(
            verification
                .as_array()
                .unwrap_or(&empty)
                .iter()
                .map(|c| (c, "verification")),
        )
        .chain(rep.iter().map(|c| (c, "repeatability")));
    for (check, source) in all {
        let verdict = check
            .get("verdict")
            .and_then(Value::as_str)
            .unwrap_or("not_evaluated");
        let n = counts.entry(verdict.to_string()).or_insert(json!(0));
        *n = json!(n.as_u64().unwrap_or(0) + 1);
        let name = check
            .get("name")
            .or_else(|| check.get("quantity"))
            .cloned()
            .unwrap_or(Value::Null);
        let item = json!({ "name": name, "source": source, "check": check });
        match verdict {
            "fail" => by[0].push(item),
            "indeterminate" => by[1].push(item),
            "pass" => {}
            _ => by[2].push(item),
        }
    }
    let passed = counts.get("pass").is_some();
    let verdict = if !by[0].is_empty() {
        "fail"
    } else if !by[1].is_empty() {
        "indeterminate"
    } else if passed {
        "pass"
    } else {
        "not_evaluated"
    };
    let unobservable: Vec<Value> = params
        .as_array()
        .unwrap_or(&empty)
        .iter()
        .filter(|p| p.get("observable") == Some(&json!(false)))
        .filter_map(|p| p.get("name").cloned())
        .collect();
    let [failed, indeterminate, not_evaluated] = by;
    json!({
        "verdict": verdict,
        "meets_standard": verdict == "pass",
        "counts": counts,
        "failed": failed,
        "indeterminate": indeterminate,
        "not_evaluated": not_evaluated,
        "unobservable": unobservable,
    })
}

/// Residual rows grouped by segment, in the order segments first appear:
/// `[{segment, channels: {ax: row, ...}}]`. Accepts a list of rows
/// (`{segment, channel, mean, std, ...}`) or an object `{segment: {channel: {...}}}`.
fn residual_table(results: &Value) -> Value {
    let mut out: Vec<(String, Map<String, Value>)> = vec![];
    let mut add = |seg: &str, ch: &str, row: &Value| {
        let i = match out.iter().position(|(s, _)| s == seg) {
            Some(i) => i,
            None => {
                out.push((seg.to_string(), Map::new()));
                out.len() - 1
            }
        };
        out[i].1.insert(ch.to_string(), row.clone());
    };
    match results.get("residuals") {
        Some(Value::Array(rows)) => {
            for row in rows {
                let s = row.get("segment").and_then(Value::as_str);
                let c = row.get("channel").and_then(Value::as_str);
                if let (Some(s), Some(c)) = (s, c) {
                    add(s, c, row);
                }
            }
        }
        Some(Value::Object(segs)) => {
            for (s, chans) in segs {
                for (c, row) in chans.as_object().into_iter().flatten() {
                    add(s, c, row);
                }
            }
        }
        _ => {}
    }
    Value::Array(
        out.into_iter()
            .map(|(s, c)| json!({ "segment": s, "channels": c }))
            .collect(),
    )
}

/// Min, max, mean and span of a time series' values, or null when empty.
fn stats(series: &[(f64, f64)]) -> Value {
    let vals: Vec<f64> = series
        .iter()
        .map(|p| p.1)
        .filter(|v| v.is_finite())
        .collect();
    if vals.is_empty() {
        return Value::Null;
    }
    let min = vals.iter().copied().fold(f64::INFINITY, f64::min);
    let max = vals.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let mean = vals.iter().sum::<f64>() / vals.len() as f64;
    let t0 = series.first().map_or(0.0, |p| p.0);
    let t1 = series.last().map_or(0.0, |p| p.0);
    json!({ "min": min, "max": max, "mean": mean, "span": max - min, "duration_s": t1 - t0 })
}
