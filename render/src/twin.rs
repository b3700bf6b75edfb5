//! The twin's time-series figures: per kind of segment where the twin disagrees, a few
//! representative segments, each a panel overlaying the recording (black), the twin as it
//! is (orange) and the twin updated (green) on the channel that disagrees most, from
//! explain.json's `twin.series`. Drawn for the report and written as files by `ratecal
//! explain --twin`: one implementation.

use super::svg::{Chart, PALETTE, Series, Style, stack};
use serde_json::Value;

/// One figure per segment kind of `twin.series` in an explain.json, in the order the kinds
/// first appear: `(kind, svg)`.
pub fn twin_figures(explain: &Value) -> Vec<(String, String)> {
    let series: Vec<&Value> = explain
        .get("twin")
        .and_then(|t| t.get("series"))
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
        .collect();
    let mut kinds: Vec<&str> = Vec::new();
    for s in &series {
        if let Some(k) = text(s, "kind")
            && !kinds.contains(&k)
        {
            kinds.push(k);
        }
    }
    kinds
        .into_iter()
        .filter_map(|kind| {
            let charts: Vec<Chart> = series
                .iter()
                .filter(|s| text(s, "kind") == Some(kind))
                .filter_map(|&s| panel(s))
                .collect();
            let svg = stack(
                &format!("The twin against the recording: {kind} segments"),
                &charts,
            )?;
            Some((kind.to_string(), svg))
        })
        .collect()
}

/// The twin's residual figure of an explain.json with `twin`: every segment's residual RMS
/// against the twin as it is (orange) and updated (green), on the channels of the sensors
/// where it disagrees (every channel when it agrees), the final model's noise floor in
/// grey: explain's finding figure.
pub fn twin_residual_figure(explain: &Value) -> Option<String> {
    let twin = explain.get("twin")?;
    let segments = |k: &str| {
        twin.get(k)
            .and_then(|p| p.get("segments"))
            .and_then(Value::as_array)
            .cloned()
            .unwrap_or_default()
    };
    let rows: Vec<Value> = segments("before")
        .iter()
        .zip(&segments("after"))
        .map(|(b, a)| {
            serde_json::json!({ "segment": b["segment"], "channel": b["channel"],
                "rms_before": b["rms"], "rms_after": a["rms"], "held_out": false })
        })
        .collect();
    let located: Vec<Value> = twin
        .get("before")
        .and_then(|p| p.get("disagree"))
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
        .map(|d| serde_json::json!({ "channel": d["channel"] }))
        .collect();
    let f = serde_json::json!({ "title": "twin", "residuals": rows, "located": located });
    super::finding::figure(&f, explain.get("final").and_then(|f| f.get("noise_floor")))
}

fn text<'a>(v: &'a Value, key: &str) -> Option<&'a str> {
    v.get(key).and_then(Value::as_str)
}

fn numbers(v: &Value, key: &str) -> Vec<f64> {
    v.get(key)
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
        .map(|x| x.as_f64().unwrap_or(f64::NAN))
        .collect()
}

/// A segment's panel: the three series against the time in the segment.
fn panel(s: &Value) -> Option<Chart> {
    let t = numbers(s, "t_s");
    let ch = text(s, "channel")?;
    let unit = if ch.starts_with('g') { "°/s" } else { "m/s²" };
    let series = [
        ("recording", "real", PALETTE[6]),
        ("twin as it is", "before", PALETTE[1]),
        ("twin updated", "after", PALETTE[2]),
    ]
    .into_iter()
    .map(|(name, key, color)| Series {
        name: name.into(),
        points: t
            .iter()
            .zip(numbers(s, key))
            .map(|(&t, y)| (t, y))
            .filter(|(t, y)| t.is_finite() && y.is_finite())
            .collect(),
        err: None,
        style: Style::Line,
        color: color.into(),
    })
    .filter(|s| !s.points.is_empty())
    .collect();
    Some(Chart {
        title: format!("{} {ch}", text(s, "segment").unwrap_or("")),
        x_label: "time in the segment (s)".into(),
        y_label: format!("output − ideal input ({unit})"),
        series,
        ..Chart::default()
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn one_figure_per_kind_with_the_three_series() {
        let x = json!({ "twin": { "series": [
            { "segment": "r1", "kind": "rate", "channel": "az",
              "t_s": [0.5, 1.5], "real": [0.06, 0.061], "before": [0.0, 0.0], "after": [0.06, 0.06] },
            { "segment": "s1", "kind": "static", "channel": "gx",
              "t_s": [0.5, 1.5], "real": [0.01, 0.01], "before": [0.0, 0.0], "after": [0.01, 0.01] },
            { "segment": "r2", "kind": "rate", "channel": "ax",
              "t_s": [0.5], "real": [0.02], "before": [0.0], "after": [0.02] }
        ] } });
        let figs = twin_figures(&x);
        let kinds: Vec<&str> = figs.iter().map(|f| f.0.as_str()).collect();
        assert_eq!(kinds, ["rate", "static"]);
        let rate = &figs[0].1;
        for name in [
            "recording",
            "twin as it is",
            "twin updated",
            "r1 az",
            "r2 ax",
        ] {
            assert!(rate.contains(name), "{name} missing");
        }
        assert!(!rate.contains("s1 gx"));
    }

    #[test]
    fn no_series_no_figure() {
        assert!(twin_figures(&json!({ "twin": { "series": [] } })).is_empty());
        assert!(twin_figures(&json!({})).is_empty());
    }
}
