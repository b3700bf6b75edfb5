//! `ratecal analyze` from the command line: exit codes and the results file.

use crate::support;
use std::process::Command;
use support::example;

fn analyze(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_ratecal"))
        .arg("analyze")
        .args(args)
        .output()
        .unwrap()
}

/// Results are written; a check this recording cannot evaluate makes the verdict
/// `incomplete`, which is not a pass (exit 3).
#[test]
fn writes_results_and_an_incomplete_verdict_exits_three() {
    let Some(ex) = example() else { return };
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("results.json");
    let o = analyze(&[
        ex.to_str().unwrap(),
        "--procedure",
        "procedures/imu-2d-standard",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(
        o.status.code(),
        Some(3),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out).unwrap()).unwrap();
    assert_eq!(v["format"], "ratecal-results/1");
    assert_eq!(v["verdict"], "incomplete");
    assert_eq!(
        v["parameters"]["gyro.scale.z"],
        serde_json::json!({ "observable": false })
    );
    for s in ["accel", "gyro"] {
        for w in ["bias", "scale"] {
            for a in ["x", "y", "z"] {
                assert!(v["parameters"].get(format!("{s}.{w}.{a}")).is_some());
            }
        }
    }
    assert!(
        v["acceptance"]
            .as_array()
            .unwrap()
            .iter()
            .any(|a| a["verdict"] == "not_evaluated")
    );
}

#[test]
fn input_and_usage_errors() {
    let tmp = tempfile::tempdir().unwrap();
    let o = analyze(&[tmp.path().to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("manifest.yaml"));
    assert_eq!(analyze(&[]).status.code(), Some(2));
}

/// A threshold the recording cannot meet: results are still written, the check says
/// fail, the exit code is 3; the procedure is identified by its canonical hash.
#[test]
fn failed_check_exits_three_and_names_the_procedure_hash() {
    let Some(ex) = example() else { return };
    let tmp = tempfile::tempdir().unwrap();
    let std_text = std::fs::read_to_string("procedures/imu-2d-standard/1.0.0.rcal").unwrap();
    let strict = std_text.replace(
        "accept gyro.residual.std <= 0.1 deg/s",
        "accept gyro.residual.std <= 0.000001 deg/s",
    );
    assert_ne!(strict, std_text, "the standard procedure's limit moved");
    let proc_file = tmp.path().join("strict.rcal");
    std::fs::write(&proc_file, &strict).unwrap();
    let out = tmp.path().join("results.json");
    let o = analyze(&[
        ex.to_str().unwrap(),
        "--procedure",
        proc_file.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(
        o.status.code(),
        Some(3),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out).unwrap()).unwrap();
    let fails: Vec<_> = v["acceptance"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|a| a["verdict"] == "fail")
        .collect();
    assert_eq!(fails.len(), 1, "{fails:?}");
    assert!(
        fails[0]["name"]
            .as_str()
            .unwrap()
            .contains("gyro.residual.std")
    );
    let want = ratecal_grammar::canonical(&strict).unwrap().sha256;
    assert_eq!(v["model"]["procedure"]["sha256"], want.as_str());
}

/// The IMU stream is read a window at a time: a bad cell deep inside a segment is still
/// refused, located at its line and column in imu.csv, with exit 1 and no results file.
#[test]
fn a_bad_cell_inside_a_segment_is_located() {
    let Some(ex) = example() else { return };
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("run");
    std::fs::create_dir(&dir).unwrap();
    for f in ["manifest.yaml", "imu.csv", "table.csv"] {
        std::fs::copy(ex.join(f), dir.join(f)).unwrap();
    }
    let imu = std::fs::read_to_string(dir.join("imu.csv")).unwrap();
    let mut lines: Vec<String> = imu.lines().map(String::from).collect();
    // A row in the middle of the recording (inside the long gyro block), its gy cell.
    let row = lines.len() / 2;
    let mut cells: Vec<&str> = lines[row].split(',').collect();
    cells[5] = "0.0.1";
    lines[row] = cells.join(",");
    std::fs::write(dir.join("imu.csv"), lines.join("\n") + "\n").unwrap();
    let out = tmp.path().join("results.json");
    let o = analyze(&[dir.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("imu.csv"), "{err}");
    assert!(err.contains(&format!(":{}:", row + 1)), "{err}");
    assert!(!out.exists());
}
