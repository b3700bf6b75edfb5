//! Views of results.json that templates find hard to build themselves: parameters split
//! by sensor, kind and axis; the bias/scale table; residuals grouped by segment; checks
//! with one spelling for the expanded uncertainty; the overall verdict.

use serde_json::{Map, Value, json};

/// `key` for a residual row: `ax` from `{sensor: accel, channel: x}`, else the channel.
pub fn channel_key(row: &Value) -> Option<String> {
    let ch = row.get("channel")?.as_str()?;
    match row.get("sensor").and_then(Value::as_str) {
        Some(s) if ch.len() == 1 => Some(format!("{}{ch}", &s[..1.min(s.len())])),
        _ => Some(ch.to_string()),
    }
}

/// Splits `accel.bias.x` into sensor, kind and axis (`accel.misalignment.xy`: axis `xy`).
fn split_name(name: &str) -> (String, String, String) {
    let mut it = name.splitn(3, '.');
    let mut next = || it.next().unwrap_or_default().to_string();
    (next(), next(), next())
}

fn param_entry(name: &str, p: &Value, observability: Option<&Value>) -> Value {
    let (sensor, kind, axis) = split_name(name);
    let observable = p.get("observable").and_then(Value::as_bool).unwrap_or(true)
        && p.get("value").is_some_and(Value::is_number);
    let mut m = p.as_object().cloned().unwrap_or_default();
    m.insert("name".into(), json!(name));
    m.insert("sensor".into(), json!(sensor));
    m.insert("kind".into(), json!(kind));
    m.insert("axis".into(), json!(axis));
    m.insert("observable".into(), json!(observable));
    if !observable {
        let why = observability.and_then(|o| o.get(name)).cloned();
        m.insert("reason".into(), why.unwrap_or(Value::Null));
    }
    Value::Object(m)
}

fn params(results: &Value) -> Option<&Map<String, Value>> {
    results.get("parameters").and_then(Value::as_object)
}

fn entry(results: &Value, name: &str) -> Value {
    let p = params(results).and_then(|m| m.get(name)).cloned();
    param_entry(
        name,
        &p.unwrap_or(json!({ "observable": false })),
        results.get("observability"),
    )
}

/// Every parameter as an entry `{name, sensor, kind, axis, observable, value, u, unit, reason}`.
pub fn parameters(results: &Value) -> Value {
    let Some(ps) = params(results) else {
        return json!([]);
    };
    let obs = results.get("observability");
    Value::Array(ps.iter().map(|(n, p)| param_entry(n, p, obs)).collect())
}

/// One row per sensor and axis: `{sensor, axis, bias, scale}` (each a parameter entry).
pub fn calibration_rows(results: &Value) -> Value {
    let mut rows = vec![];
    for sensor in ["accel", "gyro"] {
        for axis in ["x", "y", "z"] {
            rows.push(json!({
                "sensor": sensor,
                "axis": axis,
                "bias": entry(results, &format!("{sensor}.bias.{axis}")),
                "scale": entry(results, &format!("{sensor}.scale.{axis}")),
            }));
        }
    }
    Value::Array(rows)
}

const NOISE_KINDS: [&str; 3] = ["noise", "arw", "bias_instability"];

/// Gyro noise per axis: `{axis, noise, arw, bias_instability}`, or `[]` when none is given.
pub fn gyro_noise_rows(results: &Value) -> Value {
    let Some(ps) = params(results) else {
        return json!([]);
    };
    if !ps.keys().any(|n| {
        NOISE_KINDS
            .iter()
            .any(|k| n.starts_with(&format!("gyro.{k}.")))
    }) {
        return json!([]);
    }
    let rows = ["x", "y", "z"].map(|axis| {
        let mut row = json!({ "axis": axis });
        for k in NOISE_KINDS {
            row[k] = entry(results, &format!("gyro.{k}.{axis}"));
        }
        row
    });
    json!(rows)
}

/// Parameters other than bias, scale and gyro noise (misalignments, thermal drifts...).
pub fn other_parameters(results: &Value) -> Value {
    let Some(ps) = params(results) else {
        return json!([]);
    };
    let shown = |n: &str| {
        let (s, k, a) = split_name(n);
        let xyz = matches!(a.as_str(), "x" | "y" | "z");
        let main = matches!(s.as_str(), "accel" | "gyro") && matches!(k.as_str(), "bias" | "scale");
        let noise = s == "gyro" && NOISE_KINDS.contains(&k.as_str());
        xyz && (main || noise)
    };
    let obs = results.get("observability");
    Value::Array(
        ps.iter()
            .filter(|(n, _)| !shown(n))
            .map(|(n, p)| param_entry(n, p, obs))
            .collect(),
    )
}

/// Whether the results carry a temperature model (observable thermal-drift parameters).
pub fn has_temperature_model(results: &Value, parameters: &Value) -> bool {
    results
        .get("temperature_model")
        .is_some_and(|v| !v.is_null())
        || parameters.as_array().into_iter().flatten().any(|p| {
            p.get("kind").and_then(Value::as_str) == Some("thermal_drift")
                && p.get("observable") == Some(&json!(true))
        })
}

/// Acceptance checks with `expanded_u` (from `U`) and `note` (from `reason`) added.
pub fn checks(results: &Value) -> Value {
    let list = results
        .get("acceptance")
        .and_then(Value::as_array)
        .cloned()
        .unwrap_or_default();
    Value::Array(
        list.into_iter()
            .map(|mut c| {
                if let Some(m) = c.as_object_mut() {
                    let u = ["U", "expanded_u", "expanded_uncertainty"]
                        .iter()
                        .find_map(|k| m.get(*k).filter(|v| !v.is_null()).cloned());
                    m.insert("expanded_u".into(), u.unwrap_or(Value::Null));
                    let note = ["reason", "note"].iter().find_map(|k| m.get(*k).cloned());
                    m.insert("note".into(), note.unwrap_or(Value::Null));
                    if m.get("quantity").is_none_or(Value::is_null) {
                        let name = m.get("name").cloned().unwrap_or(Value::Null);
                        m.insert("quantity".into(), name);
                    }
                }
                c
            })
            .collect(),
    )
}

/// Checks whose quantity starts with one of `prefixes` (or ends with `.error`, for `"error"`).
pub fn checks_of(checks: &Value, pred: impl Fn(&str) -> bool) -> Value {
    let list = checks.as_array().into_iter().flatten();
    Value::Array(
        list.filter(|c| c.get("quantity").and_then(Value::as_str).is_some_and(&pred))
            .cloned()
            .collect(),
    )
}

/// Residual rows grouped by segment, in the order segments first appear:
/// `[{segment, channels: {ax: row, ...}}]`. Accepts a list of rows
/// (`{segment, sensor, channel, mean, std, ...}`) or an object `{segment: {channel: {...}}}`.
pub fn residual_table(results: &Value) -> Value {
    let mut out: Vec<(String, Map<String, Value>)> = vec![];
    let mut add = |seg: &str, ch: String, row: &Value| {
        let i = match out.iter().position(|(s, _)| s == seg) {
            Some(i) => i,
            None => {
                out.push((seg.to_string(), Map::new()));
                out.len() - 1
            }
        };
        out[i].1.insert(ch, row.clone());
    };
    match results.get("residuals") {
        Some(Value::Array(rows)) => {
            for row in rows {
                let s = row.get("segment").and_then(Value::as_str);
                if let (Some(s), Some(k)) = (s, channel_key(row)) {
                    add(s, k, row);
                }
            }
        }
        Some(Value::Object(segs)) => {
            for (s, chans) in segs {
                for (c, row) in chans.as_object().into_iter().flatten() {
                    add(s, c.clone(), row);
                }
            }
        }
        _ => {}
    }
    let rows = out
        .into_iter()
        .map(|(s, c)| json!({ "segment": s, "channels": c }));
    Value::Array(rows.collect())
}

/// The run's verdict (results.json `verdict`; for an older results file without one, the
/// worst over the checks, `incomplete` when one was not decided) and the checks by outcome.
pub fn summary(checks: &Value, results: &Value, params: &Value) -> Value {
    let mut counts = Map::new();
    let mut by: [Vec<Value>; 4] = Default::default(); // fail, indeterminate, not evaluated, deferred
    let empty = vec![];
    let arr = |v: Option<&Value>| v.and_then(Value::as_array).unwrap_or(&empty).clone();
    let with_verdict = |v: &Value| v.get("verdict").is_some_and(Value::is_string);
    let extra = arr(results.get("verification"))
        .into_iter()
        .filter(with_verdict)
        .map(|c| (c, "verification"))
        .chain(
            arr(results
                .get("repeatability")
                .and_then(|r| r.get("parameters")))
            .into_iter()
            .filter(with_verdict)
            .map(|c| (c, "repeatability")),
        );
    let all = arr(Some(checks))
        .into_iter()
        .map(|c| (c, "acceptance"))
        .chain(extra);
    for (check, source) in all {
        let verdict = check
            .get("verdict")
            .and_then(Value::as_str)
            .unwrap_or("not_evaluated");
        let n = counts.entry(verdict.to_string()).or_insert(json!(0));
        *n = json!(n.as_u64().unwrap_or(0) + 1);
        let name = check.get("name").or_else(|| check.get("quantity")).cloned();
        let item = json!({ "name": name, "source": source, "check": check });
        match verdict {
            "fail" => by[0].push(item),
            "indeterminate" => by[1].push(item),
            "pass" => {}
            "deferred" => by[3].push(item),
            _ => by[2].push(item),
        }
    }
    let recorded = results.get("verdict").and_then(Value::as_str);
    let verdict = match recorded {
        Some(v) => v,
        None if !by[0].is_empty() => "fail",
        None if !by[1].is_empty() || !by[2].is_empty() => "incomplete",
        None if counts.contains_key("pass") => "pass",
        None => "incomplete",
    };
    let unobservable: Vec<Value> = arr(Some(params))
        .into_iter()
        .filter(|p| p.get("observable") == Some(&json!(false)))
        // A value bounded from above is shown as its bound where it stands.
        .filter(|p| !p.get("upper_bound").is_some_and(Value::is_number))
        .map(|p| json!({ "name": p.get("name"), "reason": p.get("reason") }))
        .collect();
    let [failed, indeterminate, not_evaluated, deferred] = by;
    let sanity_failed: Vec<Value> = arr(results.get("sanity"))
        .into_iter()
        .filter(|c| c.get("status").and_then(Value::as_str) == Some("fail"))
        .collect();
    json!({
        "verdict": verdict,
        "reason": results.get("verdict_reason").cloned().unwrap_or(Value::Null),
        "sanity_failed": sanity_failed,
        "meets_standard": verdict == "pass",
        "counts": counts,
        "failed": failed,
        "indeterminate": indeterminate,
        "not_evaluated": not_evaluated,
        "deferred": deferred,
        "unobservable": unobservable,
    })
}

/// The recalibration interval the archive's trend implies: the soonest a determined drift
/// is expected to cross its acceptance limit, as text for the conclusions.
pub(crate) fn trend_interval(trend: &Value) -> Option<String> {
    let params = trend.get("parameters")?.as_array()?;
    let (days, p) = params
        .iter()
        .filter_map(|p| Some((p.get("recalibration_days")?.as_f64()?, p)))
        .filter(|(d, _)| d.is_finite())
        .min_by(|a, b| a.0.total_cmp(&b.0))?;
    let months = (days / 30.44).floor().max(1.0);
    let conf = trend
        .get("confidence")
        .and_then(Value::as_f64)
        .unwrap_or(0.95)
        * 100.0;
    Some(format!(
        "{months:.0} months (by {}: the archive's trend of {} reaches its acceptance limit then, at {conf:.0} % confidence)",
        p.get("recalibrate_by")
            .and_then(Value::as_str)
            .unwrap_or("?"),
        p.get("name").and_then(Value::as_str).unwrap_or("?"),
    ))
}

/// What the report shows of the archive's trend: how many calibrations, since when, and
/// each determined drift (`rate`, `u` per year, with the parameter's unit); `null` when no
/// archive was consulted or it holds no calibration of the unit.
pub(crate) fn trend_view(trend: &Value) -> Value {
    let n = trend
        .get("calibrations")
        .and_then(Value::as_u64)
        .unwrap_or(0);
    if n == 0 {
        return Value::Null;
    }
    let params = trend
        .get("parameters")
        .and_then(Value::as_array)
        .cloned()
        .unwrap_or_default();
    let since = params
        .iter()
        .filter_map(|p| {
            p.get("points")?
                .as_array()?
                .first()?
                .get("started")?
                .as_str()
        })
        .min()
        .map(|s| s.chars().take(10).collect::<String>());
    let drifts: Vec<Value> = params
        .iter()
        .filter_map(|p| {
            let d = p.get("drift")?;
            Some(json!({
                "name": p.get("name"),
                "unit": format!("{}/year", p.get("unit").and_then(Value::as_str).unwrap_or("")),
                "rate": d.get("rate_per_year"),
                "u": d.get("u_rate_per_year"),
                "recalibrate_by": p.get("recalibrate_by"),
            }))
        })
        .collect();
    json!({
        "serial": trend.get("serial"),
        "calibrations": n,
        "since": since,
        "drifts": drifts,
    })
}
