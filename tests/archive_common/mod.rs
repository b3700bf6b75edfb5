//! Shared by the archive tests: run folders as `ratecal run` leaves them (written directly,
//! hashes and all, so a test needs no dry run), and the `ratecal` command.

#![allow(dead_code)]

use std::path::Path;
use std::process::{Command, Output};

pub fn sha(bytes: &[u8]) -> String {
    ratecal_folder::hashes::sha256_hex(bytes)
}

const TABLE: &str = "t,outer,inner,outer_rate,inner_rate\n0,0,0,0,0\n";
const STATION: &str = "site: { latitude_deg: 55.7, gravity_mps2: 9.8156 }\n";

/// A finished run folder: `serial` (none: no serial in the manifest), start date, accel
/// bias x in results.json, and `extra` files stored with it.
pub fn write_run(
    dir: &Path,
    serial: Option<&str>,
    started: &str,
    bias: f64,
    extra: &[(&str, Vec<u8>)],
) {
    std::fs::create_dir_all(dir).unwrap();
    let procedure = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/procedures/imu-2d-standard/1.0.0.rcal"
    ))
    .unwrap();
    let canon = ratecal_grammar::canonical(&procedure).unwrap();
    // The IMU stream differs per run (by its bias), so each run has its own files.
    let imu = format!("t,ax,ay,az,gx,gy,gz\n0,{bias},0,9.8,0,0,0\n0.01,{bias},0,9.8,0,0,0\n");
    std::fs::write(dir.join("imu.csv"), &imu).unwrap();
    std::fs::write(dir.join("table.csv"), TABLE).unwrap();
    std::fs::write(dir.join("station.yaml"), STATION).unwrap();
    std::fs::write(dir.join("procedure.rcal"), &procedure).unwrap();
    for (name, bytes) in extra {
        let p = dir.join(name);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, bytes).unwrap();
    }
    let serial_line = serial
        .map(|s| format!("  serial: {s}\n"))
        .unwrap_or_default();
    let name = dir.file_name().unwrap().to_string_lossy();
    let manifest = format!(
        "format: ratecal-recording/1
station:
  site: {{ latitude_deg: 55.7, gravity_mps2: 9.8156 }}
  table: {{ outer_axis: [0, -1, 0], inner_axis: [1, 0, 0] }}
imu:
  model: SIM-TAC-100
{serial_line}procedure: {{ name: imu-2d-standard, version: 1.0.0, sha256: {} }}
segments: []
run:
  id: {name}
  ratecal_version: 0.1.0
  dry_run: false
  started: {started}
  ended: {started}
  status: completed
  station_sha256: {}
  files_sha256:
    imu.csv: {}
    table.csv: {}
",
        canon.sha256,
        sha(STATION.as_bytes()),
        sha(imu.as_bytes()),
        sha(TABLE.as_bytes())
    );
    std::fs::write(dir.join("manifest.yaml"), manifest).unwrap();
    let results = serde_json::json!({
        "format": "ratecal-results/1",
        "parameters": {
            "accel.bias.x": { "value": bias, "u": 0.0005, "unit": "m/s^2" },
            "gyro.bias.z": { "observable": false }
        },
        "acceptance": [
            { "name": "abs(accel.bias.x) <= 0.05 m/s^2", "quantity": "abs(accel.bias.x)",
              "value": bias, "op": "<=", "limit": 0.05, "unit": "m/s^2", "margin": 0.0,
              "U": 0.001, "rule": "simple", "verdict": "pass" }
        ]
    });
    std::fs::write(
        dir.join("results.json"),
        serde_json::to_string_pretty(&results).unwrap(),
    )
    .unwrap();
    seal(dir);
}

/// Seals the folder as `ratecal run` does last (every file's SHA-256 in seal.json).
pub fn seal(dir: &Path) {
    use ratecal_folder::seal::{SEAL_FILE, SEAL_HASH_FILE, Seal};
    let mut files: Vec<(String, Vec<u8>)> = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                let rel = p
                    .strip_prefix(dir)
                    .unwrap()
                    .to_string_lossy()
                    .replace('\\', "/");
                if rel != SEAL_FILE && rel != SEAL_HASH_FILE {
                    files.push((rel, std::fs::read(&p).unwrap()));
                }
            }
        }
    }
    let seal = Seal::new(
        "2026-01-01T00:00:00Z",
        files.iter().map(|(p, b)| (p.as_str(), b.as_slice())),
    );
    let json = seal.to_json();
    std::fs::write(dir.join(SEAL_FILE), &json).unwrap();
    std::fs::write(dir.join(SEAL_HASH_FILE), Seal::hash_line(&json)).unwrap();
}

/// `ratecal ARGS` in `cwd`, with no archive from the environment.
pub fn ratecal(args: &[&str], cwd: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_ratecal"))
        .args(args)
        .current_dir(cwd)
        .env_remove("RATECAL_ARCHIVE")
        .output()
        .unwrap()
}

pub fn code(o: &Output) -> i32 {
    o.status.code().unwrap_or(-1)
}

pub fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// `archive list --format json` (plus `more` arguments) as JSON.
pub fn list(archive: &str, more: &[&str], cwd: &Path) -> Vec<serde_json::Value> {
    let mut args = vec!["archive", "list", "--format", "json", "--archive", archive];
    args.extend_from_slice(more);
    let o = ratecal(&args, cwd);
    assert_eq!(code(&o), 0, "{}", text(&o));
    serde_json::from_slice::<Vec<serde_json::Value>>(&o.stdout).unwrap()
}

/// Every file under `dir`, by relative path, with its bytes.
pub fn tree(dir: &Path) -> Vec<(String, Vec<u8>)> {
    fn walk(root: &Path, d: &Path, out: &mut Vec<(String, Vec<u8>)>) {
        for e in std::fs::read_dir(d).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                walk(root, &p, out);
            } else {
                let rel = p.strip_prefix(root).unwrap().to_string_lossy().into_owned();
                out.push((rel, std::fs::read(&p).unwrap()));
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, dir, &mut out);
    out.sort();
    out
}
