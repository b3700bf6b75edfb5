//! The size-effect procedure end to end: `ratecal run procedures/size-effect --dry-run`
//! without `--station` runs on the embedded swaying station, and its coordinates, and those
//! of `ratecal analyze` on the same recording, match the station's lever arms; and
//! `ratecal analyze` of the independent `sway-independent` example matches its truth.

use crate::support::shared;
use std::process::Command;

/// The embedded swaying station's coordinates (drivers/stations/swaying.yaml), mm.
const TRUTH: [(&str, f64); 6] = [
    ("rxy", 4.1),
    ("rxz", -2.7),
    ("ryx", 3.3),
    ("ryz", 5.2),
    ("rzx", -6.1),
    ("rzy", 2.4),
];

fn check(results: &std::path::Path) {
    let text = std::fs::read_to_string(results).unwrap();
    let r: serde_json::Value = serde_json::from_str(&text).unwrap();
    for (name, want) in TRUTH {
        let p = &r["parameters"][format!("size_effect.{name}_mm")];
        let v = p["value"].as_f64().unwrap_or(f64::NAN);
        assert!((v - want).abs() < 0.3, "{name}: {v} mm vs {want} mm");
        assert!(p["u"].as_f64().unwrap() > 0.0);
    }
}

#[test]
fn dry_run_without_a_station_and_analyze_recover_the_coordinates() {
    let tmp = tempfile::tempdir().unwrap();
    let run = tmp.path().join("run");
    let o = Command::new(env!("CARGO_BIN_EXE_ratecal"))
        .args(["run", "procedures/size-effect", "--dry-run", "--out"])
        .arg(&run)
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    check(&run.join("results.json"));
    let out = tmp.path().join("results.json");
    let o = Command::new(env!("CARGO_BIN_EXE_ratecal"))
        .arg("analyze")
        .arg(&run)
        .args(["--procedure", "procedures/size-effect", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    check(&out);
}

#[test]
fn analyze_recovers_the_independent_sway_within_half_a_millimetre() {
    // X brought up by the inner axis at -87 deg, the reference centre off the table axes.
    let Some(dir) = shared::shared_example("sway-independent") else {
        return;
    };
    let truth: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("truth.json")).unwrap()).unwrap();
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("results.json");
    let o = Command::new(env!("CARGO_BIN_EXE_ratecal"))
        .arg("analyze")
        .arg(&dir)
        .args(["--procedure", "procedures/size-effect", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        matches!(o.status.code(), Some(0 | 3)),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    for (name, _) in TRUTH {
        let key = format!("{name}_mm");
        let want = truth["size_effect"][&key].as_f64().unwrap();
        let v = r["parameters"][format!("size_effect.{key}")]["value"]
            .as_f64()
            .unwrap_or(f64::NAN);
        assert!((v - want).abs() < 0.5, "{name}: {v} mm vs {want} mm");
    }
    // Three cycles, Z, X, Y up, each with its two periods' difference accounted for.
    let cycles = r["size_effect"]["cycles"].as_array().unwrap();
    let ups: Vec<&str> = cycles
        .iter()
        .map(|c| c["up_axis"].as_str().unwrap())
        .collect();
    assert_eq!(ups, ["z", "x", "y"]);
    for c in cycles {
        assert!(c["instrumental_mps2"].is_array(), "{c}");
        assert_eq!(c["segments"].as_array().unwrap().len(), 2);
    }
    assert!(r["size_effect"].get("left_out").is_none());
}
