//! The manual station's statements against a station: `place` needs a manual station,
//! `move` a rate table; the diagnostics are located and carry a help line.

use ratecal_check::{CheckOptions, NoImports, StationLimits, check_text};
use ratecal_physics::Geometry;
use ratecal_plan::{Action, Node};

fn opts(manual: bool) -> CheckOptions {
    CheckOptions {
        station: Some(StationLimits {
            max_rate_dps: 500.0,
            max_accel_dps2: 200.0,
            gyro_range_dps: 400.0,
            accel_range_mps2: 16.0 * 9.80665,
            geometry: Geometry::seed(),
            manual,
            travel_deg: [None, None],
            imu_grade: String::new(),
        }),
    }
}

const PLACE: &str = "procedure p version 0.0.1 {\n  step s {\n    place +z up within 5 deg\n    settle {\n      gyro fluctuation <= 0.5 deg/s over 2 s\n    }\n    acquire accel for 5 s at 100 Hz as \"a\"\n  }\n}\n";
const MOVE: &str = "procedure p version 0.0.1 {\n  step s {\n    move to pitch 0 deg, roll 90 deg\n    settle for 5 s\n    acquire accel for 5 s at 100 Hz as \"a\"\n  }\n}\n";

fn refused(text: &str, manual: bool) -> String {
    let d = check_text("p.rcal", text, &NoImports, &opts(manual)).unwrap_err();
    assert!(d.iter().all(|d| d.line_col().is_some()), "{d:?}");
    d.iter().map(|d| d.render()).collect()
}

#[test]
fn place_needs_a_manual_station_and_move_a_table() {
    assert!(check_text("p.rcal", PLACE, &NoImports, &opts(true)).is_ok());
    assert!(check_text("p.rcal", MOVE, &NoImports, &opts(false)).is_ok());
    let r = refused(PLACE, false);
    assert!(
        r.contains("check::manual_station") && r.contains("needs a manual station"),
        "{r}"
    );
    assert!(r.contains("p.rcal:3:5") && r.contains("help:"), "{r}");
    let r = refused(MOVE, true);
    assert!(
        r.contains("a manual station has no rate table to move"),
        "{r}"
    );
    assert!(r.contains("p.rcal:3:5") && r.contains("help:"), "{r}");
}

#[test]
fn a_place_plans_the_pose_and_its_tolerance() {
    let c = check_text("p.rcal", PLACE, &NoImports, &opts(true)).unwrap();
    let pose = c.plan.steps[0].body.iter().find_map(|n| match n {
        Node::Do(Action::Place(p)) => Some(p.clone()),
        _ => None,
    });
    let pose = pose.expect("a place action");
    assert_eq!(
        (pose.up.as_deref(), pose.tolerance_deg),
        (Some("+z"), Some(5.0))
    );
    assert!(
        pose.message
            .contains("Place the unit with +Z up on the fixture")
    );
}
