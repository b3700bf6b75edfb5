//! `ratecal check` and `ratecal fmt` exit codes and outputs (spec/cli.md).

use std::process::Command;

fn ratecal(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_ratecal"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("run ratecal");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn check_bundled_procedures() {
    let (code, out, _) = ratecal(&[
        "check",
        "procedures/imu-2d-standard@1.0.0",
        "procedures/imu-2d-standard",
        "procedures/imu-2d-consumer@1.0.0",
        "procedures/size-effect/1.0.0.rcal",
    ]);
    assert_eq!(code, 0);
    assert!(
        out.contains("imu-2d-standard 1.0.0: ok, estimated duration 1 h 13 min"),
        "{out}"
    );
    // A folder stands for its newest version.
    assert!(out.contains("imu-2d-standard 1.1.0: ok"), "{out}");
    assert!(out.contains("imu-2d-consumer 1.0.0: ok"));
    assert!(out.contains("size-effect 1.0.0: ok"));
}

#[test]
fn check_errors_usage_and_missing_files() {
    let (code, _, err) = ratecal(&["check", "check/tests/fixtures/err_seed_attitude_4.rcal"]);
    assert_eq!(code, 1);
    assert!(
        err.contains("check::unobservable") && err.contains("err_seed_attitude_4.rcal:51:"),
        "{err}"
    );
    assert_eq!(ratecal(&["check"]).0, 2);
    assert_eq!(ratecal(&["check", "--no-such-flag", "x"]).0, 2);
    let (code, _, err) = ratecal(&["check", "procedures/imu-2d-standard@9.9.9"]);
    assert_eq!(code, 1);
    assert!(err.contains("versions: 1.0.0"), "{err}");
}

#[test]
fn check_with_a_station() {
    let (code, out, _) = ratecal(&[
        "check",
        "--station",
        "drivers/stations/default.yaml",
        "procedures/imu-2d-standard",
    ]);
    assert_eq!(code, 0, "{out}");
    let (code, _, err) = ratecal(&[
        "check",
        "--station",
        "drivers/stations/default.yaml",
        "procedures/size-effect",
    ]);
    assert_eq!(code, 1);
    assert!(err.contains("check::station_limit"));
}

#[test]
fn check_json_keeps_stdout_for_json() {
    let (code, out, _) = ratecal(&["check", "--format", "json", "procedures/imu-2d-standard"]);
    assert_eq!(code, 0);
    let v: serde_json::Value = serde_json::from_str(&out).expect("only JSON on stdout");
    assert_eq!(v[0]["name"], "imu-2d-standard");
}

#[test]
fn fmt_check_names_files_that_are_not_canonical() {
    assert_eq!(ratecal(&["fmt", "--check", "procedures"]).0, 0);
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("1.0.0.rcal");
    std::fs::write(&path, "procedure p version 1.0.0 {   title \"x\" }").expect("write");
    let p = path.to_string_lossy().into_owned();
    let (code, out, _) = ratecal(&["fmt", "--check", &p]);
    assert_eq!(code, 1);
    assert!(out.contains("1.0.0.rcal"));
    assert_eq!(ratecal(&["fmt", &p]).0, 0);
    assert_eq!(
        std::fs::read_to_string(&path).expect("read"),
        "procedure p version 1.0.0 {\n  title \"x\"\n}\n"
    );
    assert_eq!(ratecal(&["fmt", "--check", &p]).0, 0);
}
