//! Builds the data model templates see (documented field by field in
//! `docs/report-templates.md`) from results.json, the manifest and the plan. Every section
//! is tolerant: a recording from another system has no `run` or `procedure`, an older
//! results.json may lack residuals or Allan curves; the context then holds `null` or `[]`
//! and the templates say "not recorded".

use super::{ReportInput, process, views};
use serde_json::{Value, json};

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
    let parameters = views::parameters(results);
    let checks = views::checks(results);
    let summary = views::summary(&checks, results, &parameters);
    let environment = environment(input, &get("environment"));
    let recording = results.get("recording").cloned().unwrap_or(Value::Null);

    let procedure = match get("procedure") {
        Value::Null => match recording.get("procedure") {
            Some(p) if !p.is_null() => p.clone(),
            _ => input.plan.as_ref().map_or(
                Value::Null,
                |p| json!({ "name": p.name, "version": p.version, "sha256": null }),
            ),
        },
        p => p,
    };
    // An empty hash is as good as none: the report says "not recorded".
    let sha = procedure
        .get("sha256")
        .filter(|s| s.as_str().is_some_and(|s| !s.is_empty()));
    let traceability = json!({
        "procedure_name": procedure.get("name"),
        "procedure_version": procedure.get("version"),
        "procedure_sha256": sha,
        "station_sha256": run.get("station_sha256"),
        "ratecal_version": input.ratecal_version,
        "run_ratecal_version": run.get("ratecal_version"),
        "run_id": run.get("id").or_else(|| recording.get("run_id")),
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
    let imu = match get("imu") {
        Value::Null => recording.get("imu").cloned().unwrap_or(json!({})),
        i => i,
    };
    let trend = input.archive_trend.clone().unwrap_or(Value::Null);
    let from_trend = views::trend_interval(&trend);
    let interval = input
        .plan
        .as_ref()
        .and_then(|p| {
            p.meta
                .get("recalibration_interval")
                .or_else(|| p.meta.get("recalibration"))
                .cloned()
        })
        .or_else(|| from_trend.clone());
    let repeatability = match results.get("repeatability") {
        Some(r) if r.is_object() => {
            let mut r = r.clone();
            let n = match r.get("runs") {
                Some(Value::Array(a)) => json!(a.len()),
                Some(n) => n.clone(),
                None => Value::Null,
            };
            r["run_count"] = n;
            r
        }
        _ => Value::Null,
    };
    let sync = results.get("sync").map(|s| {
        let ms = s
            .get("max_sync_error_s")
            .and_then(Value::as_f64)
            .map(|v| v * 1e3)
            .or_else(|| s.get("error_ms").and_then(Value::as_f64));
        let mut s = s.clone();
        if s.is_object() {
            s["max_sync_error_ms"] = json!(ms);
        }
        s
    });
    let acquisition = json!({
        "imu_rate_hz": recording.get("imu_rate_hz"),
        "table_rate_hz": recording.get("table_rate_hz"),
        "imu_rows": recording.get("imu_rows"),
        "table_rows": recording.get("table_rows"),
        "duration_s": recording.get("duration_s"),
        // An import without a table (`table: none`) synthesizes the table stream from the
        // declared attitudes: no feedback to speak of (docs/import.md).
        "table_synthesized": manifest
            .and_then(|m| m.get("station"))
            .and_then(|s| s.pointer("/table/model"))
            .and_then(Value::as_str)
            .is_some_and(|t| t.starts_with("none")),
    });

    json!({
        "report": { "format": CONTEXT_FORMAT, "ratecal_version": input.ratecal_version },
        "dry_run": run.get("dry_run").and_then(Value::as_bool).unwrap_or(false),
        "run": run,
        "procedure": procedure,
        "traceability": traceability,
        "imu": imu,
        "station": get("station"),
        "environment": environment,
        "acquisition": acquisition,
        "process": process::describe(manifest, input.plan.as_ref(), results),
        "plan": input.plan.as_ref().map(|p| serde_json::to_value(p).unwrap_or(Value::Null)),
        "results": results,
        "parameters": parameters,
        "calibration": views::calibration_rows(results),
        "gyro_noise": views::gyro_noise_rows(results),
        "other_parameters": views::other_parameters(results),
        "acceptance": checks,
        "verification": results.get("verification").cloned().unwrap_or(json!([])),
        "verification_checks": views::checks_of(&checks, |q| q.ends_with(".error")),
        "repeatability": repeatability,
        "repeatability_checks": views::checks_of(&checks, |q| q.starts_with("repeatability.")),
        "residuals": results.get("residuals").cloned().unwrap_or(json!([])),
        "residual_table": views::residual_table(results),
        "allan": results.get("allan").cloned().unwrap_or(Value::Null),
        "sync": sync,
        "warnings": results.get("warnings").cloned().unwrap_or(json!([])),
        "sanity": results.get("sanity").cloned().unwrap_or(json!([])),
        "explain": input.explain.clone().unwrap_or(Value::Null),
        "archive_trend": views::trend_view(&trend),
        "findings": results.get("findings").cloned().unwrap_or(json!([])),
        "summary": summary,
        "history": history(&run),
        "recommendations": {
            "temperature_span_c": environment["imu_temperature"].get("span"),
            "temperature_compensation": views::has_temperature_model(results, &parameters),
            "recalibration_interval": interval,
        },
    })
}

/// What happened to the run, in plain sentences for the report's first lines: each
/// interruption and resume, an abort, a failure, a procedure run although changed after
/// release (from the manifest's `run` block, where the journal's abort and resume are kept).
fn history(run: &Value) -> Vec<String> {
    let s = |v: Option<&Value>| v.and_then(Value::as_str).map(str::to_string);
    let at = |t: Option<&Value>, step: Option<&Value>| {
        let t = t
            .and_then(Value::as_f64)
            .map(|t| format!(" at t = {t:.3} s"));
        let step = s(step).map(|st| format!(" in step {st}"));
        format!("{}{}", t.unwrap_or_default(), step.unwrap_or_default())
    };
    let mut out = Vec::new();
    for r in run
        .get("resumes")
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
    {
        let why = s(r.get("reason")).map(|w| format!(": {w}"));
        let ended = s(r.get("ended")).map(|e| format!(" (ended {e})"));
        let from = r.get("from_step").and_then(Value::as_u64).unwrap_or(0) + 1;
        out.push(format!(
            "Interrupted ({}){}{}{}; resumed {} from step {from}.",
            s(r.get("interrupted_status")).unwrap_or_else(|| "interrupted".into()),
            at(r.get("t"), r.get("step")),
            why.unwrap_or_default(),
            ended.unwrap_or_default(),
            s(r.get("resumed")).unwrap_or_else(|| "later".into()),
        ));
    }
    let ended = s(run.get("ended")).map(|e| format!(" (ended {e})"));
    match run.get("status").and_then(Value::as_str) {
        Some("aborted") => {
            let a = run.get("abort");
            let rule =
                s(a.and_then(|a| a.get("rule"))).unwrap_or_else(|| "no reason recorded".into());
            let values = s(a.and_then(|a| a.get("values"))).map(|v| format!(" ({v})"));
            out.push(format!(
                "ABORTED{}: {rule}{}{}.",
                at(a.and_then(|a| a.get("t")), a.and_then(|a| a.get("step"))),
                values.unwrap_or_default(),
                ended.unwrap_or_default()
            ));
        }
        Some("failed") => out.push(format!(
            "FAILED: {}{}.",
            s(run.get("failure")).unwrap_or_else(|| "no reason recorded".into()),
            ended.unwrap_or_default()
        )),
        Some("running") => out.push("The run never ended (status `running`).".into()),
        _ => {}
    }
    if let Some(d) = s(run.get("draft_procedure")) {
        // A draft procedure heads the report: it is no calibration of record.
        out.insert(0, format!("{d}."));
    }
    if let Some(c) = s(run.get("changed_after_release")) {
        out.push(format!("Run with --allow-changed: {c}."));
    }
    out
}

/// Lab conditions: the manifest's block (or the one results.json repeats), ambient and IMU
/// temperature statistics from the series (or from results.json's summary).
fn environment(input: &ReportInput, manifest_env: &Value) -> Value {
    let res_env = input.results.get("environment");
    let env = match manifest_env {
        Value::Null => res_env
            .and_then(|e| e.get("recorded"))
            .cloned()
            .unwrap_or(Value::Null),
        e => e.clone(),
    };
    let recorded = env
        .as_object()
        .is_some_and(|e| e.values().any(|v| !v.is_null()));
    let ambient = stats(&input.temperature.ambient).or_else(|| {
        let a = res_env?.get("ambient")?;
        let (min, max) = (a.get("min_c")?.as_f64()?, a.get("max_c")?.as_f64()?);
        Some(
            json!({ "min": min, "max": max, "mean": a.get("mean_c"), "span": max - min,
                     "drift_c_per_h": a.get("drift_c_per_h") }),
        )
    });
    let imu = stats(&input.temperature.imu).or_else(|| {
        let r = res_env?.get("imu_temp_range_c")?.as_array()?;
        let (min, max) = (r.first()?.as_f64()?, r.get(1)?.as_f64()?);
        Some(json!({ "min": min, "max": max, "span": max - min }))
    });
    json!({
        "recorded": recorded,
        "temperature_c": env.get("temperature_c"),
        "humidity_pct": env.get("humidity_pct"),
        "pressure_kpa": env.get("pressure_kpa"),
        "vibration_g": env.get("vibration_g"),
        "ambient": ambient,
        "imu_temperature": imu,
    })
}

/// Min, max, mean and span of a time series' values, or `None` when empty.
fn stats(series: &[(f64, f64)]) -> Option<Value> {
    let vals: Vec<f64> = series
        .iter()
        .map(|p| p.1)
        .filter(|v| v.is_finite())
        .collect();
    if vals.is_empty() {
        return None;
    }
    let min = vals.iter().copied().fold(f64::INFINITY, f64::min);
    let max = vals.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let mean = vals.iter().sum::<f64>() / vals.len() as f64;
    let t0 = series.first().map_or(0.0, |p| p.0);
    let t1 = series.last().map_or(0.0, |p| p.0);
    Some(json!({ "min": min, "max": max, "mean": mean, "span": max - min, "duration_s": t1 - t0 }))
}
