//! Turns and attitudes in the manifest (spec/recording-format.md): `kind: turn` with a
//! signed body axis and its nominal angle, `attitude: feedback | nominal | unknown` with
//! `tolerance_deg` required with `nominal`, and an old recording's `up: oblique` read as
//! `attitude: unknown`.

use ratecal_recording::{Attitude, SegmentKind, read};
use std::fmt::Write as _;
use std::path::Path;

/// A small recording folder with `segments` (YAML lines) over 10 s of samples.
fn folder(dir: &Path, segments: &str) {
    let mut imu = String::from("t,ax,ay,az,gx,gy,gz\n");
    let mut table = String::from("t,outer,inner,outer_rate,inner_rate\n");
    for k in 0..=1000 {
        let t = k as f64 / 100.0;
        let _ = writeln!(imu, "{t},0,0,9.81,0,0,0");
        if k % 2 == 0 {
            let _ = writeln!(table, "{t},0,0,0,0");
        }
    }
    std::fs::write(dir.join("imu.csv"), imu).unwrap();
    std::fs::write(dir.join("table.csv"), table).unwrap();
    let m = format!(
        "format: ratecal-recording/1\nstation:\n  site: {{ latitude_deg: 45, gravity_mps2: 9.81 }}\n  table: {{ outer_axis: [0, -1, 0], inner_axis: [1, 0, 0] }}\nsegments:\n{segments}"
    );
    std::fs::write(dir.join("manifest.yaml"), m).unwrap();
}

#[test]
fn turns_and_attitudes_read_back() {
    let dir = tempfile::tempdir().unwrap();
    folder(
        dir.path(),
        "  - { id: a, kind: static, t_start: 0, t_end: 3, up: +x, attitude: nominal, tolerance_deg: 0.5 }\n\
         \x20 - { id: r, kind: turn, t_start: 3, t_end: 5, axis: -x, angle_deg: 360 }\n\
         \x20 - { id: b, kind: static, t_start: 5, t_end: 7, attitude: unknown }\n\
         \x20 - { id: f, kind: turn, t_start: 7, t_end: 8 }\n\
         \x20 - { id: c, kind: static, t_start: 8, t_end: 9, up: oblique }\n\
         \x20 - { id: d, kind: static, t_start: 9, t_end: 10 }\n",
    );
    let r = read(dir.path()).unwrap();
    let s = &r.manifest.segments;
    assert_eq!(s[0].attitude(), Attitude::Nominal);
    assert_eq!(s[0].tolerance_deg, Some(0.5));
    assert_eq!(s[1].kind, SegmentKind::Turn);
    assert_eq!(
        (s[1].axis.as_deref(), s[1].angle_deg),
        (Some("-x"), Some(360.0))
    );
    assert_eq!(s[2].attitude(), Attitude::Unknown);
    assert_eq!((s[3].axis.as_deref(), s[3].angle_deg), (None, None));
    // An old recording's oblique pose is a pose of unknown attitude.
    assert_eq!(s[4].attitude(), Attitude::Unknown);
    assert!(s[4].is_oblique());
    assert_eq!(s[5].attitude(), Attitude::Feedback);
    // Written back, the keys survive.
    let text = ratecal_recording::manifest_yaml(&r.manifest).unwrap();
    assert!(
        text.contains("attitude: nominal") && text.contains("tolerance_deg: 0.5"),
        "{text}"
    );
    assert!(
        text.contains("kind: turn") && text.contains("angle_deg: 360"),
        "{text}"
    );
}

#[test]
fn err_nominal_without_tolerance_is_located() {
    let dir = tempfile::tempdir().unwrap();
    folder(
        dir.path(),
        "  - { id: a, kind: static, t_start: 0, t_end: 3 }\n\
         \x20 - { id: face, kind: static, t_start: 4, t_end: 6, up: +z, attitude: nominal }\n",
    );
    let e = read(dir.path()).unwrap_err();
    let msg = e.to_string();
    assert!(msg.contains("manifest.yaml:7:"), "{msg}");
    assert!(
        msg.contains("`face`") && msg.contains("tolerance_deg"),
        "{msg}"
    );
    let help = miette::Diagnostic::help(&e)
        .map(|h| h.to_string())
        .unwrap_or_default();
    assert!(help.contains("tolerance_deg"), "{help}");
}

#[test]
fn err_unknown_attitude_word_is_located() {
    let dir = tempfile::tempdir().unwrap();
    folder(
        dir.path(),
        "  - { id: a, kind: static, t_start: 0, t_end: 3, attitude: guessed }\n",
    );
    let msg = read(dir.path()).unwrap_err().to_string();
    assert!(msg.contains("manifest.yaml:6:"), "{msg}");
}
