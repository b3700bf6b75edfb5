//! `run --resume` of a manual run stopped mid-way (issue 36): the interruption left the unit
//! anywhere, so a resumed step that begins with a turn or an acquisition first asks the
//! operator for the last recorded pose again and waits for rest. A fixture's face is placed
//! again (and checked); a hand-held pose cannot be, and the turn after the interruption
//! joins no recorded pose: the gyro fit leaves it out instead of integrating a motion it
//! never saw.

use crate::support;
use ratecal_recording::{Attitude, Manifest, SegmentKind};
use std::path::Path;
use std::process::{Command, Output};
use support::*;

fn manual_station() -> String {
    format!(
        "{}/drivers/stations/manual.yaml",
        env!("CARGO_MANIFEST_DIR")
    )
}

/// A dry run of `proc_path` into `dir/run`, stopped abruptly after the `nth` checkpoint
/// (each recorded segment is one), then resumed; the resume's output.
fn crash_and_resume(proc_path: &str, nth: usize, dir: &Path) -> Output {
    let station = manual_station();
    let args = [
        "run",
        proc_path,
        "--station",
        &station,
        "--dry-run",
        "--out",
        "run",
    ];
    let o = Command::new(env!("CARGO_BIN_EXE_ratecal"))
        .args(args)
        .current_dir(dir)
        .env("RATECAL_CRASH_AT", format!("after-checkpoint#{nth}"))
        .output()
        .unwrap();
    assert_ne!(code(&o), 0, "the crash point was not reached\n{}", text(&o));
    ratecal(&["run", "--resume", "run"], dir)
}

fn manifest(dir: &Path) -> Manifest {
    let text = std::fs::read_to_string(dir.join("manifest.yaml")).unwrap();
    ratecal_recording::parse_manifest("manifest.yaml", &text).unwrap()
}

/// A face, then (a step of its own) a quarter turn about it and a pose after it.
const FACE_THEN_TURN: &str = r#"procedure resume-face version 0.0.1 {
  step face {
    place +z up within 5 deg
    settle {
      gyro fluctuation <= 0.5 deg/s over 1 s
      accel fluctuation <= 0.01 g over 1 s
      timeout 60 s
    }
    acquire accel, gyro for 2 s at 100 Hz as "face/+z"
  }
  step quarter {
    turn about +z by 90 deg as "turn/+z"
    settle {
      gyro fluctuation <= 0.5 deg/s over 1 s
      accel fluctuation <= 0.01 g over 1 s
      timeout 60 s
    }
    acquire accel, gyro for 2 s at 100 Hz as "after"
  }
}
"#;

#[test]
fn a_resumed_step_that_begins_with_a_turn_asks_for_the_last_face_again() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::write(dir.join("p.rcal"), FACE_THEN_TURN).unwrap();
    // The third checkpoint falls in step `quarter` (after turn/+z, or `after` when the run's
    // start counts none).
    let o = crash_and_resume("p.rcal", 3, dir);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let said = text(&o);
    let again = said
        .find("place the unit with +Z up on the fixture again (its last pose, face/+z)")
        .unwrap_or_else(|| panic!("no request for the last face in\n{said}"));
    let turn = said
        .find("Turn the unit by 90 deg about +Z")
        .unwrap_or_else(|| panic!("no turn in\n{said}"));
    assert!(again < turn, "{said}");
    let m = manifest(&dir.join("run"));
    let ids: Vec<&str> = m.segments.iter().map(|s| s.id.as_str()).collect();
    assert_eq!(ids, ["face/+z", "turn/+z", "after"]);
    // The pose after the turn is still the face asked for (nominal, +z up), as without
    // the interruption; the turn starts once the face is back, not before.
    let after = &m.segments[2];
    assert_eq!(after.attitude(), Attitude::Nominal);
    assert_eq!(after.up.as_deref(), Some("+z"));
    let resumed_t = m.run.as_ref().unwrap().resumes[0].t.unwrap();
    assert!(
        m.segments[1].t_start > resumed_t + 1.0,
        "{:?}",
        m.segments[1]
    );
}

#[test]
fn a_resumed_multi_pose_run_leaves_the_broken_turn_out_of_the_gyro_fit() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    // The fourth checkpoint falls in step `poses` (pose/00 is step `rest`'s only segment).
    let o = crash_and_resume(&procedures("imu-multi-pose"), 4, dir);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let said = text(&o);
    assert!(
        said.contains("the last pose (pose/00, held by hand) cannot be placed again"),
        "{said}"
    );
    let m = manifest(&dir.join("run"));
    let turns = m
        .segments
        .iter()
        .filter(|s| s.kind == SegmentKind::Turn)
        .count();
    assert_eq!(turns, 14);
    let r = json(&dir.join("run/results.json"));
    assert_eq!(r["verdict"], "pass", "{}", r["acceptance"]);
    let fitted: Vec<&str> = r["manual"]["turns"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t["segment"].as_str().unwrap())
        .collect();
    // turn/1 began after the interruption, from wherever the unit lay, not from pose/00.
    assert_eq!(fitted.len(), 13, "{fitted:?}");
    assert!(!fitted.contains(&"turn/1"), "{fitted:?}");
    let cal = r["manual"]["turn_rms_calibrated_deg"].as_f64().unwrap();
    assert!(cal < 0.1, "{cal} deg");
}
