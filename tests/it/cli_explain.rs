//! `ratecal explain` from the command line, on the shared lever-arm recording: user effects
//! from files and folders, located errors in them, and the adoption diff that `patch -p0`
//! applies, after which `ratecal check` accepts the procedure and `ratecal diff` names the
//! effect.

use crate::support;
use std::path::Path;
use std::process::{Command, Output};
use support::{example, text};

fn ratecal(args: &[&str], cwd: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_ratecal"))
        .args(args)
        .env_remove("RATECAL_EFFECTS")
        .current_dir(cwd)
        .output()
        .unwrap()
}

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

#[test]
fn a_folder_of_effect_files_is_tried_like_the_registry() {
    let Some(ex) = example() else { return };
    let o = ratecal(
        &[
            "explain",
            ex.to_str().unwrap(),
            "--effects",
            "docs/examples/effects",
            "--without",
            "lever_arm",
            "--format",
            "json",
        ],
        Path::new(ROOT),
    );
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    // The Earth's rate is taken first when significant; the centripetal user effect next.
    let f = v["findings"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f["effect"] == "centripetal")
        .expect("the centripetal user effect is found");
    assert_eq!(f["defined_in"], "docs/examples/effects/centripetal.effect");
    // The recording's truth: rxx -4, ryy 14, rzz 25 mm.
    for (p, truth) in [("rxx_mm", -4.0), ("ryy_mm", 14.0), ("rzz_mm", 25.0)] {
        let (x, u) = (
            f["parameters"][p]["value"].as_f64().unwrap(),
            f["parameters"][p]["u"].as_f64().unwrap(),
        );
        assert!((x - truth).abs() < 3.0 * u, "{p} = {x} ± {u}");
    }
    let files: Vec<&str> = v["user_effects"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["effect"].as_str().unwrap())
        .collect();
    assert_eq!(files, ["accel_cross_xz", "centripetal"]);
    assert_eq!(v["adopt"], "with earth_rate");
}

#[test]
fn errors_in_effect_files_are_located_and_exit_two() {
    let Some(ex) = example() else { return };
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(
        tmp.path().join("bad.effect"),
        "effect bad {\n  explanation \"x\"\n  param a unit \"1\" needs \"m\"\n  gx += a * a * w_b.x\n}\n",
    )
    .unwrap();
    let o = ratecal(
        &["explain", ex.to_str().unwrap(), "--effects", "bad.effect"],
        tmp.path(),
    );
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("effect::not_linear"), "{err}");
    assert!(err.contains("[bad.effect:4:9]"), "{err}");
    assert!(err.contains("help:"), "{err}");
    assert!(o.stdout.is_empty());
}

#[test]
fn the_adoption_diff_applies_and_the_new_version_checks() {
    let Some(ex) = example() else { return };
    let tmp = tempfile::tempdir().unwrap();
    let folder = tmp.path().join("procedures/imu-2d-standard");
    std::fs::create_dir_all(&folder).unwrap();
    for f in ["1.0.0.rcal", "1.1.0.rcal", "versions.lock"] {
        std::fs::copy(
            format!("{ROOT}/procedures/imu-2d-standard/{f}"),
            folder.join(f),
        )
        .unwrap();
    }
    let args = [
        "explain",
        ex.to_str().unwrap(),
        "--procedure",
        "procedures/imu-2d-standard",
    ];
    let o = ratecal(&[&args[..], &["--format", "json"]].concat(), tmp.path());
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["adopt"], "with lever_arm");
    let diff = v["adopt_diff"].as_str().unwrap();
    // The text output carries the same diff.
    let t = ratecal(&args, tmp.path());
    assert!(String::from_utf8_lossy(&t.stdout).contains(diff));
    std::fs::write(tmp.path().join("adopt.diff"), diff).unwrap();
    let Ok(p) = Command::new("patch")
        .args(["-p0", "-i", "adopt.diff"])
        .current_dir(tmp.path())
        .output()
    else {
        println!("skipped: patch not installed");
        return;
    };
    assert!(p.status.success(), "{}", text(&p));
    // The folder stands for its newest release (1.1.0): the adopted draft is named.
    let c = ratecal(&["check", "procedures/imu-2d-standard@1.2.0"], tmp.path());
    assert_eq!(c.status.code(), Some(0), "{}", text(&c));
    assert!(String::from_utf8_lossy(&c.stdout).contains("imu-2d-standard 1.2.0: ok"));
    assert!(text(&c).contains("versions::unreleased"), "{}", text(&c));
    let d = ratecal(
        &[
            "diff",
            "procedures/imu-2d-standard@1.1.0",
            "procedures/imu-2d-standard@1.2.0",
        ],
        tmp.path(),
    );
    assert_eq!(d.status.code(), Some(1), "{}", text(&d));
    assert!(
        String::from_utf8_lossy(&d.stdout)
            .contains("step accel_static / fit accel_bias_scale / effects: none -> lever_arm"),
        "{}",
        text(&d)
    );
}

/// A run folder explained against the seed model: its own procedure already holds the
/// Earth's rate (every procedure's references hold it at the station's latitude), so
/// explain names it but does not ask to add it (issue 39: "add `with earth_rate`" where
/// results.json held `earth_rate (fixed)`).
#[test]
fn what_the_runs_procedure_holds_is_not_to_be_added() {
    let tmp = tempfile::tempdir().unwrap();
    let run = ratecal(
        &[
            "run",
            &support::procedures("imu-2d-standard"),
            "--dry-run",
            "--out",
            "run",
        ],
        tmp.path(),
    );
    assert_eq!(run.status.code(), Some(0), "{}", text(&run));
    let results = support::json(&tmp.path().join("run/results.json"));
    assert!(results.to_string().contains("earth_rate"), "{results}");
    let o = ratecal(&["explain", "run", "--format", "json"], tmp.path());
    // Found, but held by the run's procedure: nothing to add, so nothing to report (exit 0).
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(
        (v["findings"].as_array().unwrap().iter()).any(|f| f["effect"] == "earth_rate"),
        "{v}"
    );
    assert_eq!(v["already_held"], serde_json::json!(["earth_rate"]));
    assert!(
        !v["adopt"].as_str().unwrap_or("").contains("earth_rate"),
        "{}",
        v["adopt"]
    );
    let t = ratecal(&["explain", "run"], tmp.path());
    let out = String::from_utf8_lossy(&t.stdout);
    assert!(!out.contains("add `with earth_rate`"), "{out}");
    assert!(
        out.contains("already in the run's procedure (nothing to add): earth_rate"),
        "{out}"
    );
}
