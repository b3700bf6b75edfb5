//! The size-effect procedure 1.1.0 against station limits: a table that cannot reach the
//! 5 s, 90 deg sway is told so on the oscillate statement.

use ratecal_check::{CheckOptions, NoImports, StationLimits, check_text};
use ratecal_physics::Geometry;
use ratecal_plan::{Action, Node};

const SWAY: &str = include_str!("../../../procedures/size-effect/1.1.0.rcal");

fn station(max_accel: f64) -> CheckOptions {
    CheckOptions {
        station: Some(StationLimits {
            max_rate_dps: 500.0,
            max_accel_dps2: max_accel,
            gyro_range_dps: 400.0,
            accel_range_mps2: 16.0 * 9.80665,
            geometry: Geometry::vertical_outer(),
            manual: false,
            travel_deg: [None, None],
            imu_grade: String::new(),
        }),
    }
}

#[test]
fn a_slow_table_is_refused_on_the_short_period() {
    check_text("sway", SWAY, &NoImports, &station(300.0)).expect("within limits");
    // 90 deg * (2 pi / 5 s)^2 = 142.1 deg/s^2; the 10 s sway (35.5) passes.
    let diags = check_text("sway", SWAY, &NoImports, &station(100.0)).expect_err("too much");
    assert!(
        diags.iter().all(|d| d.code == "check::station_limit"),
        "{diags:?}"
    );
    assert_eq!(diags.len(), 1, "{diags:?}");
    assert!(
        diags[0].labels[0].1.contains("peak 142.1 deg/s^2"),
        "{:?}",
        diags[0].labels
    );
    assert!(diags[0].help.is_some(), "{diags:?}");
}

#[test]
fn three_cycles_of_two_periods_with_x_tilted() {
    let plan = check_text("sway", SWAY, &NoImports, &CheckOptions::default())
        .expect("checks")
        .plan;
    let mut periods = Vec::new();
    let mut remounts = 0;
    fn walk(nodes: &[Node], periods: &mut Vec<f64>, remounts: &mut usize) {
        for n in nodes {
            match n {
                Node::Do(Action::Oscillate {
                    period_s,
                    amplitude_deg,
                    ..
                }) => {
                    assert_eq!(*amplitude_deg, 90.0);
                    periods.push(*period_s);
                }
                Node::Do(Action::Remount { .. }) => *remounts += 1,
                _ => {}
            }
        }
    }
    walk(&plan.steps[0].body, &mut periods, &mut remounts);
    assert_eq!(remounts, 3);
    assert_eq!(periods, vec![5.0, 10.0, 5.0, 10.0, 5.0, 10.0]);
}
