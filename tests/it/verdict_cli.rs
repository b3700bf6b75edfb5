//! Honest verdicts end to end: an aborted run says so (exit 4, results.json `aborted`, the
//! report's first lines) and analysing it later exits 3; a wrong procedure is not a pass;
//! run-time warnings reach the terminal and the report; a run that fails is recorded as
//! failed; a released version changed after release is refused; a closed pipe is no panic.

use crate::support;
use support::*;

use std::process::{Command, Stdio};

#[test]
fn an_aborted_run_is_aborted_in_results_report_and_later_analysis() {
    let tmp = tempfile::tempdir().unwrap();
    let station = format!(
        "{}/drivers/stations/faulty-table.yaml",
        env!("CARGO_MANIFEST_DIR")
    );
    let std = procedures("imu-2d-standard");
    let args = [
        "run",
        &std,
        "--station",
        &station,
        "--dry-run",
        "--out",
        "ft",
    ];
    let o = ratecal(&args, tmp.path());
    assert_eq!(code(&o), 4, "{}", text(&o));
    let dir = tmp.path().join("ft");
    let results = json(&dir.join("results.json"));
    assert_eq!(results["verdict"], "aborted");
    let report = std::fs::read_to_string(dir.join("report.md")).unwrap();
    let head: String = report.lines().take(12).collect::<Vec<_>>().join("\n");
    assert!(head.contains("Overall verdict: **ABORTED**"), "{head}");
    assert!(head.contains("ABORTED at t ="), "{head}");
    assert!(!report.contains("meet the standard**"), "{report}");
    assert!(dir.join("report.html").exists() && dir.join("seal.json").exists());

    let o = ratecal(&["analyze", "ft", "--procedure", &std], tmp.path());
    assert_eq!(code(&o), 3, "{}", text(&o));
    let out: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(out["verdict"], "aborted");
}

#[test]
fn a_run_analysed_with_the_wrong_procedure_is_incomplete() {
    let tmp = tempfile::tempdir().unwrap();
    let o = mini_run(tmp.path(), "r", &[]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    // MINI declares no acceptance check: nothing is judged (exit 0, never a pass).
    assert_eq!(
        json(&tmp.path().join("r/results.json"))["verdict"],
        "not_judged"
    );
    let std = procedures("imu-2d-standard");
    let o = ratecal(&["analyze", "r", "--procedure", &std], tmp.path());
    assert_eq!(code(&o), 3, "{}", text(&o));
    let out: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(out["verdict"], "incomplete");
}

#[test]
fn run_time_warnings_reach_the_terminal_and_the_report() {
    let tmp = tempfile::tempdir().unwrap();
    let o = mini_too_fast_run(tmp.path(), "r");
    let journal = std::fs::read_to_string(tmp.path().join("r/journal.jsonl")).unwrap();
    let rule = journal
        .lines()
        .map(|l| serde_json::from_str::<serde_json::Value>(l).unwrap())
        .find(|e| e["event"] == "warning")
        .and_then(|e| e["values"].as_str().map(String::from))
        .unwrap_or_else(|| panic!("no warning in the journal:\n{journal}"));
    assert!(rule.contains("200 Hz"), "{rule}");
    assert!(
        String::from_utf8_lossy(&o.stdout).contains(&rule),
        "{}",
        text(&o)
    );
    let report = std::fs::read_to_string(tmp.path().join("r/report.md")).unwrap();
    assert!(report.contains(&rule), "{rule} not in:\n{report}");
}

#[test]
fn a_run_that_fails_after_its_folder_exists_records_why() {
    let tmp = tempfile::tempdir().unwrap();
    // Nothing listens on the discard port: the table cannot be reached.
    let st = ratecal_drivers::DEFAULT_STATION_YAML.replacen(
        "driver: sim",
        "driver: { tcp: { address: \"127.0.0.1:9\", timeout: 1 s } }",
        1,
    );
    std::fs::write(tmp.path().join("st.yaml"), st).unwrap();
    std::fs::write(tmp.path().join("p.rcal"), MINI).unwrap();
    let o = ratecal(
        &["run", "p.rcal", "--station", "st.yaml", "--out", "r"],
        tmp.path(),
    );
    assert_eq!(code(&o), 1, "{}", text(&o));
    let m = std::fs::read_to_string(tmp.path().join("r/manifest.yaml")).unwrap();
    assert!(m.contains("status: failed"), "{m}");
    assert!(m.contains("failure:"), "{m}");
}

#[test]
fn a_release_changed_after_release_is_refused_unless_allowed() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("mini");
    std::fs::create_dir_all(&dir).unwrap();
    let released = ratecal_grammar::canonical(MINI).unwrap().sha256;
    std::fs::write(dir.join("versions.lock"), format!("1.0.0 {released}\n")).unwrap();
    let edited = MINI.replace("timeout 60 s -> abort", "timeout 90 s -> abort");
    std::fs::write(dir.join("1.0.0.rcal"), edited).unwrap();

    let o = ratecal(&["check", "mini/1.0.0.rcal"], tmp.path());
    assert_eq!(code(&o), 1, "{}", text(&o));
    let err = text(&o);
    assert!(err.contains("check::changed_after_release"), "{err}");
    assert!(
        err.contains("procedure mini version 1.0.0"),
        "points at the version line: {err}"
    );
    assert!(err.contains("release a new version"), "{err}");
    let o = ratecal(&["check", "mini/1.0.0.rcal", "--allow-changed"], tmp.path());
    assert_eq!(code(&o), 0, "{}", text(&o));

    let o = ratecal(&["run", "mini", "--dry-run", "--out", "r"], tmp.path());
    assert_eq!(code(&o), 1, "{}", text(&o));
    assert!(!tmp.path().join("r").exists());
    let o = ratecal(
        &["run", "mini", "--dry-run", "--out", "r", "--allow-changed"],
        tmp.path(),
    );
    assert_eq!(code(&o), 0, "{}", text(&o));
    let m = std::fs::read_to_string(tmp.path().join("r/manifest.yaml")).unwrap();
    assert!(m.contains("changed_after_release:"), "{m}");
    let report = std::fs::read_to_string(tmp.path().join("r/report.md")).unwrap();
    assert!(report.contains("--allow-changed"), "{report}");

    let o = ratecal(&["analyze", "r", "--procedure", "mini"], tmp.path());
    assert_eq!(code(&o), 1, "{}", text(&o));
    let o = ratecal(
        &["analyze", "r", "--procedure", "mini", "--allow-changed"],
        tmp.path(),
    );
    assert_eq!(code(&o), 0, "{}", text(&o));
}

#[test]
fn a_closed_pipe_ends_quietly() {
    let std = procedures("imu-2d-standard");
    for args in [vec!["log", std.as_str()], vec!["check", std.as_str()]] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_ratecal"))
            .args(&args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        // The reader goes away before anything is written (`| head -0`).
        drop(child.stdout.take());
        let out = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(0), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
}
