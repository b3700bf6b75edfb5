//! Diff fixtures: `fixtures/diff/<case>/{old,new}.rcal`, checked by the real checker,
//! diffed, and snapshot in text and JSON. Cases named `reformat_*` or `params_resolved`
//! mean the same procedure and must show no semantic change.

use ratecal_audit::{self as audit, ChangeKind, DiffReport, render};
use ratecal_check::{CheckOptions, NoImports, check_text};
use std::path::Path;

fn load(path: &Path) -> (ratecal_plan::Plan, String) {
    let text = std::fs::read_to_string(path).unwrap();
    let name = path.display().to_string();
    let checked =
        check_text(&name, &text, &NoImports, &CheckOptions::default()).unwrap_or_else(|d| {
            panic!(
                "{name} does not check: {:?}",
                d.iter().map(|d| d.render()).collect::<Vec<_>>()
            )
        });
    (
        checked.plan,
        ratecal_grammar::canonical(&text).unwrap().sha256,
    )
}

fn report(case: &str) -> DiffReport {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/diff")
        .join(case);
    let (old, old_sha) = load(&dir.join("old.rcal"));
    let (new, new_sha) = load(&dir.join("new.rcal"));
    audit::diff_report(&old, &old_sha, &new, &new_sha)
}

fn cases() -> Vec<String> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/diff");
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

fn no_change_expected(case: &str) -> bool {
    case.starts_with("reformat_") || case == "params_resolved"
}

#[test]
fn every_fixture_snapshots_text_and_json() {
    for case in cases() {
        let r = report(&case);
        assert_eq!(
            r.changes.is_empty(),
            no_change_expected(&case),
            "{case}: {:#?}",
            r.changes
        );
        insta::assert_snapshot!(format!("{case}_text"), render::text(&r, false));
        insta::assert_snapshot!(format!("{case}_json"), render::json(&r));
    }
}

#[test]
fn reformatting_changes_the_text_not_the_meaning() {
    let r = report("reformat_only");
    assert_ne!(
        std::fs::read_to_string(
            Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("tests/fixtures/diff/reformat_only/old.rcal")
        )
        .unwrap(),
        std::fs::read_to_string(
            Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("tests/fixtures/diff/reformat_only/new.rcal")
        )
        .unwrap()
    );
    assert!(r.changes.is_empty());
}

/// What each case must contain, written from the edit made to the text, not from the output.
#[test]
fn each_case_reports_the_edit_it_made() {
    use ChangeKind::*;
    let expect: &[(&str, &str, ChangeKind)] = &[
        (
            "accept_loosened",
            "step gyro_scale / accept gyro.residual.std",
            Loosened,
        ),
        ("accept_within_abs", "accept accel.bias.y", Loosened),
        ("accept_within_abs", "accept abs(accel.scale.x)", Tightened),
        ("accept_within_abs", "accept norm(accel.bias)", Changed),
        (
            "accept_tightened",
            "step accel_static / accept accel.residual.std",
            Tightened,
        ),
        (
            "param_changed",
            "step accel_static / accept accel.residual.std",
            Loosened,
        ),
        ("requirements_changed", "requires imu.warm_up", Loosened),
        (
            "requirements_changed",
            "requires table.position_accuracy",
            Tightened,
        ),
        ("requirements_changed", "requires table.levelness", Removed),
        (
            "environment_changed",
            "environment temperature / max",
            Loosened,
        ),
        (
            "environment_changed",
            "environment temperature / min",
            Loosened,
        ),
        ("environment_changed", "environment humidity", Removed),
        ("abort_removed", "abort when imu abnormal", Removed),
        (
            "abort_weakened",
            "abort when table.attitude_error > / limit",
            Loosened,
        ),
        (
            "abort_weakened",
            "abort when table.attitude_error > / persistence",
            Loosened,
        ),
        (
            "abort_weakened",
            "step gyro_bias / abort when ambient.temperature drifts / action",
            Loosened,
        ),
        (
            "abort_added",
            "step gyro_scale / abort when table.rate_error >",
            Added,
        ),
        ("step_added", "step warm_check", Added),
        ("step_removed", "step warm_check", Removed),
        ("step_moved", "step verification", Moved),
        (
            "attitude_added",
            "step accel_static / attitude pitch 45 deg, roll 45 deg",
            Added,
        ),
        (
            "attitude_removed",
            "step accel_static / attitude pitch 45 deg, roll 45 deg",
            Removed,
        ),
        (
            "rate_point_added",
            "step gyro_scale / rate point inner 150 deg/s",
            Added,
        ),
        // One edit of a `for` list is one change to the list, not one per axis and
        // acquisition.
        ("rate_list_edited", "step gyro_scale / rate points", Changed),
        (
            "rate_list_edited",
            "step gyro_scale / acquisitions renamed",
            Changed,
        ),
        (
            "settle_changed",
            "step accel_static / settle / fluctuation",
            Loosened,
        ),
        (
            "settle_changed",
            "step gyro_scale / settle / min time",
            Tightened,
        ),
        (
            "acquisition_changed",
            "step accel_static / acquire / duration",
            Changed,
        ),
        (
            "fit_changed",
            "step accel_static / fit accel_bias_scale / outliers",
            Changed,
        ),
        (
            "verify_added",
            "verify at pitch -30 deg, roll 60 deg",
            Added,
        ),
        (
            "verify_limit_loosened",
            "verify at inner 75 deg/s / accept gyro.error",
            Loosened,
        ),
        ("metadata_changed", "title", Changed),
        ("repeatability_changed", "accept repeatability.cv", Changed),
    ];
    for (case, path, kind) in expect {
        let r = report(case);
        assert!(
            r.changes.iter().any(|c| c.path == *path && c.kind == *kind),
            "{case}: expected {path} {kind:?} in {:#?}",
            r.changes
        );
        let alert =
            matches!(kind, Loosened) || (matches!(kind, Removed) && !path.contains("attitude"));
        if alert {
            assert!(
                r.changes.iter().any(|c| c.path == *path && c.alert),
                "{case}: {path} must stand out"
            );
        }
    }
}

/// One edited rate list (100 deg/s made 150 deg/s, on both axes) reads as that edit: the
/// list, the acquisitions it renames and the duration, not a removal and an addition per
/// axis and per acquisition.
#[test]
fn an_edited_rate_list_is_one_change_of_the_list() {
    let r = report("rate_list_edited");
    let paths: Vec<&str> = r.changes.iter().map(|c| c.path.as_str()).collect();
    assert_eq!(
        paths,
        [
            "step gyro_scale / rate points",
            "step gyro_scale / acquisitions renamed",
            "estimated duration"
        ],
        "{:#?}",
        r.changes
    );
    let list = &r.changes[0];
    assert_eq!(
        list.new.as_deref(),
        Some("outer -100, -50, 0, 50, 150 deg/s; inner -100, -50, 0, 50, 150 deg/s")
    );
    let (old, new) = (&r.changes[2].old, &r.changes[2].new);
    assert_ne!(old, new, "a duration change that prints as none");
}
