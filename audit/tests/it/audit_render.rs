//! The text an auditor signs and the stable JSON, for one revision of the standard plan.

use crate::audit_support;
use audit_support::*;
use ratecal_audit::{self as audit, render};
use ratecal_plan::*;

fn revision() -> (Plan, Plan) {
    let old = standard();
    let mut new = standard();
    new.version = "1.1.0".into();
    new.accepts[1].limit = q(0.15, "deg/s", Dim::Rate, 0.15);
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
    new.aborts.remove(1);
    new.requirements[0].limit = q(5.0, "arcsec", Dim::Angle, 5.0 / 3600.0);
    (old, new)
}

#[test]
fn text_and_json_of_a_revision() {
    let (old, new) = revision();
    let report = audit::diff_report(&old, &"a".repeat(64), &new, &"b".repeat(64));
    let text = render::text(&report, false);
    assert!(!text.contains('\x1b'), "no colour unless asked");
    insta::assert_snapshot!("revision_text", text);
    insta::assert_snapshot!("revision_json", render::json(&report));
    insta::assert_snapshot!("revision_summary", render::summary(&report.changes));
}

#[test]
fn no_change_reads_as_such() {
    let report = audit::diff_report(&standard(), &"a".repeat(64), &standard(), &"a".repeat(64));
    let text = render::text(&report, false);
    assert!(text.contains("No semantic change."), "{text}");
    let json: serde_json::Value = serde_json::from_str(&render::json(&report)).unwrap();
    assert_eq!(json["changes"], serde_json::json!([]));
    assert_eq!(json["old"]["version"], "1.0.0");
    assert_eq!(render::summary(&report.changes), "no semantic change");
}
