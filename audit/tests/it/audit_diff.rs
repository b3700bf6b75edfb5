//! Semantic diff over hand-built plans: each kind of change, its direction, its path.

use crate::audit_support;
use audit_support::*;
use ratecal_audit::{self as audit, Change, ChangeKind, render};
use ratecal_plan::*;

fn kinds(changes: &[Change]) -> Vec<(&str, ChangeKind)> {
    changes.iter().map(|c| (c.path.as_str(), c.kind)).collect()
}

#[test]
fn a_plan_has_no_change_with_itself() {
    assert!(audit::diff(&standard(), &standard()).is_empty());
}

#[test]
fn the_version_number_alone_is_no_change() {
    let mut new = standard();
    new.version = "1.0.1".into();
    assert!(audit::diff(&standard(), &new).is_empty());
}

#[test]
fn the_same_limit_in_other_units_is_no_change() {
    let mut new = standard();
    new.accepts[0].limit = q(2.0, "mg", Dim::Accel, 2.0 * G * 1e-3);
    new.requirements[1].limit = q(0.5, "h", Dim::Time, 0.5 * 3600.0);
    assert!(audit::diff(&standard(), &new).is_empty());
}

#[test]
fn raising_an_upper_acceptance_limit_loosens_it() {
    let mut new = standard();
    new.accepts[1].limit = q(0.15, "deg/s", Dim::Rate, 0.15);
    let c = audit::diff(&standard(), &new);
    assert_eq!(
        kinds(&c),
        vec![(
            "step gyro_scale / accept gyro.residual.std",
            ChangeKind::Loosened
        )]
    );
    assert!(c[0].alert);
    assert_eq!(c[0].old.as_deref(), Some("<= 0.1 deg/s"));
    assert_eq!(c[0].new.as_deref(), Some("<= 0.15 deg/s"));
}

#[test]
fn lowering_a_lower_limit_loosens_and_raising_tightens() {
    let mut new = standard();
    new.requirements[1].limit = q(10.0, "min", Dim::Time, 600.0);
    new.requirements[0].limit = q(5.0, "arcsec", Dim::Angle, 5.0 / 3600.0);
    let c = audit::diff(&standard(), &new);
    assert_eq!(
        kinds(&c),
        vec![
            ("requires table.position_accuracy", ChangeKind::Tightened),
            ("requires imu.warm_up", ChangeKind::Loosened)
        ]
    );
    assert!(!c[0].alert && c[1].alert);
}

#[test]
fn guard_banding_tightens_and_a_wider_band_loosens() {
    let mut new = standard();
    new.accepts[0].rule = DecisionRule::GuardBanded;
    new.environment[0].min = Some(q(15.0, "degC", Dim::Temperature, 15.0));
    let c = audit::diff(&standard(), &new);
    assert_eq!(
        kinds(&c),
        vec![
            ("environment temperature / min", ChangeKind::Loosened),
            (
                "step accel_static / accept accel.residual.std",
                ChangeKind::Tightened
            ),
        ]
    );
}

#[test]
fn added_verification_attitude() {
    let mut new = standard();
    new.verifications.push(Verification {
        point: VerifyPoint::Attitude {
            outer_deg: -30.0,
            inner_deg: 60.0,
        },
        limits: vec![accept(
            None,
            "accel.error",
            Cmp::Le,
            q(0.01, "g", Dim::Accel, 0.01 * G),
        )],
        segments: vec![],
    });
    let c = audit::diff(&standard(), &new);
    assert_eq!(
        kinds(&c),
        vec![("verify at pitch -30 deg, roll 60 deg", ChangeKind::Added)]
    );
    assert_eq!(c[0].new.as_deref(), Some("accel.error <= 0.01 g"));
}

#[test]
fn removed_and_weakened_abort_rules_stand_out() {
    let mut new = standard();
    new.aborts.remove(1);
    new.aborts[0].condition = AbortCondition::Above {
        signal: Signal::AttitudeError,
        limit: 10.0 / 3600.0,
    };
    new.steps[1].aborts[0].persistence_s = 0.0;
    new.steps[1].aborts[0].action = AbortAction::Warn;
    let c = audit::diff(&standard(), &new);
    assert_eq!(
        kinds(&c),
        vec![
            (
                "abort when table.attitude_error > / limit",
                ChangeKind::Loosened
            ),
            ("abort when imu abnormal", ChangeKind::Removed),
            (
                "step gyro_bias / abort when ambient.temperature drifts / action",
                ChangeKind::Loosened
            ),
        ]
    );
    assert!(c.iter().all(|c| c.alert));
    assert_eq!(c[0].old.as_deref(), Some("5 arcsec"));
    assert_eq!(c[0].new.as_deref(), Some("10 arcsec"));
    let text = render::summary(&c);
    assert!(
        text.contains("! WEAKENED abort when table.attitude_error > / limit"),
        "{text}"
    );
    assert!(text.contains("! REMOVED abort when imu abnormal"), "{text}");
}

#[test]
fn a_settle_change_everywhere_in_a_step_is_one_change() {
    let mut new = standard();
    for n in &mut new.steps[0].body {
        if let Node::Do(Action::Settle(s)) = n {
            s.stable[0].max_fluctuation = 0.002 * G;
        }
    }
    let c = audit::diff(&standard(), &new);
    assert_eq!(
        kinds(&c),
        vec![(
            "step accel_static / settle / fluctuation",
            ChangeKind::Loosened
        )]
    );
    assert_eq!(c[0].old.as_deref(), Some("0.001 g over 5 s"));
    assert_eq!(c[0].new.as_deref(), Some("0.002 g over 5 s"));
}

#[test]
fn a_settle_change_in_one_place_names_its_acquisition() {
    let mut new = standard();
    if let Node::Do(Action::Settle(s)) = &mut new.steps[0].body[4] {
        s.min_time_s = 60.0;
    }
    let c = audit::diff(&standard(), &new);
    assert_eq!(
        kinds(&c),
        vec![(
            "step accel_static / settle before accel_static/2 / min time",
            ChangeKind::Tightened
        )]
    );
    assert_eq!(
        (c[0].old.as_deref(), c[0].new.as_deref()),
        (Some("30 s"), Some("1 min"))
    );
}

#[test]
fn acquisition_parameters() {
    let mut new = standard();
    for n in &mut new.steps[2].body {
        if let Node::Do(Action::Acquire(a)) = n {
            a.duration_s = 20.0;
            a.rate_hz = 200.0;
        }
    }
    let c = audit::diff(&standard(), &new);
    assert_eq!(
        kinds(&c),
        vec![
            ("step gyro_scale / acquire / duration", ChangeKind::Changed),
            (
                "step gyro_scale / acquire / sample rate",
                ChangeKind::Changed
            ),
        ]
    );
}

#[test]
fn removed_attitude_and_added_rate_point() {
    let mut new = standard();
    new.steps[0].body.drain(9..12); // attitude 4: pitch -90
    new.steps[2] = gyro_scale(&[-100.0, -50.0, 0.0, 50.0, 100.0, 200.0]);
    let c = audit::diff(&standard(), &new);
    let k = kinds(&c);
    assert!(
        k.contains(&(
            "step accel_static / attitude pitch -90 deg, roll 0 deg",
            ChangeKind::Removed
        )),
        "{k:?}"
    );
    assert!(
        k.contains(&(
            "step accel_static / acquire accel_static/4",
            ChangeKind::Removed
        )),
        "{k:?}"
    );
    assert!(
        k.contains(&(
            "step gyro_scale / rate point outer 200 deg/s",
            ChangeKind::Added
        )),
        "{k:?}"
    );
    assert!(
        k.contains(&(
            "step gyro_scale / rate point inner 200 deg/s",
            ChangeKind::Added
        )),
        "{k:?}"
    );
    assert!(
        k.contains(&(
            "step gyro_scale / acquire gyro_scale/inner/+200",
            ChangeKind::Added
        )),
        "{k:?}"
    );
    // a settle that goes with its acquisition is not reported apart
    assert!(!k.iter().any(|(p, _)| p.contains("settle")), "{k:?}");
}

#[test]
fn reordered_steps_and_attitudes_are_moved() {
    let mut new = standard();
    new.steps.swap(1, 2);
    let c = audit::diff(&standard(), &new);
    assert_eq!(
        c.iter().filter(|c| c.kind == ChangeKind::Moved).count(),
        1,
        "{c:?}"
    );
    assert!(
        c.iter()
            .all(|c| c.kind == ChangeKind::Moved && c.path.starts_with("step gyro_")),
        "{c:?}"
    );

    let mut new = standard();
    let att5: Vec<Node> = new.steps[0].body.drain(12..15).collect();
    new.steps[0].body.splice(0..0, att5);
    let c = audit::diff(&standard(), &new);
    assert_eq!(
        kinds(&c),
        vec![(
            "step accel_static / attitude pitch 0 deg, roll 90 deg",
            ChangeKind::Moved
        )]
    );
    assert_eq!(
        (c[0].old.as_deref(), c[0].new.as_deref()),
        (Some("position 5"), Some("position 1"))
    );
}

#[test]
fn added_and_removed_steps_with_their_fits_and_limits() {
    let mut new = standard();
    let gone = new.steps.remove(2);
    new.estimated_duration_s -= gone.estimated_duration_s;
    new.fits.remove(2);
    new.accepts.remove(1);
    let c = audit::diff(&standard(), &new);
    assert_eq!(
        kinds(&c),
        vec![
            ("step gyro_scale", ChangeKind::Removed),
            ("step gyro_scale / fit gyro_scale", ChangeKind::Removed),
            (
                "step gyro_scale / accept gyro.residual.std",
                ChangeKind::Removed
            ),
            ("estimated duration", ChangeKind::Changed),
        ]
    );
    assert!(c[0].alert && c[2].alert);
    let back = audit::diff(&new, &standard());
    assert_eq!(back[0].kind, ChangeKind::Added);
}

#[test]
fn fit_parameters_and_metadata() {
    let mut new = standard();
    new.fits[0].outliers = Some(Outliers::Grubbs(0.05));
    new.fits[0].lowpass = Some((4, 10.0));
    new.title = "IMU 2D calibration".into();
    new.meta.insert("owner".into(), "metrology lab".into());
    let c = audit::diff(&standard(), &new);
    assert_eq!(
        kinds(&c),
        vec![
            ("title", ChangeKind::Changed),
            ("meta owner", ChangeKind::Added),
            (
                "step accel_static / fit accel_bias_scale / outliers",
                ChangeKind::Changed
            ),
            (
                "step accel_static / fit accel_bias_scale / lowpass",
                ChangeKind::Changed
            ),
        ]
    );
    assert_eq!(c[2].new.as_deref(), Some("grubbs alpha 0.05"));
}

#[test]
fn a_difference_no_view_names_is_still_reported() {
    let mut new = standard();
    new.steps[2]
        .body
        .retain(|n| !matches!(n, Node::Do(Action::Stop { .. })));
    let c = audit::diff(&standard(), &new);
    assert_eq!(
        kinds(&c),
        vec![("step gyro_scale / body", ChangeKind::Changed)]
    );
}

#[test]
fn repeat_counts() {
    let mut old = standard();
    old.steps[1].body = vec![Node::Repeat {
        count: 3,
        var: Some("k".into()),
        body: old.steps[1].body.clone(),
    }];
    let mut new = old.clone();
    if let Node::Repeat { count, .. } = &mut new.steps[1].body[0] {
        *count = 5;
    }
    let c = audit::diff(&old, &new);
    assert_eq!(
        kinds(&c),
        vec![("step gyro_bias / repeat", ChangeKind::Changed)]
    );
    assert_eq!(
        (c[0].old.as_deref(), c[0].new.as_deref()),
        (Some("3 times"), Some("5 times"))
    );
}
