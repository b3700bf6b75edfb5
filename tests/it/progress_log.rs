//! Progress for pipes and logs (issue 39, item 5): with standard error not a terminal,
//! `ratecal run` says a line when each step starts and one per minute of run time within a
//! step, with wall time, run time and what it does; `--log-format json` makes each a JSON
//! object with stable keys.

use crate::support::*;

/// One step of two and a half minutes of acquisition: two lines within it.
const LONG: &str = r#"procedure long version 1.0.0 {
  title "A long static acquisition"
  step rest "At rest" {
    move to pitch 0 deg, roll 0 deg
    settle for 5 s
    acquire accel, gyro, table for 150 s at 100 Hz as "rest"
  }
  step tilt {
    move to pitch 90 deg, roll 0 deg
    settle for 5 s
    acquire accel, gyro, table for 10 s at 100 Hz as "tilt"
  }
}
"#;

#[test]
fn a_piped_run_says_each_step_and_each_minute() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("p.rcal"), LONG).unwrap();
    let o = ratecal(&["run", "p.rcal", "--dry-run", "--out", "r"], tmp.path());
    assert_eq!(code(&o), 0, "{}", text(&o));
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    let lines: Vec<&str> = err.lines().filter(|l| l.starts_with("[wall ")).collect();
    assert!(
        lines
            .iter()
            .any(|l| l.contains("| simulated 0:00:00") && l.contains("step 1 rest: started")),
        "{err}"
    );
    let within: Vec<&&str> = lines
        .iter()
        .filter(|l| l.contains("step 1 rest: running"))
        .collect();
    assert_eq!(
        within.len(),
        2,
        "one line per minute of the long step: {err}"
    );
    assert!(within[0].contains("simulated 0:01:0"), "{err}");
    assert!(
        lines.iter().any(|l| l.contains("step 2 tilt: started")),
        "{err}"
    );
    assert!(
        !lines.iter().any(|l| l.contains("step 2 tilt: running")),
        "a short step has no minute lines: {err}"
    );
}

#[test]
fn json_lines_carry_stable_keys() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("p.rcal"), LONG).unwrap();
    let o = ratecal(
        &[
            "run",
            "p.rcal",
            "--dry-run",
            "--out",
            "r",
            "--log-format",
            "json",
        ],
        tmp.path(),
    );
    assert_eq!(code(&o), 0, "{}", text(&o));
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    let events: Vec<serde_json::Value> = err
        .lines()
        .filter(|l| l.starts_with('{'))
        .map(|l| serde_json::from_str(l).expect("each progress line is one JSON object"))
        .collect();
    let kinds: Vec<&str> = events
        .iter()
        .filter_map(|e| e["event"].as_str())
        .filter(|k| *k != "message")
        .collect();
    assert_eq!(
        kinds,
        ["step", "progress", "progress", "step", "end"],
        "{err}"
    );
    let first = &events[0];
    for key in ["wall_s", "run_s", "estimated_s", "step_index"] {
        assert!(first[key].is_number(), "{key}: {first}");
    }
    assert_eq!(first["clock"], "simulated");
    assert_eq!(first["step"], "rest");
    assert!(
        events[1]["run_s"].as_f64().unwrap() >= 60.0,
        "{}",
        events[1]
    );
}
