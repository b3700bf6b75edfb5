//! A trend for people (a table) and for plots (SVG, hand-written: a few lines and error bars
//! need no plotting library or fonts).

use super::{ParamTrend, Trend};
use crate::dates;
use ratecal_analysis::measured::format_measured;
use std::fmt::Write;

impl Trend {
    /// The table `archive trend` prints.
    pub fn text(&self) -> String {
        let mut s = format!(
            "serial {}: {} calibration(s); intervals at {:.0} % confidence (one-sided, k = {:.3})\n",
            self.serial,
            self.calibrations,
            self.confidence * 100.0,
            self.k
        );
        for p in &self.parameters {
            s.push('\n');
            s.push_str(&param_text(p));
        }
        s
    }

    /// One SVG panel per parameter: values with ±2u bars, the fitted drift line, the limit.
    pub fn svg(&self) -> String {
        let (w, panel_h) = (640.0, 220.0);
        let h = panel_h * self.parameters.len().max(1) as f64;
        let mut s = format!(
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" \
             viewBox=\"0 0 {w} {h}\" font-family=\"sans-serif\" font-size=\"11\">\n"
        );
        let _ = writeln!(
            s,
            "<title>ratecal archive trend: serial {}</title>",
            xml(&self.serial)
        );
        for (i, p) in self.parameters.iter().enumerate() {
            s.push_str(&panel(p, i as f64 * panel_h, w, panel_h));
        }
        s.push_str("</svg>\n");
        s
    }
}

fn param_text(p: &ParamTrend) -> String {
    let mut s = format!("{} [{}]\n", p.name, p.unit);
    for pt in &p.points {
        let _ = writeln!(
            s,
            "  {}  {}  run {}",
            pt.started.get(..10).unwrap_or(&pt.started),
            format_measured(pt.value, pt.u, &p.unit),
            pt.run
        );
    }
    match &p.drift {
        Some(d) => {
            let _ = writeln!(
                s,
                "  drift {}/year (Birge ratio {:.2})",
                format_measured(d.rate_per_year, d.u_rate_per_year, &p.unit),
                d.birge_ratio
            );
        }
        None => s.push_str("  drift undetermined\n"),
    }
    if let Some(l) = &p.limit {
        match (&p.recalibration_days, &p.recalibrate_by) {
            (Some(days), Some(by)) if *days <= 0.0 => {
                let _ = writeln!(
                    s,
                    "  limit {}: reached already (by {by}): recalibrate now",
                    l.text
                );
            }
            (Some(days), Some(by)) => {
                let _ = writeln!(
                    s,
                    "  limit {}: recalibrate within {days:.0} days (by {by})",
                    l.text
                );
            }
            _ => {
                let _ = writeln!(s, "  limit {}", l.text);
            }
        }
    }
    for n in &p.notes {
        let _ = writeln!(s, "  note: {n}");
    }
    s
}

fn panel(p: &ParamTrend, top: f64, w: f64, h: f64) -> String {
    let (left, right, pad) = (70.0, 20.0, 24.0);
    let mut s = String::new();
    let _ = writeln!(
        s,
        "<text x=\"{left}\" y=\"{:.1}\">{} [{}]</text>",
        top + 14.0,
        xml(&p.name),
        xml(&p.unit)
    );
    let pts: Vec<(f64, f64, f64)> = p
        .points
        .iter()
        .filter_map(|q| Some((dates::days_from_iso(&q.started)?, q.value, q.u)))
        .collect();
    if pts.is_empty() {
        return s;
    }
    let (mut t0, mut t1) = (f64::MAX, f64::MIN);
    let (mut y0, mut y1) = (f64::MAX, f64::MIN);
    for &(t, v, u) in &pts {
        t0 = t0.min(t);
        t1 = t1.max(t);
        y0 = y0.min(v - 2.0 * u);
        y1 = y1.max(v + 2.0 * u);
    }
    if let Some(l) = &p.limit {
        y0 = y0.min(l.limit);
        y1 = y1.max(l.limit);
    }
    if t1 - t0 < 1.0 {
        t0 -= 1.0;
        t1 += 1.0;
    }
    if y1 - y0 <= 0.0 {
        y0 -= 1.0;
        y1 += 1.0;
    }
    let x = |t: f64| left + (t - t0) / (t1 - t0) * (w - left - right);
    let y = |v: f64| top + h - pad - (v - y0) / (y1 - y0) * (h - 2.0 * pad);
    let _ = writeln!(
        s,
        "<rect x=\"{left}\" y=\"{:.1}\" width=\"{:.1}\" height=\"{:.1}\" fill=\"none\" stroke=\"#999\"/>",
        top + pad,
        w - left - right,
        h - 2.0 * pad
    );
    let _ = writeln!(s, "<text x=\"4\" y=\"{:.1}\">{y1:.3e}</text>", y(y1) + 4.0);
    let _ = writeln!(s, "<text x=\"4\" y=\"{:.1}\">{y0:.3e}</text>", y(y0) + 4.0);
    let _ = writeln!(
        s,
        "<text x=\"{left}\" y=\"{:.1}\">{}</text><text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"end\">{}</text>",
        top + h - 6.0,
        dates::iso_date(t0),
        w - right,
        top + h - 6.0,
        dates::iso_date(t1)
    );
    for &(t, v, u) in &pts {
        let _ = writeln!(
            s,
            "<line x1=\"{0:.1}\" y1=\"{1:.1}\" x2=\"{0:.1}\" y2=\"{2:.1}\" stroke=\"#333\"/>\
             <circle cx=\"{0:.1}\" cy=\"{3:.1}\" r=\"3\" fill=\"#1f77b4\"/>",
            x(t),
            y(v - 2.0 * u),
            y(v + 2.0 * u),
            y(v)
        );
    }
    if let Some(d) = &p.drift {
        let _ = writeln!(
            s,
            "<line class=\"drift\" x1=\"{:.1}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke=\"#d62728\"/>",
            x(t0),
            y(d.at(t0)),
            x(t1),
            y(d.at(t1))
        );
    }
    if let Some(l) = &p.limit {
        let _ = writeln!(
            s,
            "<line class=\"limit\" x1=\"{left}\" y1=\"{0:.1}\" x2=\"{1:.1}\" y2=\"{0:.1}\" stroke=\"#ff7f0e\" stroke-dasharray=\"4 3\"/>",
            y(l.limit),
            w - right
        );
    }
    s
}

fn xml(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}
