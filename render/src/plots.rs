//! The report's pictures, drawn from results.json sections and the temperature series. A
//! section that is missing or empty gives no plot (`None`), never an empty frame.

use super::svg::{Chart, PALETTE, Series, Style};
use super::{ReportInput, TemperatureSeries};
use serde_json::Value;
use std::collections::BTreeMap;

/// Every plot by name (`residuals_accel`, `residuals_gyro`, `rate_fit`, `allan`,
/// `temperature`), and one per finding, in the findings' order.
pub struct Plots {
    /// Named plots (`None`: no data).
    pub named: BTreeMap<&'static str, Option<String>>,
    /// Residuals before/after, one per results.json finding (`None`: no residuals).
    pub findings: Vec<Option<String>>,
    /// Residuals before/after, one per explain.json finding.
    pub explain: Vec<Option<String>>,
    /// The twin's residual figure and its time series, one per kind of segment where it
    /// disagrees (explain.json's `twin`).
    pub twin: Vec<String>,
}

/// Draws every plot the input has data for.
pub fn draw(input: &ReportInput) -> Plots {
    let r = &input.results;
    let mut named = BTreeMap::new();
    named.insert(
        "residuals_accel",
        residuals(r, ["ax", "ay", "az"], "Accelerometer residuals", "m/s²"),
    );
    named.insert(
        "residuals_gyro",
        residuals(r, ["gx", "gy", "gz"], "Gyroscope residuals", "°/s"),
    );
    named.insert(
        "rate_fit",
        rate_fit(r).or_else(|| rate_residuals(r, input.manifest.as_ref())),
    );
    named.insert("allan", allan(r));
    named.insert("size_effect_velocity", size_effect_velocity(r));
    named.insert("temperature", temperature(&input.temperature));
    let findings = match r.get("findings").and_then(Value::as_array) {
        Some(fs) => fs.iter().map(|f| super::finding::figure(f, None)).collect(),
        None => vec![],
    };
    let explain = input
        .explain
        .as_ref()
        .map(super::finding::explain_figures)
        .unwrap_or_default()
        .into_iter()
        .map(|(_, svg)| svg)
        .collect();
    // The twin's residual figure, then its time series per segment kind.
    let twin = match &input.explain {
        Some(x) => super::twin::twin_residual_figure(x)
            .into_iter()
            .chain(super::twin::twin_figures(x).into_iter().map(|(_, svg)| svg))
            .collect(),
        None => Vec::new(),
    };
    Plots {
        named,
        findings,
        explain,
        twin,
    }
}

fn num(v: &Value, keys: &[&str]) -> Option<f64> {
    keys.iter().find_map(|k| v.get(*k).and_then(Value::as_f64))
}

fn text<'a>(v: &'a Value, keys: &[&str]) -> Option<&'a str> {
    keys.iter().find_map(|k| v.get(*k).and_then(Value::as_str))
}

/// Residual rows as (segment, channel, mean, std), from a list of rows or an object
/// `{segment: {channel: {mean, std}}}`.
fn residual_rows(r: &Value) -> Vec<(String, String, f64, f64)> {
    match r.get("residuals") {
        Some(Value::Array(rows)) => rows
            .iter()
            .filter_map(|row| {
                Some((
                    text(row, &["segment"])?.to_string(),
                    super::views::channel_key(row)?,
                    num(row, &["mean"])?,
                    num(row, &["std"]).unwrap_or(0.0),
                ))
            })
            .collect(),
        Some(Value::Object(segs)) => segs
            .iter()
            .flat_map(|(seg, chans)| {
                chans
                    .as_object()
                    .into_iter()
                    .flatten()
                    .filter_map(move |(ch, v)| {
                        Some((
                            seg.clone(),
                            ch.clone(),
                            num(v, &["mean"])?,
                            num(v, &["std"]).unwrap_or(0.0),
                        ))
                    })
            })
            .collect(),
        _ => vec![],
    }
}

fn residuals(r: &Value, channels: [&str; 3], title: &str, unit: &str) -> Option<String> {
    let rows = residual_rows(r);
    let mut segments: Vec<String> = vec![];
    for (s, ch, ..) in &rows {
        if channels.contains(&ch.as_str()) && !segments.contains(s) {
            segments.push(s.clone());
        }
    }
    let series = channels
        .iter()
        .enumerate()
        .map(|(k, ch)| {
            let mine: Vec<_> = rows.iter().filter(|row| row.1 == *ch).collect();
            // Offset the channels a little so their error bars do not overlap.
            let dx = (k as f64 - 1.0) * 0.18;
            let idx = |s: &String| segments.iter().position(|x| x == s).unwrap_or(0) as f64;
            Series {
                name: (*ch).to_string(),
                points: mine.iter().map(|row| (idx(&row.0) + dx, row.2)).collect(),
                err: Some(mine.iter().map(|row| row.3).collect()),
                style: Style::Markers,
                color: PALETTE[k].into(),
            }
        })
        .collect();
    Chart {
        title: format!("{title} per segment (mean ± std)"),
        y_label: format!("residual ({unit})"),
        series,
        x_categories: segments,
        zero_line: true,
        ..Chart::default()
    }
    .to_svg()
}

/// Gyro output minus reference against the reference rate: markers for the rate points,
/// the line the fitted bias and scale predict (`K (w + b) - w`).
fn rate_fit(r: &Value) -> Option<String> {
    let rows = r.get("rate_points").and_then(Value::as_array)?;
    let mut channels: Vec<String> = vec![];
    for row in rows {
        if let Some(ch) = text(row, &["channel"])
            && !channels.iter().any(|c| c == ch)
        {
            channels.push(ch.to_string());
        }
    }
    let mut series = vec![];
    for (k, ch) in channels.iter().enumerate() {
        let pts: Vec<(f64, f64)> = rows
            .iter()
            .filter(|row| text(row, &["channel"]) == Some(ch))
            .filter_map(|row| {
                let w = num(row, &["reference_dps", "reference"])?;
                let m = num(row, &["measured_dps", "measured"])?;
                Some((w, m - w))
            })
            .collect();
        let color = PALETTE[k % PALETTE.len()].to_string();
        let axis = ch.trim_start_matches('g');
        let param = |kind: &str| {
            r.get("parameters")
                .and_then(|p| p.get(format!("gyro.{kind}.{axis}")))
                .and_then(|p| p.get("value"))
                .and_then(Value::as_f64)
        };
        if let (Some(b), Some(s)) = (param("bias"), param("scale")) {
            let lo = pts.iter().map(|p| p.0).fold(f64::INFINITY, f64::min);
            let hi = pts.iter().map(|p| p.0).fold(f64::NEG_INFINITY, f64::max);
            let k_ = 1.0 + s * 1e-6;
            let line = if lo < hi {
                vec![(lo, k_ * (lo + b) - lo), (hi, k_ * (hi + b) - hi)]
            } else {
                vec![]
            };
            series.push(Series {
                name: format!("{ch} fit"),
                points: line,
                err: None,
                style: Style::Line,
                color: color.clone(),
            });
        }
        series.push(Series {
            name: ch.clone(),
            points: pts,
            err: None,
            style: Style::Markers,
            color,
        });
    }
    Chart {
        title: "Gyro rate-point fit: output − reference".into(),
        x_label: "reference rate (°/s)".into(),
        y_label: "output − reference (°/s)".into(),
        series,
        zero_line: true,
        ..Chart::default()
    }
    .to_svg()
}

/// Residual means (± std) of the gyro channels at each rate point against the nominal rate:
/// what the rate-point fit leaves unexplained. Used when results.json has no `rate_points`.
fn rate_residuals(r: &Value, manifest: Option<&Value>) -> Option<String> {
    let segs = manifest?.get("segments")?.as_array()?;
    let rate_of = |id: &str| {
        segs.iter()
            .find(|s| text(s, &["id"]) == Some(id) && text(s, &["kind"]) == Some("rate"))
            .and_then(|s| {
                Some((
                    text(s, &["axis"]).unwrap_or("?").to_string(),
                    num(s, &["rate_dps"])?,
                ))
            })
    };
    let mut series: Vec<Series> = vec![];
    for (seg, ch, mean, std) in residual_rows(r) {
        let Some((axis, rate)) = rate_of(&seg) else {
            continue;
        };
        if !ch.starts_with('g') {
            continue;
        }
        let name = format!("{axis}: {ch}");
        let k = match series.iter().position(|s| s.name == name) {
            Some(k) => k,
            None => {
                let n = series.len();
                series.push(Series {
                    name,
                    points: vec![],
                    err: Some(vec![]),
                    style: Style::Markers,
                    color: PALETTE[n % PALETTE.len()].into(),
                });
                n
            }
        };
        // Spread the series a little around each rate so the error bars stay apart.
        let dx = (k as f64 - 2.5) * 1.2;
        series[k].points.push((rate + dx, mean));
        if let Some(e) = series[k].err.as_mut() {
            e.push(std);
        }
    }
    Chart {
        title: "Gyro rate-point fit: residuals (output − model)".into(),
        x_label: "nominal table rate (°/s)".into(),
        y_label: "residual (°/s)".into(),
        series,
        zero_line: true,
        ..Chart::default()
    }
    .to_svg()
}

/// The navigation velocity of each swaying segment, East and North, from its start: the
/// drift whose rate the size-effect fit uses.
fn size_effect_velocity(r: &Value) -> Option<String> {
    let segs = r.get("size_effect")?.get("segments")?.as_array()?;
    let mut series = Vec::new();
    for (k, s) in segs.iter().enumerate() {
        let id = text(s, &["segment"]).unwrap_or("?");
        let v = s.get("velocity").and_then(Value::as_array)?;
        let rows: Vec<[f64; 3]> = v
            .iter()
            .filter_map(|p| {
                let p = p.as_array()?;
                Some([
                    p.first()?.as_f64()?,
                    p.get(1)?.as_f64()?,
                    p.get(2)?.as_f64()?,
                ])
            })
            .collect();
        let Some(first) = rows.first().copied() else {
            continue;
        };
        for (c, dir) in [(1, "E"), (2, "N")] {
            let points: Vec<(f64, f64)> = rows
                .iter()
                .map(|p| (p[0] - first[0], p[c] - first[c]))
                .collect();
            series.push(Series {
                name: format!("{id} {dir}"),
                points: thin(&points, 300),
                err: None,
                style: Style::Line,
                color: PALETTE[(2 * k + c - 1) % PALETTE.len()].into(),
            });
        }
    }
    Chart {
        title: "Velocity drift while swaying".into(),
        x_label: "time from the segment's start (s)".into(),
        y_label: "velocity change (m/s)".into(),
        series,
        ..Chart::default()
    }
    .to_svg()
}

fn allan(r: &Value) -> Option<String> {
    let a = r.get("allan")?;
    let unit = a.get("unit").and_then(Value::as_str).unwrap_or("deg/s");
    // results.json: `{tau_s, adev_dps: [x, y, z]}`; also `{channels: {gx: {tau_s, adev}}}`.
    let mut curves: Vec<(String, &Vec<Value>, &Vec<Value>)> = vec![];
    if let (Some(tau), Some(adev)) = (
        a.get("tau_s").and_then(Value::as_array),
        a.get("adev_dps").and_then(Value::as_array),
    ) {
        for (axis, d) in ["gx", "gy", "gz"].iter().zip(adev) {
            if let Some(d) = d.as_array() {
                curves.push((axis.to_string(), tau, d));
            }
        }
    } else if let Some(chans) = a.get("channels").and_then(Value::as_object) {
        for (ch, c) in chans {
            let tau = c
                .get("tau_s")
                .or_else(|| c.get("tau"))
                .and_then(Value::as_array);
            if let (Some(tau), Some(d)) = (tau, c.get("adev").and_then(Value::as_array)) {
                curves.push((ch.clone(), tau, d));
            }
        }
    }
    let series = curves
        .into_iter()
        .enumerate()
        .map(|(k, (ch, tau, adev))| Series {
            name: ch,
            points: tau
                .iter()
                .zip(adev)
                .filter_map(|(t, d)| Some((t.as_f64()?, d.as_f64()?)))
                .collect(),
            err: None,
            style: Style::LineMarkers,
            color: PALETTE[k % PALETTE.len()].into(),
        })
        .collect();
    Chart {
        title: "Allan deviation of the static block".into(),
        x_label: "averaging time τ (s)".into(),
        y_label: format!("σ(τ) ({})", super::filters::pretty_unit(unit)),
        x_log: true,
        y_log: true,
        series,
        ..Chart::default()
    }
    .to_svg()
}

/// At most `n` points, evenly picked (the plot needs the shape, not every sample).
fn thin(points: &[(f64, f64)], n: usize) -> Vec<(f64, f64)> {
    if points.len() <= n {
        return points.to_vec();
    }
    let step = points.len() as f64 / n as f64;
    (0..n)
        .map(|i| points[(i as f64 * step) as usize])
        .chain(points.last().copied())
        .collect()
}

fn temperature(t: &TemperatureSeries) -> Option<String> {
    let minutes = |p: &[(f64, f64)]| -> Vec<(f64, f64)> {
        let t0 = p.first().map_or(0.0, |q| q.0);
        thin(p, 400)
            .iter()
            .map(|q| ((q.0 - t0) / 60.0, q.1))
            .collect()
    };
    let mut series = vec![];
    if !t.imu.is_empty() {
        series.push(Series {
            name: "IMU internal".into(),
            points: minutes(&t.imu),
            err: None,
            style: Style::Line,
            color: PALETTE[1].into(),
        });
    }
    if !t.ambient.is_empty() {
        series.push(Series {
            name: "lab ambient".into(),
            points: minutes(&t.ambient),
            err: None,
            style: Style::Line,
            color: PALETTE[0].into(),
        });
    }
    Chart {
        title: "Temperature over the run".into(),
        x_label: "time since start (min)".into(),
        y_label: "temperature (°C)".into(),
        series,
        ..Chart::default()
    }
    .to_svg()
}
