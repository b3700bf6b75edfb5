//! The size-effect procedure end to end: `ratecal run procedures/size-effect --dry-run`
//! without `--station` runs on the embedded swaying station, and its coordinates, and those
//! of `ratecal analyze` on the same recording, match the station's lever arms.

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
        assert!((v - want).abs() < 0.5, "{name}: {v} mm vs {want} mm");
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
