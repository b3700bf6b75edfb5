//! The before/after figure of a finding: for each channel of the sensors where the finding
//! shows, the residual of every segment (recording order) before and after the effect was
//! modelled, segments held out of the fit as open circles, and the final model's noise
//! floor. Drawn for the report and written as files by `ratecal explain`: one
//! implementation.

use super::svg::{Chart, PALETTE, Series, Style, stack};
use serde_json::Value;

const CHANNELS: [&str; 6] = ["ax", "ay", "az", "gx", "gy", "gz"];

/// One figure per finding of an explain.json (`ratecal-explain/1`), in the findings' order:
/// the finding's effect id and its SVG (`None` when the finding holds no residuals).
pub fn explain_figures(explain: &Value) -> Vec<(String, Option<String>)> {
    let floor = explain.get("final").and_then(|f| f.get("noise_floor"));
    explain
        .get("findings")
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
        .map(|f| {
            let effect = text(f, "effect").unwrap_or("finding").to_string();
            (effect, figure(f, floor))
        })
        .collect()
}

/// A finding's figure. Rows are `residuals` entries `{segment, channel, rms_before,
/// rms_after, held_out}` (explain.json; log scale), or `{segment, channel, before, after}`
/// residual means (results.json's `findings`; linear scale). Panels: every channel of the
/// sensors in the finding's `located` entries, else every channel with rows.
pub fn figure(f: &Value, noise_floor: Option<&Value>) -> Option<String> {
    let rows: Vec<Row> = f
        .get("residuals")
        .and_then(Value::as_array)?
        .iter()
        .filter_map(Row::of)
        .collect();
    let located: Vec<&str> = f
        .get("located")
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
        .filter_map(|l| text(l, "channel"))
        .collect();
    let mut channels: Vec<&str> = rows.iter().map(|r| r.channel.as_str()).collect();
    channels.sort_by_key(|c| CHANNELS.iter().position(|k| k == c).unwrap_or(6));
    channels.dedup();
    // Every channel of each sensor where the finding shows, the unchanged ones too.
    if !located.is_empty() {
        channels.retain(|c| located.iter().any(|l| l.get(..1) == c.get(..1)));
    }
    let effect = ["title", "effect", "name"]
        .iter()
        .find_map(|k| text(f, k))
        .unwrap_or("finding");
    let charts: Vec<Chart> = channels
        .iter()
        .map(|ch| panel(effect, ch, &rows, noise_floor))
        .collect();
    stack(&format!("Residuals before and after: {effect}"), &charts)
}

/// One row of a finding's residual table.
struct Row {
    segment: String,
    channel: String,
    before: f64,
    after: f64,
    held_out: bool,
    /// RMS (explain.json) rather than a mean (results.json).
    rms: bool,
}

impl Row {
    fn of(v: &Value) -> Option<Row> {
        let num = |k: &str| v.get(k).and_then(Value::as_f64);
        let rms = num("rms_before").is_some();
        Some(Row {
            segment: text(v, "segment")?.to_string(),
            channel: text(v, "channel").unwrap_or("").to_string(),
            before: num("rms_before").or_else(|| num("before"))?,
            after: num("rms_after").or_else(|| num("after"))?,
            held_out: v.get("held_out").and_then(Value::as_bool) == Some(true),
            rms,
        })
    }
}

fn text<'a>(v: &'a Value, key: &str) -> Option<&'a str> {
    v.get(key).and_then(Value::as_str)
}

fn panel(effect: &str, ch: &str, rows: &[Row], noise_floor: Option<&Value>) -> Chart {
    let mine: Vec<&Row> = rows.iter().filter(|r| r.channel == ch).collect();
    let rms = mine.iter().all(|r| r.rms);
    let (sensor, unit) = if ch.starts_with('g') {
        ("gyro_dps", "°/s")
    } else {
        ("accel_mps2", "m/s²")
    };
    let mut series = Vec::new();
    // Before a little left of the segment, after a little right: unchanged pairs stay apart.
    for (name, held, dx, color) in [
        ("before", false, -0.12, PALETTE[1]),
        ("after", false, 0.12, PALETTE[2]),
        ("before, held out", true, -0.12, PALETTE[1]),
        ("after, held out", true, 0.12, PALETTE[2]),
    ] {
        let points: Vec<(f64, f64)> = mine
            .iter()
            .enumerate()
            .filter(|(_, r)| r.held_out == held)
            .map(|(i, r)| {
                let y = if name.starts_with("before") {
                    r.before
                } else {
                    r.after
                };
                (i as f64 + dx, y)
            })
            .collect();
        if !points.is_empty() {
            series.push(Series {
                name: name.into(),
                points,
                err: None,
                style: if held {
                    Style::OpenMarkers
                } else {
                    Style::Markers
                },
                color: color.into(),
            });
        }
    }
    let floor = noise_floor
        .and_then(|n| n.get(sensor))
        .and_then(Value::as_f64);
    if let Some(nf) = floor.filter(|nf| rms && *nf > 0.0 && !mine.is_empty()) {
        series.push(Series {
            name: "noise floor".into(),
            points: vec![(-0.4, nf), (mine.len() as f64 - 0.6, nf)],
            err: None,
            style: Style::Line,
            color: "#999".into(),
        });
    }
    let what = if rms { "RMS" } else { "mean" };
    let label = if ch.is_empty() {
        String::new()
    } else {
        format!(" {ch}")
    };
    Chart {
        title: format!("{effect}:{label} residual {what} per segment"),
        y_label: format!("residual {what} ({unit})"),
        y_log: rms,
        zero_line: !rms,
        series,
        x_categories: mine.iter().map(|r| r.segment.clone()).collect(),
        ..Chart::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn explain() -> Value {
        json!({
            "final": { "noise_floor": { "accel_mps2": 2e-4, "gyro_dps": 3e-3 } },
            "findings": [{
                "effect": "lever_arm",
                "located": [{ "segment": "r1", "channel": "az" }],
                "residuals": [
                    { "segment": "s1", "channel": "ax", "rms_before": 2.2e-4, "rms_after": 2.2e-4, "held_out": false },
                    { "segment": "s1", "channel": "az", "rms_before": 2.1e-4, "rms_after": 2.0e-4, "held_out": false },
                    { "segment": "r1", "channel": "az", "rms_before": 6.0e-2, "rms_after": 1.9e-4, "held_out": false },
                    { "segment": "r2", "channel": "az", "rms_before": 5.9e-2, "rms_after": 1.8e-4, "held_out": true },
                    { "segment": "r1", "channel": "gz", "rms_before": 3.0e-3, "rms_after": 3.0e-3, "held_out": false }
                ]
            }, { "effect": "earth_rate" }]
        })
    }

    #[test]
    fn one_panel_per_located_channel_with_every_segment() {
        let figs = explain_figures(&explain());
        assert_eq!(figs.len(), 2);
        assert_eq!(figs[0].0, "lever_arm");
        let svg = figs[0].1.as_deref().unwrap();
        assert!(svg.starts_with("<svg xmlns") && svg.ends_with("</svg>"));
        // The accelerometer channels with rows (ax unchanged, az where it shows), with every
        // segment; not gz (the gyros are not where it shows).
        assert!(svg.contains("lever_arm: ax residual RMS per segment"));
        assert!(svg.contains("lever_arm: az residual RMS per segment"));
        assert!(!svg.contains(" gz "));
        assert_eq!(svg.matches("<svg").count(), 1 + 2);
        for seg in ["s1", "r1", "r2"] {
            assert!(svg.contains(&format!(">{seg}</text>")), "{seg}");
        }
        // In the az panel: two fitted segments per series, one held out (open circles), the
        // noise floor.
        let svg = svg.split_once("lever_arm: az").unwrap().1;
        let series = |name: &str| {
            svg.split(&format!(r#"data-name="{name}">"#))
                .nth(1)
                .unwrap()
                .split("</g>")
                .next()
                .unwrap()
                .to_string()
        };
        assert_eq!(series("before").matches("<circle").count(), 2 + 1);
        assert_eq!(
            series("after, held out")
                .matches(r##"fill="#fff""##)
                .count(),
            1 + 1
        );
        assert!(svg.contains(r#"data-name="noise floor""#));
        // A finding without residuals has no figure.
        assert!(figs[1].1.is_none());
    }

    #[test]
    fn residual_means_are_drawn_on_a_linear_scale() {
        let f = json!({ "title": "t", "residuals": [
            { "segment": "a", "before": -0.2, "after": 0.01 },
            { "segment": "b", "before": 0.3, "after": -0.02 }
        ]});
        let svg = figure(&f, None).unwrap();
        assert!(svg.contains("t: residual mean per segment"));
        assert!(svg.contains("stroke-dasharray")); // the zero line
    }
}
