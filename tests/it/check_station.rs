//! `ratecal check` knows the station (issue 39, item 3): the built-in station `run` would
//! use unless `--station`, named in its output; the IMU's range, the table's travel, the
//! settle before a static acquisition against the attitude aborts, and the IMU's class;
//! an abort states its values in the unit its limit was written in.

use crate::support::*;

/// A static acquisition after a move, watched by an attitude abort rule.
const STATIC: &str = r#"procedure statics version 1.0.0 {
  title "One static attitude"
  imu class tactical
  abort when table.attitude_error > 5 arcsec for 1 s

  step statics {
    move to pitch 90 deg, roll 0 deg
SETTLE
    acquire accel, gyro, table for 10 s at 100 Hz as "static"
  }
}
"#;

const SETTLED: &str = "    settle {\n      at least 5 s\n      table.attitude_error <= 5 arcsec\n      timeout 60 s -> abort\n    }";

fn check(dir: &std::path::Path, text: &str, extra: &[&str]) -> std::process::Output {
    std::fs::write(dir.join("p.rcal"), text).unwrap();
    let mut args = vec!["check", "p.rcal"];
    args.extend_from_slice(extra);
    ratecal(&args, dir)
}

#[test]
fn check_names_the_station_it_checked_on() {
    let tmp = tempfile::tempdir().unwrap();
    let o = check(tmp.path(), &STATIC.replace("SETTLE", SETTLED), &[]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert!(
        String::from_utf8_lossy(&o.stdout).contains("station: <default station> (built in"),
        "{}",
        text(&o)
    );
    let st = format!(
        "{}/drivers/stations/default.yaml",
        env!("CARGO_MANIFEST_DIR")
    );
    let o = check(
        tmp.path(),
        &STATIC.replace("SETTLE", SETTLED),
        &["--station", &st],
    );
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert!(text(&o).contains(&format!("station: {st}")), "{}", text(&o));
}

#[test]
fn a_rate_above_the_imu_range_is_refused_without_station() {
    let tmp = tempfile::tempdir().unwrap();
    // The default station's IMU measures up to 400 deg/s; its table turns at 500.
    let o = check(tmp.path(), &MINI.replace("[50] deg/s", "[450] deg/s"), &[]);
    assert_eq!(code(&o), 1, "{}", text(&o));
    assert!(
        text(&o).contains("check::station_limit") && text(&o).contains("gyro range"),
        "{}",
        text(&o)
    );
    assert!(
        text(&o).contains("checked on <default station>"),
        "{}",
        text(&o)
    );
}

#[test]
fn an_angle_beyond_the_stations_travel_is_refused_at_the_angle() {
    let tmp = tempfile::tempdir().unwrap();
    let station = ratecal_drivers::DEFAULT_STATION_YAML.replace(
        "  max_accel_dps2: 200\n",
        "  max_accel_dps2: 200\n  outer_travel: [-180 deg, 180 deg]\n  inner_travel: [-360 deg, 360 deg]\n",
    );
    std::fs::write(tmp.path().join("limited.yaml"), station).unwrap();
    let text_405 = STATIC
        .replace("SETTLE", SETTLED)
        .replace("pitch 90 deg", "pitch 405 deg");
    let o = check(tmp.path(), &text_405, &["--station", "limited.yaml"]);
    assert_eq!(code(&o), 1, "{}", text(&o));
    let t = text(&o);
    assert!(t.contains("check::station_limit"), "{t}");
    assert!(
        t.contains("beyond the travel of the table's outer axis"),
        "{t}"
    );
    assert!(t.contains("p.rcal:7:19"), "located at `405 deg`: {t}");
    assert!(t.contains("-180 deg .. 180 deg"), "{t}");
    // Within the travel: accepted; the default station states none.
    let o = check(
        tmp.path(),
        &STATIC.replace("SETTLE", SETTLED),
        &["--station", "limited.yaml"],
    );
    assert_eq!(code(&o), 0, "{}", text(&o));
    // A spin on an axis of limited travel cannot be run.
    let o = check(tmp.path(), MINI, &["--station", "limited.yaml"]);
    assert_eq!(code(&o), 1, "{}", text(&o));
    assert!(text(&o).contains("cannot spin"), "{}", text(&o));
}

#[test]
fn a_static_acquisition_needs_a_settle_within_the_attitude_abort() {
    let tmp = tempfile::tempdir().unwrap();
    let o = check(tmp.path(), &STATIC.replace("SETTLE\n", ""), &[]);
    assert_eq!(code(&o), 1, "{}", text(&o));
    let t = text(&o);
    assert!(t.contains("check::unsettled"), "{t}");
    assert!(t.contains("p.rcal:8:5"), "located at the acquisition: {t}");
    assert!(t.contains("> 5 arcsec for 1 s"), "{t}");
    // A settle looser than the abort rule cannot bring the table within it either.
    let loose = SETTLED.replace("<= 5 arcsec", "<= 60 arcsec");
    let o = check(tmp.path(), &STATIC.replace("SETTLE", &loose), &[]);
    assert_eq!(code(&o), 1, "{}", text(&o));
    assert!(
        text(&o).contains("cannot bring the table within"),
        "{}",
        text(&o)
    );
    // Without an attitude abort, nothing to hold it to.
    let free = STATIC
        .replace("SETTLE\n", "")
        .replace("  abort when table.attitude_error > 5 arcsec for 1 s\n", "");
    let o = check(tmp.path(), &free, &[]);
    assert_eq!(code(&o), 0, "{}", text(&o));
}

#[test]
fn an_imu_below_the_procedures_class_is_a_warning() {
    let tmp = tempfile::tempdir().unwrap();
    let nav = STATIC
        .replace("SETTLE", SETTLED)
        .replace("imu class tactical", "imu class navigation");
    let o = check(tmp.path(), &nav, &[]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let t = text(&o);
    assert!(t.contains("check::imu_class"), "{t}");
    assert!(
        t.contains("the procedure is for a navigation IMU; the station's IMU is tactical"),
        "{t}"
    );
    let o = check(tmp.path(), &STATIC.replace("SETTLE", SETTLED), &[]);
    assert!(!text(&o).contains("check::imu_class"), "{}", text(&o));
}

#[test]
fn an_abort_states_the_value_in_the_unit_of_its_limit() {
    let tmp = tempfile::tempdir().unwrap();
    let station = station_with(
        "faults: [ { table: { at: 8 s, axis: inner, mode: runaway, rate: 30 deg/s } } ]",
    );
    std::fs::write(tmp.path().join("runaway.yaml"), station).unwrap();
    let o = mini_run(tmp.path(), "out", &["--station", "runaway.yaml"]);
    assert_eq!(code(&o), 4, "{}", text(&o));
    let t = text(&o);
    assert!(t.contains("table.attitude_error (arcsec) = ["), "{t}");
    assert!(!t.contains("table.attitude_error (deg)"), "{t}");
}
