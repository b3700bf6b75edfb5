//! The forest plot of explain across recordings: per pooled parameter, each recording's
//! value with its ±u bar (named by run and serial), the pooled value with its band (±u)
//! and the fleet's band (±sqrt(u² + spread²), where a new unit of the model is expected),
//! the outliers' recordings in red and the recordings the pool leaves out as open circles.
//! One HTML page holds them all (`ratecal explain RUN RUN... --plots DIR`); plain SVG, no
//! script.

use super::axis::{axis, tick_label};
use super::svg::{PALETTE, esc};
use ratecal_analysis::explain::across::{Across, Outlier, PooledOut};
use std::fmt::Write;

const W: f64 = 720.0;
/// The labels' column (run · serial) and the values' column on the right.
const LABELS: f64 = 250.0;
const VALUES: f64 = 150.0;
const TOP: f64 = 40.0;
const ROW: f64 = 16.0;
/// Space below the rows: the pooled row, the axis and its ticks, the legend.
const BELOW: f64 = 84.0;
const BLUE: &str = PALETTE[0];
const RED: &str = PALETTE[1];

/// The page: a heading, the recordings and the outliers, then a forest plot per pooled
/// parameter of `effects`, in their order.
pub fn across_page(a: &Across) -> String {
    let mut s =
        String::from("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n");
    let units = a.units();
    let title = format!("Across {} recordings of {units} units", a.recordings.len());
    let _ = write!(
        s,
        "<title>{}</title>\n<style>body{{font-family:sans-serif;max-width:760px;margin:2em auto}}\
         h2{{font-size:1.1em;margin-top:2em}} td,th{{padding:0 .6em;text-align:left}}</style>\n\
         </head>\n<body>\n<h1>{}</h1>\n",
        esc(&title),
        esc(&title)
    );
    if a.effects.is_empty() {
        s.push_str("<p>Nothing pooled to show: no parameter recurs.</p>\n");
    }
    for e in &a.effects {
        let _ = write!(
            s,
            "<section id=\"{id}\">\n<h2>{id} <small>({})</small></h2>\n{}\n</section>\n",
            esc(&e.verdict),
            forest(e, &a.outliers),
            id = esc(&format!("{}.{}", e.effect, e.parameter)),
        );
    }
    s.push_str(&outlier_table(&a.outliers));
    s.push_str("</body>\n</html>\n");
    s
}

fn outlier_table(outliers: &[Outlier]) -> String {
    if outliers.is_empty() {
        return String::new();
    }
    let mut s = String::from(
        "<h2>Outliers</h2>\n<table>\n<tr><th>serial</th><th>parameter</th><th>value</th><th>u</th></tr>\n",
    );
    for o in outliers {
        let _ = writeln!(
            s,
            "<tr><td>{}</td><td>{}.{}</td><td>{}</td><td>{}</td></tr>",
            esc(&o.serial),
            esc(&o.effect),
            esc(&o.parameter),
            num(o.value),
            num(o.u)
        );
    }
    s + "</table>\n"
}

/// A number as the plot writes it: four significant digits.
fn num(v: f64) -> String {
    crate::filters::sig(v, 4)
}

/// The decimals of two significant digits of `u` (`None` without an uncertainty).
fn decimals(u: f64) -> Option<usize> {
    (u > 0.0 && u.is_finite()).then(|| (1 - u.log10().floor() as i32).clamp(0, 12) as usize)
}

/// A value and its uncertainty as every output writes them (GUM 7.2.6:
/// `ratecal_analysis::measured`).
fn pm(v: f64, u: f64) -> String {
    ratecal_analysis::measured::measured_number(v, u)
}

/// The spread, to the decimals of the pooled value.
fn spread(e: &PooledOut) -> String {
    match decimals(e.u) {
        Some(d) => format!("{:.d$}", e.spread),
        None => num(e.spread),
    }
}

/// A label the labels' column holds: a long one keeps its end (the run's own name).
fn clip(label: &str) -> String {
    const MAX: usize = 42;
    let n = label.chars().count();
    match n > MAX {
        true => format!("…{}", label.chars().skip(n - MAX + 1).collect::<String>()),
        false => label.to_string(),
    }
}

/// One parameter's forest plot as an `<svg>` element.
pub fn forest(e: &PooledOut, outliers: &[Outlier]) -> String {
    let rows = &e.per_recording;
    let pw = W - LABELS - VALUES;
    let bands = [e.pooled - e.fleet_u(), e.pooled + e.fleet_u()];
    let ends = rows
        .iter()
        .flat_map(|r| [r.value - r.u, r.value + r.u])
        .chain(bands)
        .chain([0.0]);
    let Some(xa) = axis(ends, false) else {
        return String::new();
    };
    let px = |v: f64| LABELS + xa.t(v) * pw;
    let bottom = TOP + ROW * (rows.len() as f64 + 1.5);
    let height = bottom + BELOW;
    let mut s = String::new();
    let title = format!(
        "{}.{}: {} {} ({}; spread {}, I² {:.0} %)",
        e.effect,
        e.parameter,
        pm(e.pooled, e.u),
        e.unit,
        e.verdict,
        spread(e),
        100.0 * e.i2
    );
    let _ = write!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" class="forest" viewBox="0 0 {W} {height}" width="{W}" height="{height}" role="img" aria-label="{t}" font-family="sans-serif" font-size="11"><title>{t}</title><text x="{LABELS}" y="18" font-size="13" font-weight="bold">{t}</text>"#,
        t = esc(&title)
    );
    band(&mut s, px(bands[0]), px(bands[1]), bottom, "#e3eef8");
    band(
        &mut s,
        px(e.pooled - e.u),
        px(e.pooled + e.u),
        bottom,
        "#b7d3ec",
    );
    let (x0, x) = (px(0.0), px(e.pooled));
    let _ = write!(
        s,
        r##"<line x1="{x0:.1}" y1="{TOP}" x2="{x0:.1}" y2="{bottom:.1}" stroke="#555" stroke-dasharray="4 3"/><line x1="{x:.1}" y1="{TOP}" x2="{x:.1}" y2="{bottom:.1}" stroke="{BLUE}"/>"##
    );
    for (i, r) in rows.iter().enumerate() {
        let out = outliers
            .iter()
            .any(|o| o.serial == r.serial && o.effect == e.effect && o.parameter == e.parameter);
        let left = e.left_out.contains(&r.run);
        let y = TOP + ROW * (i as f64 + 0.5);
        row(
            &mut s,
            (r.run.as_str(), r.serial.as_str()),
            (r.value, r.u),
            y,
            (out, left),
            &px,
        );
    }
    diamond(&mut s, e, bottom - ROW * 0.5, &px);
    ticks(&mut s, &xa, bottom, &px, &e.unit);
    legend(&mut s, height - 12.0);
    s + "</svg>"
}

fn band(s: &mut String, a: f64, b: f64, bottom: f64, fill: &str) {
    let _ = write!(
        s,
        r#"<rect x="{a:.1}" y="{TOP}" width="{:.1}" height="{:.1}" fill="{fill}"/>"#,
        (b - a).max(0.5),
        bottom - TOP
    );
}

/// One recording's row: its label, its bar and marker, its value on the right.
fn row(
    s: &mut String,
    (run, serial): (&str, &str),
    (v, u): (f64, f64),
    y: f64,
    (outlier, left_out): (bool, bool),
    px: &dyn Fn(f64) -> f64,
) {
    let c = if outlier { RED } else { BLUE };
    let fill = if left_out { "#fff" } else { c };
    let mut note = String::new();
    if outlier {
        note.push_str(" outlier");
    }
    if left_out {
        note.push_str(" (left out)");
    }
    let label = clip(&format!("{run} · {serial}"));
    let _ = write!(
        s,
        r##"<g class="recording" data-run="{r}" data-serial="{sn}"><text x="{:.1}" y="{:.1}" text-anchor="end">{l}</text><line x1="{:.1}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="{c}"/><circle cx="{:.1}" cy="{y:.1}" r="3.5" fill="{fill}" stroke="{c}" stroke-width="1.5"/><text x="{:.1}" y="{:.1}" fill="{c}">{}{note}</text></g>"##,
        LABELS - 8.0,
        y + 4.0,
        px(v - u),
        px(v + u),
        px(v),
        W - VALUES + 8.0,
        y + 4.0,
        pm(v, u),
        r = esc(run),
        sn = esc(serial),
        l = esc(&label),
    );
}

/// The pooled row: a diamond over the pooled value's ±u.
fn diamond(s: &mut String, e: &PooledOut, y: f64, px: &dyn Fn(f64) -> f64) {
    let (a, m, b) = (px(e.pooled - e.u), px(e.pooled), px(e.pooled + e.u));
    let _ = write!(
        s,
        r##"<g class="pooled"><text x="{:.1}" y="{:.1}" text-anchor="end" font-weight="bold">pooled ({})</text><polygon points="{a:.1},{y:.1} {m:.1},{:.1} {b:.1},{y:.1} {m:.1},{:.1}" fill="{BLUE}"/><text x="{:.1}" y="{:.1}" font-weight="bold">{}</text></g>"##,
        LABELS - 8.0,
        y + 4.0,
        esc(&e.verdict),
        y - 6.0,
        y + 6.0,
        W - VALUES + 8.0,
        y + 4.0,
        pm(e.pooled, e.u),
    );
}

fn ticks(s: &mut String, xa: &super::axis::Axis, bottom: f64, px: &dyn Fn(f64) -> f64, unit: &str) {
    let _ = write!(
        s,
        r##"<line x1="{LABELS}" y1="{bottom:.1}" x2="{:.1}" y2="{bottom:.1}" stroke="#888"/>"##,
        W - VALUES
    );
    for v in xa.ticks() {
        let x = px(v);
        let _ = write!(
            s,
            r##"<line x1="{x:.1}" y1="{bottom:.1}" x2="{x:.1}" y2="{:.1}" stroke="#888"/><text x="{x:.1}" y="{:.1}" text-anchor="middle">{}</text>"##,
            bottom + 4.0,
            bottom + 16.0,
            tick_label(v, false)
        );
    }
    let _ = write!(
        s,
        r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">{}</text>"#,
        LABELS + (W - VALUES - LABELS) / 2.0,
        bottom + 32.0,
        esc(unit)
    );
}

fn legend(s: &mut String, y: f64) {
    let items = [
        (
            format!(r#"<circle r="3.5" fill="{BLUE}"/>"#),
            "recording ± u",
        ),
        (
            format!(r##"<circle r="3.5" fill="#fff" stroke="{BLUE}" stroke-width="1.5"/>"##),
            "left out of the pool",
        ),
        (format!(r#"<circle r="3.5" fill="{RED}"/>"#), "outlier"),
        (
            r##"<rect x="-6" y="-5" width="12" height="10" fill="#b7d3ec"/>"##.to_string(),
            "pooled ± u",
        ),
        (
            r##"<rect x="-6" y="-5" width="12" height="10" fill="#e3eef8"/>"##.to_string(),
            "± fleet spread",
        ),
    ];
    let mut x = 20.0;
    for (symbol, label) in items {
        let _ = write!(
            s,
            r#"<g transform="translate({x} {y})">{symbol}<text x="10" y="4">{label}</text></g>"#
        );
        x += 30.0 + 6.0 * label.len() as f64;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ratecal_analysis::explain::across::{PerRecording, RecordingOut};

    fn entry() -> PooledOut {
        let rec = |run: &str, serial: &str, value| PerRecording {
            run: run.into(),
            serial: serial.into(),
            value,
            u: 8.0,
        };
        PooledOut {
            effect: "accel_second_order".into(),
            parameter: "x".into(),
            pooled: 16.2,
            u: 2.0,
            spread: 1.5,
            i2: 0.1,
            verdict: "model".into(),
            per_recording: vec![
                rec("r1", "A<1", 14.0),
                rec("r2", "B", 18.0),
                rec("r3", "C", 80.0),
            ],
            left_out: vec!["r3".into()],
            unit: "ug/g^2".into(),
        }
    }

    #[test]
    fn every_recording_the_pool_and_the_marks_are_drawn() {
        let out = Outlier {
            serial: "C".into(),
            effect: "accel_second_order".into(),
            parameter: "x".into(),
            value: 80.0,
            u: 8.0,
        };
        let svg = forest(&entry(), &[out]);
        assert!(svg.starts_with("<svg") && svg.ends_with("</svg>"));
        assert_eq!(svg.matches(r#"class="recording""#).count(), 3);
        assert!(svg.contains("r1 · A&lt;1"), "{svg}");
        assert!(svg.contains("16.2 ± 2.0"), "{svg}");
        // The outlier's row is red and said to be left out; the others are not.
        let r3 = svg.split(r#"data-run="r3""#).nth(1).unwrap();
        assert!(
            r3.split("</g>")
                .next()
                .unwrap()
                .contains("outlier (left out)")
        );
        assert_eq!(svg.matches("outlier (left out)").count(), 1);
        assert_eq!(svg.matches(RED).count(), 3 + 1, "row (3) and legend (1)");
    }

    #[test]
    fn the_page_holds_a_plot_per_entry() {
        let a = Across {
            recordings: vec![RecordingOut {
                run: "r1".into(),
                serial: "A".into(),
                findings: vec![],
                unexplained: 0,
            }],
            effects: vec![entry(), entry()],
            outliers: vec![],
        };
        let page = across_page(&a);
        assert_eq!(page.matches("<svg").count(), 2);
        assert!(page.starts_with("<!DOCTYPE html>") && page.ends_with("</html>\n"));
    }
}
