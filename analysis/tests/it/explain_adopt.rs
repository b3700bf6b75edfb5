//! Explain's adoption diff against real procedure files: it applies with `patch -p0` and
//! `git apply -p0`, the result checks, and the audit diff names the added effects. A
//! released version is copied to the next minor version (never edited in place); a loose
//! file is edited in place.

use ratecal_analysis::explain::{AdoptTarget, adoption, next_version};
use ratecal_audit as audit;
use ratecal_check::{CheckOptions, NoImports, check_text};
use std::path::Path;
use std::process::Command;

const ROOT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/..");

fn bundled(name: &str) -> String {
    std::fs::read_to_string(format!("{ROOT}/procedures/imu-2d-standard/{name}")).unwrap()
}

/// Applies a diff in `dir` with `tool` (`patch` or `git`); `None` when the tool is absent.
fn apply(dir: &Path, tool: &str, diff: &str) -> Option<()> {
    let path = dir.join("adopt.diff");
    std::fs::write(&path, diff).unwrap();
    let out = match tool {
        "patch" => Command::new("patch")
            .args(["-p0", "-i", "adopt.diff"])
            .current_dir(dir)
            .output(),
        _ => Command::new("git")
            .args(["apply", "-p0", "adopt.diff"])
            .current_dir(dir)
            .output(),
    };
    let Ok(out) = out else {
        println!("skipped: {tool} not installed");
        return None;
    };
    assert!(
        out.status.success(),
        "{tool}: {}{}\n{diff}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    Some(())
}

fn plan(text: &str) -> ratecal_plan::Plan {
    let c = check_text("p.rcal", text, &NoImports, &CheckOptions::default())
        .unwrap_or_else(|d| panic!("{d:?}\n{text}"));
    assert!(c.warnings.is_empty(), "{:?}", c.warnings);
    c.plan
}

fn added_effects(old: &str, new: &str) -> Vec<(String, String)> {
    audit::diff(&plan(old), &plan(new))
        .into_iter()
        .filter(|c| c.path.ends_with("effects"))
        .map(|c| (c.path, c.new.unwrap_or_default()))
        .collect()
}

#[test]
fn a_released_version_goes_to_the_next_minor_version() {
    let lock = bundled("versions.lock");
    let siblings = [
        "1.0.0.rcal".to_string(),
        "1.1.0.rcal".into(),
        "versions.lock".into(),
    ];
    assert_eq!(
        next_version("1.0.0.rcal", &lock, &siblings).as_deref(),
        Some("1.2.0")
    );
    assert_eq!(
        next_version("1.1.0.rcal", &lock, &siblings).as_deref(),
        Some("1.2.0")
    );
    // A draft above the released ones is edited in place; so is a file outside a folder.
    assert_eq!(next_version("1.2.0.rcal", &lock, &siblings), None);
    assert_eq!(next_version("p.rcal", &lock, &siblings), None);
}

#[test]
fn the_diff_applies_and_the_new_version_declares_the_effects() {
    for tool in ["patch", "git"] {
        let tmp = tempfile::tempdir().unwrap();
        let folder = tmp.path().join("procedures/imu-2d-standard");
        std::fs::create_dir_all(&folder).unwrap();
        let old = bundled("1.1.0.rcal");
        std::fs::write(folder.join("1.1.0.rcal"), &old).unwrap();
        let target = AdoptTarget {
            path: "procedures/imu-2d-standard/1.1.0.rcal".into(),
            text: old.clone(),
            next: Some((
                "1.2.0".into(),
                "procedures/imu-2d-standard/1.2.0.rcal".into(),
            )),
        };
        let a = adoption(&target, &["lever_arm", "earth_rate", "time_offset"]).unwrap();
        assert!(a.not_placed.is_empty());
        let diff = a.diff.unwrap();
        assert!(diff.starts_with("diff --git procedures/imu-2d-standard/1.1.0.rcal procedures/imu-2d-standard/1.2.0.rcal\ncopy from "));
        assert!(diff.contains("-procedure imu-2d-standard version 1.1.0 {\n+procedure imu-2d-standard version 1.2.0 {\n"), "{diff}");
        assert!(
            diff.contains("+    fit accel bias_scale with lever_arm from accel_static/* {\n"),
            "{diff}"
        );
        assert!(diff.contains("+    fit gyro scale (x, y) with earth_rate, time_offset from gyro_scale/* using gyro_bias {\n"), "{diff}");
        if apply(tmp.path(), tool, &diff).is_none() {
            continue;
        }
        // The released file is untouched; the new version is the canonical old text plus
        // the declarations.
        assert_eq!(
            std::fs::read_to_string(folder.join("1.1.0.rcal")).unwrap(),
            old
        );
        let new = std::fs::read_to_string(folder.join("1.2.0.rcal")).unwrap();
        assert_eq!(ratecal_grammar::canonical(&new).unwrap().text, new);
        assert_eq!(
            added_effects(&old, &new),
            [
                (
                    "step accel_static / fit accel_bias_scale / effects".to_string(),
                    "lever_arm".to_string()
                ),
                (
                    "step gyro_scale / fit gyro_scale / effects".into(),
                    "earth_rate, time_offset".into()
                ),
            ]
        );
    }
}

#[test]
fn a_loose_file_is_edited_in_place_and_declared_effects_are_extended() {
    let old = bundled("1.1.0.rcal").replace(
        "fit gyro scale (x, y) from",
        "fit gyro scale (x, y) with earth_rate from",
    );
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("p.rcal"), &old).unwrap();
    let target = AdoptTarget {
        path: "p.rcal".into(),
        text: old.clone(),
        next: None,
    };
    // earth_rate is declared already; g_sensitivity joins it.
    let a = adoption(&target, &["earth_rate", "g_sensitivity"]).unwrap();
    let diff = a.diff.unwrap();
    assert!(diff.starts_with("--- p.rcal\n+++ p.rcal\n"), "{diff}");
    assert_eq!(diff.matches("\n+").count(), 2, "{diff}");
    if apply(tmp.path(), "patch", &diff).is_none() {
        return;
    }
    let new = std::fs::read_to_string(tmp.path().join("p.rcal")).unwrap();
    assert!(new.contains("fit gyro scale (x, y) with earth_rate, g_sensitivity from"));
    let changes = added_effects(&old, &new);
    assert_eq!(changes.len(), 1);
    assert!(changes[0].1.contains("g_sensitivity"), "{changes:?}");
    // Nothing new: no diff.
    let again = adoption(
        &AdoptTarget {
            text: new,
            ..target
        },
        &["g_sensitivity"],
    )
    .unwrap();
    assert_eq!(again.diff, None);
}

/// A finding significant only jointly, every value within 3u of zero (a lever arm of
/// 0.22 +- 0.08 mm on a station that has none), is not asked to be adopted; one value
/// beyond 3u, or a finding without estimated values, is.
#[test]
fn no_adoption_of_values_within_three_uncertainties_of_zero() {
    use ratecal_analysis::explain::{Finding, beyond_zero};
    let finding = |params: serde_json::Value| -> Finding {
        serde_json::from_value(serde_json::json!({
            "effect": "lever_arm", "explanation": "", "located": [], "parameters": params,
            "evidence": {
                "chi2": 12.0, "dof": 3, "p_value": 1e-5, "alpha": 1e-4,
                "holdout_rms_before": { "accel_mps2": 0.0, "gyro_dps": 0.0 },
                "holdout_rms_after": { "accel_mps2": 0.0, "gyro_dps": 0.0 },
                "not_separable_from": []
            },
            "rms_after": { "accel_mps2": 0.0, "gyro_dps": 0.0 }
        }))
        .unwrap()
    };
    let p = |v: f64, u: f64| serde_json::json!({ "value": v, "u": u, "unit": "mm" });
    let faint = finding(serde_json::json!({
        "rxx_mm": p(0.22, 0.08), "ryy_mm": p(0.20, 0.075), "rzz_mm": p(-0.25, 0.09),
        "rxy_mm": { "observable": false, "needs": "accelerate about Z" }
    }));
    assert!(!beyond_zero(&faint));
    let real = finding(serde_json::json!({ "rxx_mm": p(0.22, 0.08), "rzz_mm": p(-0.5, 0.09) }));
    assert!(beyond_zero(&real));
    assert!(beyond_zero(&finding(serde_json::json!({}))));
}
