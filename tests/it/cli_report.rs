//! `ratecal report` end to end on a copy of the shared example recording: exit codes 0, 1
//! and 2, `--out`, `--format`, a lab template directory and its located errors.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The shared example recording when this machine has it (streams included), else just
/// its manifest from the fixtures: a report needs results.json and the manifest only.
fn run_dir() -> tempfile::TempDir {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let fixtures = root.join("render/tests/fixtures/report");
    let example = PathBuf::from("/work/shared/examples/standard-with-lever-arm");
    let dir = tempfile::tempdir().unwrap();
    if example.is_dir() {
        for f in ["manifest.yaml", "imu.csv", "table.csv"] {
            std::fs::copy(example.join(f), dir.path().join(f)).unwrap();
        }
    } else {
        std::fs::copy(
            fixtures.join("manifest-external.yaml"),
            dir.path().join("manifest.yaml"),
        )
        .unwrap();
    }
    std::fs::copy(
        fixtures.join("results-external.json"),
        dir.path().join("results.json"),
    )
    .unwrap();
    dir
}

fn ratecal(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_ratecal"))
        .args(args)
        .output()
        .unwrap();
    let s = |b: &[u8]| String::from_utf8_lossy(b).into_owned();
    (
        out.status.code().unwrap_or(-1),
        s(&out.stdout),
        s(&out.stderr),
    )
}

#[test]
fn markdown_to_stdout_and_html_to_a_file() {
    let dir = run_dir();
    let d = dir.path().to_str().unwrap();
    let (code, md, _) = ratecal(&["report", d]);
    assert_eq!(code, 0);
    assert!(
        md.contains("# Calibration report: held-out tactical") && md.contains("## 6. Conclusions")
    );
    let out = dir.path().join("r.html");
    let (code, stdout, _) = ratecal(&[
        "report",
        d,
        "--format",
        "html",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0);
    assert!(stdout.is_empty());
    let html = std::fs::read_to_string(out).unwrap();
    // The streams' temp column gives the temperature plot besides the results' plots.
    let has_streams = dir.path().join("imu.csv").is_file();
    assert_eq!(
        html.contains("<title>Temperature over the run"),
        has_streams
    );
    assert!(html.contains("<title>Allan deviation"));
}

#[test]
fn input_errors_exit_1_usage_errors_exit_2() {
    let dir = run_dir();
    let d = dir.path().to_str().unwrap();
    let (code, _, err) = ratecal(&["report", "/nonexistent/run"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("not a folder"));
    std::fs::write(
        dir.path().join("results.json"),
        "{\n  \"parameters\": {,\n}",
    )
    .unwrap();
    let (code, _, err) = ratecal(&["report", d]);
    assert_eq!(code, 1);
    assert!(
        err.contains("results.json") && err.contains("line 2"),
        "{err}"
    );
    std::fs::remove_file(dir.path().join("results.json")).unwrap();
    let (code, _, err) = ratecal(&["report", d]);
    assert_eq!(code, 1);
    assert!(err.contains("ratecal analyze"), "{err}");
    let (code, _, _) = ratecal(&["report", d, "--format", "pdf"]);
    assert_eq!(code, 2);
}

#[test]
fn lab_template_directory_and_its_errors() {
    let dir = run_dir();
    let d = dir.path().to_str().unwrap();
    let lab = tempfile::tempdir().unwrap();
    std::fs::write(
        lab.path().join("report.md"),
        "Lab: {{ imu.serial }} {{ summary.verdict | verdict_label }}\n",
    )
    .unwrap();
    let (code, md, _) = ratecal(&["report", d, "--template", lab.path().to_str().unwrap()]);
    assert_eq!(code, 0);
    // A results file without a verdict (written before verdicts existed) is no pass.
    assert_eq!(md, "Lab: standard-with-lever-arm INCOMPLETE\n");
    // The lab overrode report.md only: HTML still comes from the bundled template.
    let (code, html, _) = ratecal(&[
        "report",
        d,
        "--template",
        lab.path().to_str().unwrap(),
        "--format",
        "html",
    ]);
    assert_eq!(code, 0);
    assert!(html.starts_with("<!DOCTYPE html>"));
    std::fs::write(
        lab.path().join("report.md"),
        "ok\n{% for x in calibration %}\n{{ x.bias.value | nope }}\n{% endfor %}\n",
    )
    .unwrap();
    let (code, out, err) = ratecal(&["report", d, "--template", lab.path().to_str().unwrap()]);
    assert_eq!(code, 1);
    assert!(out.is_empty(), "no partial report on stdout");
    assert!(
        err.contains("report.md") && err.contains("line 3") && err.contains("unknown filter"),
        "{err}"
    );
}
