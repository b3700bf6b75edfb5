//! What the CLI tests share: running `ratecal`, a small procedure, station variants.

#![allow(dead_code)]

pub(crate) mod shared;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Two attitudes and one rate point: a dry run of it takes well under a second.
pub const MINI: &str = r#"procedure mini version 1.0.0 {
  title "Two attitudes and one rate"
  imu class tactical

  abort when table.attitude_error > 5 arcsec for 1 s
  abort when ambient.temperature outside 18 degC .. 22 degC for 2 s

  step statics "Two static attitudes" {
    for (n, pitch, roll) in [(1, 0 deg, 0 deg), (2, 90 deg, 0 deg)] {
      move to pitch pitch, roll roll
      settle {
        at least 5 s
        table.attitude_error <= 5 arcsec
        timeout 60 s -> abort
      }
      acquire accel, gyro, table for 10 s at 100 Hz as "accel_static/{n}"
    }
  }

  step rates "One rate point" {
    for axis in [outer] {
      for rate in [50] deg/s {
        spin axis at rate
        settle {
          at least 5 s
          table.rate_error <= 0.5 deg/s
          timeout 60 s -> abort
        }
        acquire gyro, table for 10 s at 100 Hz as "gyro_scale/{axis}/{rate:+}"
      }
      stop axis
    }
  }
}
"#;

/// A lab temperature excursion during MINI's rate step: the run aborts there.
pub const EXCURSION: &str = "faults: [ { temperature_excursion: { at: 36 s, delta: 4 degC, ramp: 1 s, duration: 600 s } } ]";

/// Runs `ratecal` in `cwd`.
pub fn ratecal(args: &[&str], cwd: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_ratecal"))
        .args(args)
        .current_dir(cwd)
        .output()
        .unwrap()
}

/// The exit code (-1 for a signal).
pub fn code(o: &Output) -> i32 {
    o.status.code().unwrap_or(-1)
}

/// Standard output and standard error, for assertion messages.
pub fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// The default station with `faults: []` replaced.
pub fn station_with(fault: &str) -> String {
    ratecal_drivers::DEFAULT_STATION_YAML.replace("faults: []", fault)
}

/// A JSON file of a run folder.
pub fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// The bundled procedures folder.
pub fn procedures(name: &str) -> String {
    format!("{}/procedures/{name}", env!("CARGO_MANIFEST_DIR"))
}

/// Writes MINI as `p.rcal` in `dir` and dry-runs it into `dir/out` (optionally more args).
pub fn mini_run(dir: &Path, out: &str, extra: &[&str]) -> Output {
    std::fs::write(dir.join("p.rcal"), MINI).unwrap();
    let mut args = vec!["run", "p.rcal", "--dry-run", "--out", out];
    args.extend_from_slice(extra);
    ratecal(&args, dir)
}

/// Dry-runs MINI into `dir/out` with its acquisition asking 200 Hz of the 100 Hz IMU: a
/// run-time warning.
pub fn mini_too_fast_run(dir: &Path, out: &str) -> Output {
    let fast = MINI.replace(
        "acquire gyro, table for 10 s at 100 Hz",
        "acquire gyro, table for 10 s at 200 Hz",
    );
    std::fs::write(dir.join("p.rcal"), fast).unwrap();
    ratecal(&["run", "p.rcal", "--dry-run", "--out", out], dir)
}

/// `../shared/examples/<name>`, or `None` with a "skipped" line when this machine lacks it.
pub fn shared_example(name: &str) -> Option<PathBuf> {
    shared::shared_example(name)
}

/// `../shared/<rel>`, or `None` with a "skipped" line when this machine lacks it.
pub fn shared_path(rel: &str) -> Option<PathBuf> {
    shared::shared_path(rel)
}

/// The shared lever-arm example recording (`../shared/examples/standard-with-lever-arm`),
/// or `None` with a "skipped" line when this machine lacks it.
pub fn example() -> Option<PathBuf> {
    shared::shared_example("standard-with-lever-arm")
}

/// The changes of `explain --twin --format json` (`twin.changes`), each as
/// (`effect.parameter`, from, to, u, added).
pub fn twin_changes(v: &serde_json::Value) -> Vec<(String, f64, f64, f64, bool)> {
    v["twin"]["changes"]
        .as_array()
        .expect("twin.changes")
        .iter()
        .map(|c| {
            (
                format!(
                    "{}.{}",
                    c["effect"].as_str().unwrap(),
                    c["parameter"].as_str().unwrap()
                ),
                c["from"].as_f64().unwrap(),
                c["to"].as_f64().unwrap(),
                c["u"].as_f64().unwrap(),
                c["added"].as_bool().unwrap(),
            )
        })
        .collect()
}

/// The path of an import map of `docs/examples/import/` (`ferraris.yaml`).
pub fn import_map(name: &str) -> String {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("docs/examples/import")
        .join(name);
    p.to_str().unwrap().to_string()
}

/// Imports `sources` with the example map `map` (`docs/examples/import/`) into `dir/run`;
/// the import must succeed.
pub fn import_to_run(dir: &Path, sources: &[PathBuf], map: &str) {
    let mut args = vec!["import".to_string()];
    args.extend(sources.iter().map(|p| p.display().to_string()));
    args.extend([
        "--map".into(),
        import_map(map),
        "--out".into(),
        "run".into(),
    ]);
    let a: Vec<&str> = args.iter().map(String::as_str).collect();
    let o = ratecal(&a, dir);
    assert_eq!(code(&o), 0, "{}", text(&o));
}

/// imu_tk's Xsens session in `../shared/real/imu_tk/` (accelerometer, gyro), if present.
pub fn xsens_session() -> Option<[PathBuf; 2]> {
    Some([
        shared_path("real/imu_tk/xsens_acc.mat")?,
        shared_path("real/imu_tk/xsens_gyro.mat")?,
    ])
}
