//! `ratecal explain RUN --twin STATION` when the samples' timing is off: a time offset and a
//! clock rate, which the simulator applies by re-timing the motion. A clock 50 ppm fast is
//! 0.2 s late after an hour; a first-order column cannot carry that, so the comparison
//! evaluates the signals at the twin's timing and, when the recording's differs, again at
//! the corrected one.
//!
//! Plain `explain` does the same with the timing it finds.
//!
//! Two recordings the twin's code path did not make: one written by `ratecal-witness` (a
//! second, closed-form implementation of the spec), and a dry run on a station file with
//! the timing that the twin lacks.

use crate::support;
use ratecal_witness::{Hidden, Scenario};
use serde_json::Value;
use std::path::Path;
use support::{code, ratecal, text, twin_changes};

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// `explain REC --twin TWIN [extra] --format json`: exit code and JSON.
fn explain(dir: &Path, rec: &str, twin: &str, extra: &[&str]) -> (i32, Value) {
    let mut args = vec!["explain", rec, "--twin", twin, "--format", "json"];
    args.extend_from_slice(extra);
    let o = ratecal(&args, dir);
    assert!(matches!(code(&o), 0 | 1), "{}", text(&o));
    let v = serde_json::from_slice(&o.stdout).unwrap_or_else(|e| panic!("{e}: {}", text(&o)));
    (code(&o), v)
}

/// The added timing within 3u of the truth, and nothing else added or discovered.
fn timing_found(v: &Value, tau_ms: f64, ppm: f64) {
    let c = twin_changes(v);
    let get = |name: &str| {
        c.iter()
            .find(|x| x.0 == name)
            .unwrap_or_else(|| panic!("{name} in {c:?}"))
    };
    for (name, truth) in [("time_offset.tau_ms", tau_ms), ("clock_rate.ppm", ppm)] {
        let (_, _, to, u, added) = get(name);
        assert!(*added, "{name}");
        assert!(
            (to - truth).abs() < 3.0 * u,
            "{name} = {to} ± {u}, truth {truth}"
        );
    }
    let others: Vec<_> = c
        .iter()
        .filter(|x| x.4 && !x.0.starts_with("time_offset") && !x.0.starts_with("clock_rate"))
        .collect();
    assert!(others.is_empty(), "added besides the timing: {others:?}");
    let discovered: Vec<&Value> = v["findings"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|f| f["discovered"].as_bool() == Some(true))
        .collect();
    assert!(discovered.is_empty(), "{discovered:?}");
}

/// Residual RMS of the accelerometers against the noise, before and after.
fn accel_ratio(v: &Value, which: &str) -> f64 {
    let t = &v["twin"][which];
    t["rms"]["accel_mps2"].as_f64().unwrap() / t["noise"]["accel_mps2"].as_f64().unwrap()
}

#[test]
fn a_witness_recording_with_a_clock_rate_and_a_time_offset_against_a_twin_without() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let (tau_ms, ppm) = (4.0, 60.0);
    let s = Scenario::standard("timing", 11)
        .with(Hidden::ClockRate { ppm })
        .with(Hidden::TimeOffset { tau_ms });
    ratecal_witness::write(&dir.join("real"), &s).unwrap();
    // The witness's station and IMU (its truth), no timing.
    let twin = ratecal_drivers::DEFAULT_STATION_YAML
        .replace("latitude_deg: 55.70", "latitude_deg: 40.0")
        .replace("gravity_mps2: 9.8156", "gravity_mps2: 9.80160")
        .replace("2 ug/rtHz", "0.0003 m/s^2/rtHz")
        .replace("0.0003 deg/s/rtHz", "0.0005 deg/s/rtHz")
        .replace(
            "[1.2 mg, -0.8 mg, 2.1 mg]",
            "[-0.012 m/s^2, 0.027 m/s^2, -0.019 m/s^2]",
        )
        .replace(
            "[0.035 deg/s, -0.052 deg/s, 0.018 deg/s]",
            "[-0.042 deg/s, 0.061 deg/s, 0.025 deg/s]",
        )
        .replace(
            "[350 ppm, -220 ppm, 180 ppm]",
            "[-650 ppm, 930 ppm, 410 ppm]",
        )
        .replace(
            "[420 ppm, -310 ppm, 260 ppm]",
            "[-1200 ppm, 700 ppm, 1100 ppm]",
        );
    std::fs::write(dir.join("twin.yaml"), &twin).unwrap();
    let (c, v) = explain(dir, "real", "twin.yaml", &["--write-twin", "updated.yaml"]);
    assert_eq!(c, 1);
    timing_found(&v, tau_ms, ppm);
    // The twin without the timing was far off on the moving segments; the corrected one
    // predicts them to the noise.
    assert!(
        accel_ratio(&v, "before") > 20.0,
        "{}",
        accel_ratio(&v, "before")
    );
    assert!(
        accel_ratio(&v, "after") < 1.1,
        "{}",
        accel_ratio(&v, "after")
    );
    let written = std::fs::read_to_string(dir.join("updated.yaml")).unwrap();
    assert!(written.contains("clock_rate: { ppm: "), "{written}");
    assert!(written.contains("time_offset: { tau_ms: "), "{written}");
    // The corrected twin is right: nothing to change.
    let (c, v) = explain(dir, "real", "updated.yaml", &[]);
    assert_eq!(c, 0, "{}", v["twin"]["changes"]);
    // Plain explain (no twin) takes the timing it finds exactly too: both terms within 3u,
    // nothing discovered, nothing left unexplained.
    let o = ratecal(&["explain", "real", "--format", "json"], dir);
    assert_eq!(code(&o), 1, "{}", text(&o));
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    for (id, p, truth) in [
        ("time_offset", "tau_ms", tau_ms),
        ("clock_rate", "ppm", ppm),
    ] {
        let f = v["findings"]
            .as_array()
            .unwrap()
            .iter()
            .find(|f| f["effect"] == id)
            .unwrap_or_else(|| panic!("{id} in {}", v["findings"]));
        let (x, u) = (
            f["parameters"][p]["value"].as_f64().unwrap(),
            f["parameters"][p]["u"].as_f64().unwrap(),
        );
        assert!(
            (x - truth).abs() < 3.0 * u,
            "{id}.{p} = {x} ± {u}, truth {truth}"
        );
    }
    let found: Vec<&str> = v["findings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["effect"].as_str().unwrap())
        .collect();
    assert!(
        found.iter().all(|e| !e.starts_with("discovered")),
        "{found:?}"
    );
    assert_eq!(
        v["unexplained"].as_array().unwrap().len(),
        0,
        "{}",
        v["unexplained"]
    );
}

#[test]
fn a_dry_run_with_timing_against_its_own_station_and_a_twin_without() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let lever = Path::new(ROOT).join("drivers/stations/with-lever-arm.yaml");
    let without = std::fs::read_to_string(&lever).unwrap();
    let with = without.replace(
        "    lever_arm: {",
        "    time_offset: { tau_ms: 5 }\n    clock_rate: { ppm: 50 }\n    lever_arm: {",
    );
    assert_ne!(with, without);
    std::fs::write(dir.join("real.yaml"), &with).unwrap();
    std::fs::write(dir.join("without.yaml"), &without).unwrap();
    let proc_ = Path::new(ROOT).join("procedures/imu-2d-standard");
    let o = ratecal(
        &[
            "run",
            proc_.to_str().unwrap(),
            "--dry-run",
            "--station",
            "real.yaml",
            "--seed",
            "5",
            "--out",
            "real",
        ],
        dir,
    );
    assert!(matches!(code(&o), 0 | 3), "{}", text(&o));
    // Its own station file is a right twin: the timing is taken exactly, nothing changes.
    let (c, v) = explain(dir, "real", "real.yaml", &[]);
    assert_eq!(c, 0, "{}", v["twin"]["changes"]);
    assert!(
        accel_ratio(&v, "before") < 1.1,
        "{}",
        accel_ratio(&v, "before")
    );
    // Without the timing: found, and the corrected twin is right.
    let (c, v) = explain(
        dir,
        "real",
        "without.yaml",
        &["--write-twin", "updated.yaml"],
    );
    assert_eq!(c, 1);
    timing_found(&v, 5.0, 50.0);
    let (c, _) = explain(dir, "real", "updated.yaml", &[]);
    assert_eq!(c, 0);
}
