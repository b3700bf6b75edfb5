//! A small self-contained SVG chart: linear or log axes, line and marker series, error bars,
//! a legend. Hand-written rather than a plotting crate: the reports need five simple charts,
//! no fonts are rasterised (the browser draws the text), and the output is stable for
//! snapshots.

use super::axis::{axis, tick_label};
use std::fmt::Write;

const W: f64 = 720.0;
const LEFT: f64 = 78.0;
const RIGHT: f64 = 160.0;
const TOP: f64 = 30.0;
/// Plot area height; the bottom margin grows with the category labels.
const PH: f64 = 224.0;
const BOTTOM: f64 = 46.0;
/// Category labels: font size, rotation, and a generous average glyph width.
const CAT_FONT: f64 = 9.0;
const CAT_ANGLE_DEG: f64 = 50.0;
const GLYPH: f64 = 5.4;

/// Colours for series, in order (colour-blind safe, Okabe-Ito).
pub const PALETTE: [&str; 8] = [
    "#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000", "#F0E442",
];

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Style {
    /// Straight segments between points.
    Line,
    /// A circle per point.
    Markers,
    /// Markers joined by a thin line.
    LineMarkers,
    /// An open circle per point (a subset set apart from the filled markers).
    OpenMarkers,
}

/// One named series of points, optionally with symmetric error bars (`err[i]` about `y`).
#[derive(Debug, Clone)]
pub struct Series {
    /// Legend label.
    pub name: String,
    /// Points (x, y).
    pub points: Vec<(f64, f64)>,
    /// Half-length of each point's error bar (same length as `points`), if any.
    pub err: Option<Vec<f64>>,
    /// Drawing style.
    pub style: Style,
    /// Colour (CSS).
    pub color: String,
}

/// A chart: title, axis labels, scales and series.
#[derive(Debug, Clone, Default)]
pub struct Chart {
    /// Title above the plot area.
    pub title: String,
    /// X axis label.
    pub x_label: String,
    /// Y axis label.
    pub y_label: String,
    /// Logarithmic x axis (non-positive values are dropped).
    pub x_log: bool,
    /// Logarithmic y axis.
    pub y_log: bool,
    /// Series in drawing order.
    pub series: Vec<Series>,
    /// Category labels for integer x positions (0, 1, 2...), drawn instead of numbers.
    pub x_categories: Vec<String>,
    /// Draw a horizontal line at y = 0.
    pub zero_line: bool,
}

pub(crate) fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

impl Chart {
    /// Whether any series has a drawable point.
    pub fn has_data(&self) -> bool {
        self.series.iter().any(|s| !s.points.is_empty())
    }

    /// The chart as an `<svg>` element (no XML prolog), or `None` without data.
    pub fn to_svg(&self) -> Option<String> {
        let (body, height) = self.body()?;
        Some(format!(
            r#"<svg xmlns="http://www.w3.org/2000/svg" class="plot" viewBox="0 0 {W} {height}" width="{W}" height="{height}" role="img" aria-label="{t}" font-family="sans-serif" font-size="11">{body}</svg>"#,
            t = esc(&self.title)
        ))
    }

    /// What goes inside the chart's `<svg>` element, and the element's height.
    fn body(&self) -> Option<(String, f64)> {
        let pts = || self.series.iter().flat_map(|s| s.points.iter());
        let errs = || {
            self.series.iter().flat_map(|s| {
                let e = s.err.clone().unwrap_or_default();
                s.points
                    .iter()
                    .enumerate()
                    .flat_map(move |(i, p)| {
                        let d = e.get(i).copied().unwrap_or(0.0);
                        [p.1 - d, p.1 + d]
                    })
                    .collect::<Vec<_>>()
            })
        };
        let xa = axis(pts().map(|p| p.0), self.x_log)?;
        let ya = axis(
            errs().chain(if self.zero_line { Some(0.0) } else { None }),
            self.y_log,
        )?;
        let pw = W - LEFT - RIGHT;
        let ph = PH;
        let longest = self
            .x_categories
            .iter()
            .map(|c| c.chars().count())
            .max()
            .unwrap_or(0);
        let bottom = if longest == 0 {
            BOTTOM
        } else {
            16.0 + longest as f64 * GLYPH * CAT_ANGLE_DEG.to_radians().sin()
        };
        let height = (TOP + ph + bottom).round();
        let px = |v: f64| LEFT + xa.t(v) * pw;
        let py = |v: f64| TOP + (1.0 - ya.t(v)) * ph;
        let ok = |p: &(f64, f64)| {
            p.0.is_finite()
                && p.1.is_finite()
                && (!self.x_log || p.0 > 0.0)
                && (!self.y_log || p.1 > 0.0)
        };

        let mut s = String::new();
        let _ = write!(s, r#"<title>{}</title>"#, esc(&self.title));
        let _ = write!(
            s,
            r##"<rect x="{LEFT}" y="{TOP}" width="{pw}" height="{ph}" fill="#fff" stroke="#888"/>"##
        );
        let _ = write!(
            s,
            r#"<text x="{}" y="18" text-anchor="middle" font-size="13" font-weight="bold">{}</text>"#,
            LEFT + pw / 2.0,
            esc(&self.title)
        );
        // Grid and tick labels.
        for v in ya.ticks() {
            let y = py(v);
            let _ = write!(
                s,
                r##"<line x1="{LEFT}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#e4e4e4"/><text x="{:.1}" y="{:.1}" text-anchor="end">{}</text>"##,
                LEFT + pw,
                LEFT - 6.0,
                y + 4.0,
                tick_label(v, ya.log)
            );
        }
        if self.x_categories.is_empty() {
            for v in xa.ticks() {
                let x = px(v);
                let _ = write!(
                    s,
                    r##"<line x1="{x:.1}" y1="{TOP}" x2="{x:.1}" y2="{:.1}" stroke="#e4e4e4"/><text x="{x:.1}" y="{:.1}" text-anchor="middle">{}</text>"##,
                    TOP + ph,
                    TOP + ph + 15.0,
                    tick_label(v, xa.log)
                );
            }
        } else {
            for (i, label) in self.x_categories.iter().enumerate() {
                let x = px(i as f64);
                let _ = write!(
                    s,
                    r##"<text x="{x:.1}" y="{:.1}" text-anchor="end" font-size="{CAT_FONT}" transform="rotate(-{CAT_ANGLE_DEG} {x:.1} {:.1})">{}</text>"##,
                    TOP + ph + 10.0,
                    TOP + ph + 10.0,
                    esc(label)
                );
            }
        }
        if self.zero_line && !self.y_log && ya.lo < 0.0 && ya.hi > 0.0 {
            let y = py(0.0);
            let _ = write!(
                s,
                r##"<line x1="{LEFT}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#555" stroke-dasharray="4 3"/>"##,
                LEFT + pw
            );
        }
        // Axis labels.
        if self.x_categories.is_empty() {
            let _ = write!(
                s,
                r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">{}</text>"#,
                LEFT + pw / 2.0,
                height - 8.0,
                esc(&self.x_label)
            );
        }
        let _ = write!(
            s,
            r#"<text x="14" y="{:.1}" text-anchor="middle" transform="rotate(-90 14 {:.1})">{}</text>"#,
            TOP + ph / 2.0,
            TOP + ph / 2.0,
            esc(&self.y_label)
        );
        // Series.
        for (k, ser) in self.series.iter().enumerate() {
            let c = esc(&ser.color);
            let _ = write!(s, r#"<g class="series" data-name="{}">"#, esc(&ser.name));
            if let Some(err) = &ser.err {
                for (p, e) in ser.points.iter().zip(err) {
                    if ok(p) && e.is_finite() && *e > 0.0 {
                        let _ = write!(
                            s,
                            r#"<line x1="{x:.1}" y1="{:.1}" x2="{x:.1}" y2="{:.1}" stroke="{c}"/>"#,
                            py(p.1 - e),
                            py(p.1 + e),
                            x = px(p.0)
                        );
                    }
                }
            }
            if matches!(ser.style, Style::Line | Style::LineMarkers) {
                let d: Vec<String> = ser
                    .points
                    .iter()
                    .filter(|p| ok(p))
                    .map(|p| format!("{:.1},{:.1}", px(p.0), py(p.1)))
                    .collect();
                let width = if ser.style == Style::Line { 1.6 } else { 0.8 };
                let _ = write!(
                    s,
                    r#"<polyline fill="none" stroke="{c}" stroke-width="{width}" points="{}"/>"#,
                    d.join(" ")
                );
            }
            if matches!(ser.style, Style::Markers | Style::LineMarkers) {
                for p in ser.points.iter().filter(|p| ok(p)) {
                    let _ = write!(
                        s,
                        r#"<circle cx="{:.1}" cy="{:.1}" r="3" fill="{c}"/>"#,
                        px(p.0),
                        py(p.1)
                    );
                }
            }
            if ser.style == Style::OpenMarkers {
                for p in ser.points.iter().filter(|p| ok(p)) {
                    let _ = write!(
                        s,
                        r##"<circle cx="{:.1}" cy="{:.1}" r="3.2" fill="#fff" stroke="{c}" stroke-width="1.6"/>"##,
                        px(p.0),
                        py(p.1)
                    );
                }
            }
            // Legend entry: a line for line styles, a dot for markers.
            let ly = TOP + 12.0 + 16.0 * k as f64;
            let lx = LEFT + pw + 12.0;
            let symbol = match ser.style {
                Style::Markers => format!(
                    r#"<circle cx="{}" cy="{ly}" r="3.5" fill="{c}"/>"#,
                    lx + 9.0
                ),
                Style::OpenMarkers => format!(
                    r##"<circle cx="{}" cy="{ly}" r="3.5" fill="#fff" stroke="{c}" stroke-width="1.6"/>"##,
                    lx + 9.0
                ),
                _ => format!(
                    r#"<line x1="{lx}" y1="{ly}" x2="{}" y2="{ly}" stroke="{c}" stroke-width="2.5"/>"#,
                    lx + 18.0
                ),
            };
            let _ = write!(
                s,
                r#"{symbol}<text x="{}" y="{:.1}">{}</text></g>"#,
                lx + 24.0,
                ly + 4.0,
                esc(&ser.name)
            );
        }
        Some((s, height))
    }
}

/// Charts one above the other in one `<svg>` on a white ground (a figure of several
/// panels that stands alone as a file), or `None` when no chart has data.
pub fn stack(title: &str, charts: &[Chart]) -> Option<String> {
    let mut inner = String::new();
    let mut y = 0.0;
    for (body, h) in charts.iter().filter_map(Chart::body) {
        let _ = write!(
            inner,
            r#"<svg y="{y}" width="{W}" height="{h}" viewBox="0 0 {W} {h}">{body}</svg>"#
        );
        y += h;
    }
    if y == 0.0 {
        return None;
    }
    Some(format!(
        r##"<svg xmlns="http://www.w3.org/2000/svg" class="plot" viewBox="0 0 {W} {y}" width="{W}" height="{y}" role="img" aria-label="{t}" font-family="sans-serif" font-size="11"><title>{t}</title><rect width="100%" height="100%" fill="#fff"/>{inner}</svg>"##,
        t = esc(title)
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn series(points: Vec<(f64, f64)>) -> Series {
        Series {
            name: "a<b".into(),
            points,
            err: None,
            style: Style::Line,
            color: PALETTE[0].into(),
        }
    }

    #[test]
    fn empty_chart_draws_nothing() {
        let c = Chart {
            title: "t".into(),
            ..Chart::default()
        };
        assert!(c.to_svg().is_none());
    }

    #[test]
    fn svg_is_well_formed_and_escaped() {
        let c = Chart {
            title: "R & S".into(),
            series: vec![series(vec![(0.0, 1.0), (1.0, 2.0), (2.0, f64::NAN)])],
            ..Chart::default()
        };
        let svg = c.to_svg().unwrap();
        assert!(svg.starts_with("<svg") && svg.ends_with("</svg>"));
        assert!(svg.contains("R &amp; S") && svg.contains("a&lt;b"));
        assert!(!svg.contains("NaN"));
        // The NaN point is dropped: two vertices remain.
        let poly = svg
            .split("points=\"")
            .nth(1)
            .unwrap()
            .split('"')
            .next()
            .unwrap();
        assert_eq!(poly.split(' ').count(), 2);
    }
}
