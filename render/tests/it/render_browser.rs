//! End to end: the HTML report opened in headless Chromium (Debian's `chromium`) renders
//! its plots (inline `<svg>` elements laid out with a non-zero size) and logs no console
//! error. Without Chromium the test says "skipped: chromium not installed" and passes.

use crate::render_common;
use ratecal_render::{Format, Templates, render};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn chromium() -> Option<PathBuf> {
    let fixed = PathBuf::from("/usr/bin/chromium");
    if fixed.is_file() {
        return Some(fixed);
    }
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|d| d.join("chromium"))
        .find(|p| p.is_file())
}

/// Runs Chromium headless on `page` with `extra` flags; returns (stdout, stderr).
fn run(chrome: &Path, page: &Path, extra: &[&str]) -> (String, String) {
    let profile = tempfile::tempdir().unwrap();
    let out = tempfile::NamedTempFile::new().unwrap();
    let err = tempfile::NamedTempFile::new().unwrap();
    let mut child = Command::new(chrome)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--enable-logging=stderr",
            "--v=0",
        ])
        .arg(format!("--user-data-dir={}", profile.path().display()))
        .args(extra)
        .arg(format!("file://{}", page.display()))
        .stdin(Stdio::null())
        .stdout(out.reopen().unwrap())
        .stderr(err.reopen().unwrap())
        .spawn()
        .expect("chromium starts");
    let start = Instant::now();
    loop {
        if child.try_wait().unwrap().is_some() {
            break;
        }
        if start.elapsed() > Duration::from_secs(90) {
            let _ = child.kill();
            let _ = child.wait();
            panic!("chromium did not finish within 90 s");
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    (
        std::fs::read_to_string(out.path()).unwrap_or_default(),
        std::fs::read_to_string(err.path()).unwrap_or_default(),
    )
}

/// Page console output. Chromium logs every level (log, warning, error, uncaught
/// exception, failed resource load) as `INFO:CONSOLE` lines, so the levels cannot be told
/// apart here; the report has no script, so any console line at all is a fault.
fn console_errors(stderr: &str) -> Vec<&str> {
    stderr.lines().filter(|l| l.contains(":CONSOLE")).collect()
}

/// A probe appended to a copy of the report: after layout, write each plot's (each
/// outermost SVG's) rendered size into the DOM so `--dump-dom` shows it.
const PROBE: &str = r#"<script>
window.addEventListener('load', () => {
  const sizes = [...document.querySelectorAll('svg:not(svg svg)')].map(s => {
    const r = s.getBoundingClientRect();
    const marks = s.querySelectorAll('circle, polyline').length;
    return Math.round(r.width) + 'x' + Math.round(r.height) + ':' + marks;
  });
  const p = document.createElement('pre');
  p.id = 'probe';
  p.textContent = 'SVGS=' + sizes.join(',');
  document.body.appendChild(p);
});
</script>"#;

#[test]
fn html_report_renders_its_plots_without_console_errors() {
    let Some(chrome) = chromium() else {
        println!("skipped: chromium not installed");
        return;
    };
    let html = render(&render_common::full(), &Templates::bundled(), Format::Html).unwrap();
    let dir = tempfile::tempdir().unwrap();

    // The detector must see a console error when there is one.
    let bad = dir.path().join("bad.html");
    std::fs::write(
        &bad,
        "<html><body><script>console.error('boom'); undefinedFn();</script></body></html>",
    )
    .unwrap();
    let (_, stderr) = run(&chrome, &bad, &["--dump-dom"]);
    assert!(
        !console_errors(&stderr).is_empty(),
        "detector missed an error:\n{stderr}"
    );

    // The report itself, untouched: no console output at all.
    let page = dir.path().join("report.html");
    std::fs::write(&page, &html).unwrap();
    let (dom, stderr) = run(&chrome, &page, &["--dump-dom"]);
    assert!(
        console_errors(&stderr).is_empty(),
        "console errors:\n{stderr}"
    );
    // A figure of several panels nests one `<svg>` per panel in its own.
    assert_eq!(
        dom.matches("<svg xmlns").count(),
        6,
        "six inline plots in the DOM"
    );
    assert!(dom.contains("DRY RUN: NOT A CALIBRATION CERTIFICATE"));

    // Laid out: every plot has a real size and its marks.
    let probed = dir.path().join("probed.html");
    std::fs::write(&probed, html.replace("</body>", &format!("{PROBE}</body>"))).unwrap();
    let (dom, stderr) = run(&chrome, &probed, &["--dump-dom", "--window-size=1100,900"]);
    assert!(
        console_errors(&stderr).is_empty(),
        "console errors:\n{stderr}"
    );
    let line = dom
        .lines()
        .find(|l| l.contains("<pre id=\"probe\">SVGS="))
        .expect("probe ran");
    let sizes: Vec<&str> = line
        .split("SVGS=")
        .nth(1)
        .unwrap()
        .split('<')
        .next()
        .unwrap()
        .split(',')
        .collect();
    assert_eq!(sizes.len(), 6, "{line}");
    for s in sizes {
        let (wh, marks) = s.split_once(':').unwrap();
        let (w, h) = wh.split_once('x').unwrap();
        let (w, h, marks): (f64, f64, usize) = (
            w.parse().unwrap(),
            h.parse().unwrap(),
            marks.parse().unwrap(),
        );
        assert!(w >= 300.0 && h >= 200.0, "plot too small: {s}");
        assert!(marks > 0, "plot without marks: {s}");
    }

    // And a screenshot is produced (look at it by hand: REPORT_SCREENSHOT=path).
    let shot = std::env::var("REPORT_SCREENSHOT")
        .map(PathBuf::from)
        .unwrap_or_else(|_| dir.path().join("report.png"));
    run(
        &chrome,
        &page,
        &[
            &format!("--screenshot={}", shot.display()),
            "--window-size=1100,4000",
        ],
    );
    let png = std::fs::read(&shot).expect("screenshot written");
    assert!(png.starts_with(b"\x89PNG") && png.len() > 20_000);
}
