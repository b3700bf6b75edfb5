//! Physics explain discovered joins the twin: `ratecal explain RUN --twin STATION
//! --write-twin OUT.yaml` on the independent open-world examples (`../shared/examples/
//! open-*`, written by another implementation of the spec, with physics the registry does
//! not hold) writes the discovered form's draft `.effect` file beside OUT.yaml, references
//! it under `imu.user_effects` with the recording's values, and reports it as a change
//! (`from` 0, `parameter` `k_<channel>`). Explained again with the updated twin, the
//! recording is at the noise floor (exit 0); a dry run on the updated twin carries the
//! discovered physics (the simulator evaluates the draft).

use crate::support;
use std::path::Path;
use support::{code, ratecal, shared_example, text};

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// The default station at the examples' site (latitude 40 deg) with their white noise
/// (3e-3 m/s^2 and 5e-3 deg/s per sample at 100 Hz): its biases and scale factors are not
/// the example IMU's, so the twin needs those changed too.
fn open_twin() -> String {
    let mut s = ratecal_drivers::DEFAULT_STATION_YAML.to_string();
    for (a, b) in [
        ("latitude_deg: 55.70", "latitude_deg: 40.0"),
        ("gravity_mps2: 9.8156", "gravity_mps2: 9.80160"),
        ("2 ug/rtHz", "0.0003 m/s^2/rtHz"),
        ("0.0003 deg/s/rtHz", "0.0005 deg/s/rtHz"),
    ] {
        assert!(s.contains(a), "{a}");
        s = s.replace(a, b);
    }
    s
}

/// `explain REC --twin TWIN [extra]` in `dir`: exit code and JSON.
fn explain(dir: &Path, rec: &Path, twin: &str, extra: &[&str]) -> (i32, serde_json::Value) {
    let mut args = vec![
        "explain",
        rec.to_str().unwrap(),
        "--twin",
        twin,
        "--format",
        "json",
    ];
    args.extend_from_slice(extra);
    let o = ratecal(&args, dir);
    assert!(matches!(code(&o), 0 | 1), "{}", text(&o));
    (code(&o), serde_json::from_slice(&o.stdout).expect("JSON"))
}

/// The changes adding the discovered effect: `(effect, parameter, to, u, unit)`.
fn added(v: &serde_json::Value) -> Vec<(String, String, f64, f64, String)> {
    let s = |c: &serde_json::Value, k: &str| c[k].as_str().unwrap().to_string();
    v["twin"]["changes"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|c| c["effect"].as_str().unwrap().starts_with("discovered_"))
        .map(|c| {
            assert_eq!(c["from"].as_f64(), Some(0.0), "{c}");
            assert_eq!(c["added"].as_bool(), Some(true), "{c}");
            (
                s(c, "effect"),
                s(c, "parameter"),
                c["to"].as_f64().unwrap(),
                c["u"].as_f64().unwrap(),
                s(c, "unit"),
            )
        })
        .collect()
}

/// Writes the updated twin of `example` into `dir/upd/`, checks the draft beside it and
/// its reference, and returns the discovered changes.
fn update(dir: &Path, example: &Path) -> Vec<(String, String, f64, f64, String)> {
    std::fs::write(dir.join("twin.yaml"), open_twin()).unwrap();
    std::fs::create_dir_all(dir.join("upd")).unwrap();
    let (c, v) = explain(
        dir,
        example,
        "twin.yaml",
        &["--write-twin", "upd/updated.yaml"],
    );
    assert_eq!(c, 1, "{}", v["twin"]);
    let found = added(&v);
    assert!(!found.is_empty(), "no discovered change: {}", v["twin"]);
    let id = &found[0].0;
    let draft = dir.join("upd").join(format!("{id}.effect"));
    let effect = std::fs::read_to_string(&draft).expect("the draft beside the twin");
    assert!(effect.contains(&format!("effect {id} {{")), "{effect}");
    for ch in v["twin"]["changes"].as_array().unwrap() {
        if ch["effect"] == id.as_str() {
            assert!(
                ch["defined_in"]
                    .as_str()
                    .unwrap()
                    .ends_with(&format!("{id}.effect")),
                "{ch}"
            );
        }
    }
    let yaml = std::fs::read_to_string(dir.join("upd/updated.yaml")).unwrap();
    assert!(
        yaml.contains(&format!("{id}: {{ file: \"{id}.effect\"")),
        "{yaml}"
    );
    // Each value written where it stands, to the digits its uncertainty warrants.
    for (_, p, to, u, _) in &found {
        let at = yaml.find(&format!("{p}: ")).expect("written") + p.len() + 2;
        let num: String = yaml[at..]
            .chars()
            .take_while(|c| c.is_ascii_digit() || matches!(c, '-' | '.' | 'e'))
            .collect();
        let written: f64 = num.parse().unwrap();
        assert!((written - to).abs() <= *u, "{p}: {written} for {to} ± {u}");
    }
    // Explained again with the updated twin: at the noise floor, nothing to change.
    let (c, again) = explain(dir, example, "upd/updated.yaml", &[]);
    assert_eq!(c, 0, "{}", again["twin"]);
    let t = &again["twin"];
    for s in ["accel_mps2", "gyro_dps"] {
        let (rms, noise) = (
            t["before"]["rms"][s].as_f64().unwrap(),
            t["before"]["noise"][s].as_f64().unwrap(),
        );
        assert!(rms < 1.03 * noise, "{s}: {rms} against the noise {noise}");
    }
    found
}

#[test]
fn a_discovered_bias_step_joins_the_twin_as_its_draft_effect() {
    let Some(ex) = shared_example("open-accel-bias-step") else {
        return;
    };
    let tmp = tempfile::tempdir().unwrap();
    let found = update(tmp.path(), &ex);
    // truth.json: the x and y accelerometer biases jump by 4e-3 and -3e-3 m/s^2 at 1500 s
    // (in the draft's unit, ug of the site's gravity 9.8016 m/s^2: 408 and -306).
    let names: Vec<&str> = found.iter().map(|f| f.1.as_str()).collect();
    assert_eq!(names, ["k_ax", "k_ay"], "{found:?}");
    for ((.., to, u, unit), truth) in found.iter().zip([4e-3, -3e-3]) {
        assert_eq!(unit, "ug");
        let truth_ug = truth / 9.8016 * 1e6;
        assert!(
            (to - truth_ug).abs() < 3.0 * u,
            "{to} ± {u} against {truth_ug}"
        );
    }
}

#[test]
fn a_discovered_g_squared_sensitivity_is_simulated_on_the_updated_twin() {
    let Some(ex) = shared_example("open-gyro-g2") else {
        return;
    };
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let found = update(dir, &ex);
    // truth.json: k_i f_i^2 / g^2 with k = 0.006, -0.004, 0.005 deg/s per g^2.
    let names: Vec<&str> = found.iter().map(|f| f.1.as_str()).collect();
    assert_eq!(names, ["k_gx", "k_gy", "k_gz"], "{found:?}");
    for ((.., to, u, unit), truth) in found.iter().zip([0.006, -0.004, 0.005]) {
        assert_eq!(unit, "deg/h/g^2");
        let truth_dph = truth * 3600.0;
        assert!(
            (to - truth_dph).abs() < 3.0 * u,
            "{to} ± {u} against {truth_dph}"
        );
    }
    // A dry run on the updated twin: the simulator evaluates the draft, so the updated
    // twin predicts it to the noise, and the same twin without the draft does not.
    let proc_ = Path::new(ROOT).join("procedures/imu-2d-standard");
    let o = ratecal(
        &[
            "run",
            proc_.to_str().unwrap(),
            "--dry-run",
            "--station",
            "upd/updated.yaml",
            "--seed",
            "5",
            "--out",
            "dry",
        ],
        dir,
    );
    assert!(matches!(code(&o), 0 | 3), "{}", text(&o));
    let (c, v) = explain(dir, &dir.join("dry"), "upd/updated.yaml", &[]);
    assert_eq!(c, 0, "{}", v["twin"]);
    let yaml = std::fs::read_to_string(dir.join("upd/updated.yaml")).unwrap();
    let without: String = yaml
        .lines()
        .filter(|l| !l.contains("user_effects") && !l.contains("discovered_"))
        .map(|l| format!("{l}\n"))
        .collect();
    std::fs::write(dir.join("upd/without.yaml"), without).unwrap();
    let (c, v) = explain(dir, &dir.join("dry"), "upd/without.yaml", &[]);
    assert_eq!(c, 1, "{}", v["twin"]);
}

/// A warm-up (300 s) in a witness recording (a closed-form implementation of the spec)
/// joins the twin as its discovered decay: the draft written and referenced, the
/// amplitudes within 3u (plus 15 % for the grid's time constant) of the truth, and the
/// updated twin right (`update`).
#[test]
fn a_discovered_warm_up_joins_the_twin() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let (a, tau) = ([0.03, -0.02, 0.025], 300.0);
    let mut s = ratecal_witness::Scenario::standard("warm-up", 1).with(
        ratecal_witness::Hidden::GyroWarmUp {
            amplitude_dps: a,
            tau_s: tau,
        },
    );
    // A constant temperature: nothing thermal to mistake it for.
    s.thermal.rise_c = 0.0;
    let rec = dir.join("warm");
    ratecal_witness::write(&rec, &s).unwrap();
    let found = update(dir, &rec);
    let id = &found[0].0;
    let found_tau: f64 = id
        .rsplit("decay_")
        .next()
        .and_then(|r| r.strip_suffix('s'))
        .and_then(|r| r.parse().ok())
        .unwrap_or_else(|| panic!("a decay: {id}"));
    assert!((found_tau - tau).abs() < 0.15 * tau, "{found_tau} s");
    // Amplitudes at the expression's t0, deg/h.
    let draft = std::fs::read_to_string(dir.join("upd").join(format!("{id}.effect"))).unwrap();
    let t0: f64 = draft
        .split("(t_s - ")
        .nth(1)
        .and_then(|r| r.split(')').next())
        .and_then(|r| r.parse().ok())
        .unwrap_or_else(|| panic!("{draft}"));
    for (_, p, to, u, unit) in &found {
        assert_eq!(unit, "deg/h");
        let i = ["k_gx", "k_gy", "k_gz"]
            .iter()
            .position(|c| c == p)
            .unwrap();
        let truth = a[i] * 3600.0 * (-t0 / tau).exp();
        assert!(
            (to - truth).abs() <= 3.0 * u + 0.15 * truth.abs(),
            "{p}: {to} ± {u}, truth {truth}"
        );
    }
}
