//! A broken lab template is a located diagnostic (file, line, span, help), snapshotted as
//! users see it; never a panic, never a blank report. Also: a lab's files override the
//! bundled ones by name, partials included.

use crate::render_common;
use miette::{GraphicalReportHandler, GraphicalTheme};
use ratecal_render::{Format, RenderError, Templates, render, render_template};
use render_common::{fixture, full};

fn shown(e: &RenderError) -> String {
    let mut out = String::new();
    GraphicalReportHandler::new_themed(GraphicalTheme::unicode_nocolor())
        .with_width(100)
        .render_report(&mut out, e)
        .unwrap();
    out
}

fn lab_error(file: &str) -> RenderError {
    let mut t = Templates::bundled();
    t.insert(
        file,
        fixture(&format!("errors/{file}")),
        format!("lab/{file}"),
    );
    render_template(&full(), &t, file).expect_err("the template is broken")
}

#[test]
fn err_fixtures_snapshot() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/report/errors");
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with("err_"))
        .collect();
    names.sort();
    assert!(names.len() >= 6);
    for name in names {
        let e = lab_error(&name);
        let text = shown(&e);
        assert!(
            text.contains(&format!("lab/{name}")),
            "{name}: the file is named\n{text}"
        );
        insta::assert_snapshot!(name.clone(), text);
    }
}

#[test]
fn errors_name_the_line() {
    for (file, line) in [
        ("err_syntax.md", 3),
        ("err_unknown_filter.md", 3),
        ("err_runtime.md", 3),
        ("err_missing_include.html", 3),
    ] {
        match lab_error(file) {
            RenderError::Template(t) => {
                assert_eq!(t.line, Some(line), "{file}");
                assert!(t.span.is_some(), "{file} has a span");
            }
            other => panic!("{file}: {other:?}"),
        }
    }
    assert!(matches!(
        lab_error("err_empty.md"),
        RenderError::Empty { .. }
    ));
}

#[test]
fn unknown_template_names_the_available_ones() {
    let e = render_template(&full(), &Templates::bundled(), "report.pdf").unwrap_err();
    let text = shown(&e);
    assert!(
        text.contains("report.pdf") && text.contains("report.html, report.md"),
        "{text}"
    );
}

#[test]
fn lab_files_override_bundled_ones_by_name() {
    let mut t = Templates::bundled();
    // Restyle only: the bundled HTML includes report.css, which the lab replaces.
    t.insert(
        "report.css",
        "body { color: #123456; }".into(),
        "lab/report.css".into(),
    );
    let html = render(&full(), &t, Format::Html).unwrap();
    assert!(html.contains("#123456") && !html.contains("font-variant-numeric"));
    // Replace a whole format.
    t.insert(
        "report.md",
        "Lab report for {{ imu.serial }}: {{ summary.verdict }}\n".into(),
        "lab/report.md".into(),
    );
    let md = render(&full(), &t, Format::Markdown).unwrap();
    assert_eq!(md, "Lab report for SN-00172: fail\n");
}

#[test]
fn html_autoescapes_values_but_not_plots() {
    let mut input = full();
    input.manifest.as_mut().unwrap()["imu"]["model"] =
        serde_json::json!("<script>alert(1)</script>");
    let html = render(&input, &Templates::bundled(), Format::Html).unwrap();
    assert!(!html.contains("<script>alert"));
    assert!(
        html.contains("&lt;script&gt;alert(1)&lt;&#x2f;script&gt;")
            || html.contains("&lt;script&gt;")
    );
    assert!(html.contains("<svg "));
}
