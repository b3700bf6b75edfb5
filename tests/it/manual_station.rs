//! A manual station (issue 36): the dry runs of `imu-six-face` and `imu-multi-pose` on
//! `drivers/stations/manual.yaml` (the simulated operator, the simulator's IMU error model)
//! record the poses' attitudes and the hand turns, refuse a pose on the wrong face and ask
//! again, and end in a report like a rate-table run. A terminal session of the prompts runs
//! in a pseudo-terminal (util-linux `script`) on a manual station with a simulated IMU: real
//! prompts, real time, the run waiting for the IMU's rest.

use crate::support;
use ratecal_drivers::station::Station;
use ratecal_physics::Mat3;
use ratecal_physics::effects::ImuModel;
use ratecal_recording::{Attitude, Manifest, SegmentKind};
use std::path::Path;
use support::*;

fn manual_station() -> String {
    format!(
        "{}/drivers/stations/manual.yaml",
        env!("CARGO_MANIFEST_DIR")
    )
}

fn manifest(dir: &Path) -> Manifest {
    let text = std::fs::read_to_string(dir.join("manifest.yaml")).unwrap();
    ratecal_recording::parse_manifest("manifest.yaml", &text).unwrap()
}

fn dry_run(proc_name: &str, dir: &Path) -> String {
    let out = dir.join("run");
    let o = ratecal(
        &[
            "run",
            &procedures(proc_name),
            "--station",
            &manual_station(),
            "--dry-run",
            "--out",
            out.to_str().unwrap(),
        ],
        dir,
    );
    assert_eq!(code(&o), 0, "{}", text(&o));
    for f in ["report.md", "report.html", "results.json", "seal.json"] {
        assert!(out.join(f).exists(), "{f} missing\n{}", text(&o));
    }
    // The station's consumer IMU passes the procedure's acceptance checks.
    let r = json(&out.join("results.json"));
    assert_eq!(r["verdict"], "pass", "{}", r["acceptance"]);
    text(&o)
}

#[test]
fn six_face_dry_run_records_faces_and_turns_and_ends_in_a_report() {
    let tmp = tempfile::tempdir().unwrap();
    let said = dry_run("imu-six-face", tmp.path());
    let m = manifest(&tmp.path().join("run"));
    let kinds: Vec<(SegmentKind, &str)> =
        m.segments.iter().map(|s| (s.kind, s.id.as_str())).collect();
    let order = [
        "face/+x", "turn/+x", "face/-x", "face/+y", "turn/+y", "face/-y", "face/+z", "turn/+z",
        "face/-z",
    ];
    assert_eq!(kinds.iter().map(|k| k.1).collect::<Vec<_>>(), order);
    for s in &m.segments {
        match s.kind {
            SegmentKind::Static => {
                assert_eq!(s.attitude(), Attitude::Nominal, "{}", s.id);
                assert_eq!(s.tolerance_deg, Some(5.0));
                assert_eq!(s.up.as_deref(), s.id.strip_prefix("face/"));
            }
            SegmentKind::Turn => {
                assert_eq!(s.axis.as_deref(), s.id.strip_prefix("turn/"));
                assert_eq!(s.angle_deg, Some(360.0));
                assert!(s.t_end > s.t_start);
            }
            k => panic!("unexpected segment kind {k:?}"),
        }
    }
    // The simulated operator puts the second face asked for (-X) upside down once.
    assert!(said.contains("refused: gravity is on +X"), "{said}");
    assert_eq!(
        said.matches("Place the unit with -X up").count(),
        1,
        "{said}"
    );
    assert!(said.contains("place the unit with -X up again"), "{said}");
    let r = json(&tmp.path().join("run/results.json"));
    assert_eq!(r["manual"]["method"], "six_face", "{r}");
}

#[test]
fn multi_pose_dry_run_records_unknown_poses_between_free_turns() {
    let tmp = tempfile::tempdir().unwrap();
    let said = dry_run("imu-multi-pose", tmp.path());
    let m = manifest(&tmp.path().join("run"));
    let statics: Vec<_> = m
        .segments
        .iter()
        .filter(|s| s.kind == SegmentKind::Static)
        .collect();
    let turns: Vec<_> = m
        .segments
        .iter()
        .filter(|s| s.kind == SegmentKind::Turn)
        .collect();
    assert_eq!((statics.len(), turns.len()), (15, 14));
    assert!(statics.iter().all(|s| s.attitude() == Attitude::Unknown));
    assert!(statics[0].t_end - statics[0].t_start >= 30.0);
    assert!(
        turns
            .iter()
            .all(|t| t.axis.is_none() && t.angle_deg.is_none())
    );
    // Pose, turn, pose, ...: each turn between the rests around it.
    for (k, s) in m.segments.iter().enumerate() {
        let want = if k % 2 == 0 {
            SegmentKind::Static
        } else {
            SegmentKind::Turn
        };
        assert_eq!(s.kind, want, "{}", s.id);
        if k > 0 {
            assert!(s.t_start >= m.segments[k - 1].t_end - 1e-9, "{}", s.id);
        }
    }
    assert_eq!(said.matches("Turn the unit freely").count(), 14, "{said}");
    let r = json(&tmp.path().join("run/results.json"));
    assert_eq!(r["manual"]["method"], "multi_pose", "{r}");
    let (raw, cal) = (
        r["manual"]["gravity_rms_raw_mps2"].as_f64().unwrap(),
        r["manual"]["gravity_rms_calibrated_mps2"].as_f64().unwrap(),
    );
    assert!(cal < raw / 10.0, "{raw} -> {cal}");
}

/// A sensor's `K` (`accel`, `gyro`) from the station's model: 1 + its scale terms on the
/// diagonal, its misalignment terms (`xy_mrad`...) off it.
fn sensitivity(model: &ImuModel, sensor: &str) -> Mat3 {
    let mut k = Mat3::identity();
    let axis = |c: u8| usize::from(c - b'x');
    for t in &model.terms {
        let id = t.effect.id();
        if id == format!("{sensor}_scale") {
            for i in 0..3 {
                k[(i, i)] += t.values[i] * 1e-6;
            }
        } else if id == format!("{sensor}_misalignment") {
            for (p, v) in t.effect.params().iter().zip(&t.values) {
                let b = p.name.as_bytes();
                k[(axis(b[0]), axis(b[1]))] = v * 1e-3;
            }
        }
    }
    k
}

/// The rotation `Q` of `K_a = U Q` (`U` upper triangular; Gram-Schmidt from the last row
/// up): with unknown attitudes the fitted body frame is the accelerometers' own, so the
/// station's gyro matrix in that frame is `K_g Q^T`.
fn accel_frame(k_a: &Mat3) -> Mat3 {
    let mut q = Mat3::zeros();
    for i in (0..3).rev() {
        let mut r = k_a.row(i).into_owned();
        for j in i + 1..3 {
            let qj = q.row(j).into_owned();
            r -= qj * k_a.row(i).dot(&qj);
        }
        q.set_row(i, &(r / r.norm()));
    }
    q
}

/// The multi-pose dry run's gyro scales cover the station's truth within 3u, seed after
/// seed. (A turn segment once ended at the start of the settle window that found rest,
/// cutting off the end of the hand's move: every scale came out near 5000 ppm low, 3 to
/// 5 u off.)
#[test]
fn multi_pose_dry_runs_recover_the_station_gyro_scales_within_3u() {
    let yaml = std::fs::read_to_string(manual_station()).unwrap();
    let model = Station::from_yaml(&yaml, "manual.yaml")
        .unwrap()
        .imu_model();
    let k_g = sensitivity(&model, "gyro") * accel_frame(&sensitivity(&model, "accel")).transpose();
    for seed in ["1", "2", "3"] {
        let tmp = tempfile::tempdir().unwrap();
        let out = tmp.path().join("run");
        let args = [
            "run",
            &procedures("imu-multi-pose"),
            "--station",
            &manual_station(),
            "--dry-run",
            "--seed",
            seed,
            "--out",
            out.to_str().unwrap(),
        ];
        let o = ratecal(&args, tmp.path());
        assert_eq!(code(&o), 0, "{}", text(&o));
        let r = json(&out.join("results.json"));
        for (i, ax) in ["x", "y", "z"].iter().enumerate() {
            let p = &r["parameters"][format!("gyro.scale.{ax}")];
            let (v, u) = (p["value"].as_f64().unwrap(), p["u"].as_f64().unwrap());
            let truth = (k_g[(i, i)] - 1.0) * 1e6;
            println!(
                "seed {seed}: gyro.scale.{ax} {v:.0} +- {u:.0} ppm, station {truth:.0} ({:+.1} u)",
                (v - truth) / u
            );
            assert!(
                (v - truth).abs() <= 3.0 * u,
                "seed {seed} {ax}: {v} +- {u} vs {truth}"
            );
        }
    }
}

/// A unit outside the procedure's acceptance limits fails the run: exit 3, the failed
/// check named.
#[test]
fn a_manual_run_outside_the_acceptance_limits_fails_with_exit_3() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let station = std::fs::read_to_string(manual_station()).unwrap();
    let bad = station.replace(
        "gyro_bias: [0.8 deg/s, -1.1 deg/s, 0.5 deg/s]",
        "gyro_bias: [6 deg/s, -1.1 deg/s, 0.5 deg/s]",
    );
    assert_ne!(bad, station, "the station file's gyro_bias line changed");
    std::fs::write(dir.join("station.yaml"), bad).unwrap();
    let args = [
        "run",
        &procedures("imu-six-face"),
        "--station",
        "station.yaml",
        "--dry-run",
        "--out",
        "run",
    ];
    let o = ratecal(&args, dir);
    assert_eq!(code(&o), 3, "{}", text(&o));
    let r = json(&dir.join("run/results.json"));
    let failed: Vec<&str> = r["acceptance"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|a| a["verdict"] == "fail")
        .map(|a| a["name"].as_str().unwrap())
        .collect();
    assert_eq!(failed, ["norm(gyro.bias) <= 5 deg/s"], "{r}");
}

/// Two faces, the second one placed wrong once by the simulated hand, then a quarter turn.
const PTY_PROC: &str = r#"procedure pty-manual version 0.0.1 {
  step faces {
    place +z up within 10 deg
    settle {
      gyro fluctuation <= 0.5 deg/s over 0.5 s
      accel fluctuation <= 0.01 g over 0.5 s
      timeout 30 s
    }
    acquire accel, gyro for 1 s at 100 Hz as "face/+z"
    place -x up within 10 deg
    settle {
      gyro fluctuation <= 0.5 deg/s over 0.5 s
      accel fluctuation <= 0.01 g over 0.5 s
      timeout 30 s
    }
    acquire accel, gyro for 1 s at 100 Hz as "face/-x"
    turn about -x by 90 deg as "turn/-x"
    settle {
      gyro fluctuation <= 0.5 deg/s over 0.5 s
      accel fluctuation <= 0.01 g over 0.5 s
      timeout 30 s
    }
    acquire accel, gyro for 1 s at 100 Hz as "after"
  }
}
"#;

#[test]
fn the_prompts_in_a_terminal_wait_for_rest_and_refuse_a_wrong_face() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::write(dir.join("p.rcal"), PTY_PROC).unwrap();
    // A manual station whose IMU is simulated: the prompts are real, the hand simulated.
    let station = std::fs::read_to_string(manual_station()).unwrap().replace(
        "driver: { serial: { port: /dev/ttyUSB0, baud: 921600 } }",
        "driver: sim",
    );
    std::fs::write(dir.join("station.yaml"), station).unwrap();
    let cmd = format!(
        "{} run p.rcal --station station.yaml --out run",
        env!("CARGO_BIN_EXE_ratecal")
    );
    let t0 = std::time::Instant::now();
    let o = std::process::Command::new("script")
        .args(["-q", "-e", "-c", &cmd, "/dev/null"])
        .current_dir(dir)
        .stdin(std::process::Stdio::null())
        .output()
        .expect("util-linux `script` runs the binary in a pseudo-terminal");
    let screen = String::from_utf8_lossy(&o.stdout).replace('\r', "");
    let at = |s: &str| {
        screen
            .find(s)
            .unwrap_or_else(|| panic!("no `{s}` in\n{screen}"))
    };
    let first = at("Place the unit with +Z up on the fixture, then keep it still");
    let second = at("Place the unit with -X up on the fixture, then keep it still");
    let refused = at("refused: gravity is on +X");
    let turn = at("Turn the unit by 90 deg about -X, then put it down and keep it still");
    assert!(
        first < second && second < refused && refused < turn,
        "{screen}"
    );
    // Real time: the run waited for the simulated hand's moves and rests.
    assert!(t0.elapsed().as_secs_f64() > 8.0, "{:?}", t0.elapsed());
    let m = manifest(&dir.join("run"));
    let ids: Vec<&str> = m.segments.iter().map(|s| s.id.as_str()).collect();
    assert_eq!(ids, ["face/+z", "face/-x", "turn/-x", "after"], "{screen}");
    assert_eq!(m.segments[3].up.as_deref(), Some("-x"));
}
