//! `ratecal verify` on run folders: intact, altered, missing, unsealed.

use std::path::Path;
use std::process::Command;

fn sha(bytes: &[u8]) -> String {
    ratecal_folder::hashes::sha256_hex(bytes)
}

const IMU: &str = "t,ax,ay,az,gx,gy,gz\n0,0,0,9.8,0,0,0\n0.01,0,0,9.8,0,0,0\n";
const TABLE: &str = "t,outer,inner,outer_rate,inner_rate\n0,0,0,0,0\n";
const STATION: &str = "site: { latitude_deg: 55.7, gravity_mps2: 9.8156 }\n";

/// Writes a run folder as `ratecal run` leaves it once ended.
fn write_run(dir: &Path) {
    let procedure = std::fs::read_to_string("procedures/imu-2d-standard/1.0.0.rcal").unwrap();
    let canon = ratecal_grammar::canonical(&procedure).unwrap();
    std::fs::write(dir.join("imu.csv"), IMU).unwrap();
    std::fs::write(dir.join("table.csv"), TABLE).unwrap();
    std::fs::write(dir.join("station.yaml"), STATION).unwrap();
    std::fs::write(dir.join("procedure.rcal"), &procedure).unwrap();
    let manifest = format!(
        "format: ratecal-recording/1
station:
  site: {{ latitude_deg: 55.7, gravity_mps2: 9.8156 }}
  table: {{ outer_axis: [0, -1, 0], inner_axis: [1, 0, 0] }}
procedure: {{ name: imu-2d-standard, version: 1.0.0, sha256: {} }}
segments: []
run:
  id: r1
  ratecal_version: 0.1.0
  dry_run: true
  started: 2026-01-01T00:00:00Z
  ended: 2026-01-01T01:00:00Z
  status: completed
  station_sha256: {}
  files_sha256:
    imu.csv: {}
    table.csv: {}
",
        canon.sha256,
        sha(STATION.as_bytes()),
        sha(IMU.as_bytes()),
        sha(TABLE.as_bytes())
    );
    std::fs::write(dir.join("manifest.yaml"), manifest).unwrap();
    // Sealed last, as `ratecal run` does.
    let names = [
        "imu.csv",
        "table.csv",
        "station.yaml",
        "procedure.rcal",
        "manifest.yaml",
    ];
    let bytes: Vec<(&str, Vec<u8>)> = names
        .iter()
        .map(|n| (*n, std::fs::read(dir.join(n)).unwrap()))
        .collect();
    let seal = ratecal_folder::seal::Seal::new(
        "2026-01-01T01:00:00Z",
        bytes.iter().map(|(n, b)| (*n, b.as_slice())),
    );
    let json = seal.to_json();
    std::fs::write(dir.join("seal.json"), &json).unwrap();
    std::fs::write(
        dir.join("seal.sha256"),
        ratecal_folder::seal::Seal::hash_line(&json),
    )
    .unwrap();
}

fn verify(dir: &Path) -> (i32, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_ratecal"))
        .arg("verify")
        .arg(dir)
        .output()
        .unwrap();
    (
        out.status.code().unwrap(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
    )
}

#[test]
fn verify_says_intact_or_names_what_was_altered() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    write_run(dir);
    let (code, out) = verify(dir);
    assert_eq!(code, 0, "{out}");
    assert!(out.contains("intact: 6 file(s)"), "{out}");

    // Every byte is sealed: even a re-indented procedure copy is an altered file.
    let p = std::fs::read_to_string(dir.join("procedure.rcal")).unwrap();
    std::fs::write(dir.join("procedure.rcal"), p.replace("  ", "    ")).unwrap();
    let (code, out) = verify(dir);
    assert_eq!(code, 1, "{out}");
    assert!(
        out.contains("! ALTERED  procedure.rcal: recorded sha256"),
        "{out}"
    );

    std::fs::write(
        dir.join("imu.csv"),
        IMU.replace("9.8,0,0,0\n0.01", "9.9,0,0,0\n0.01"),
    )
    .unwrap();
    std::fs::remove_file(dir.join("table.csv")).unwrap();
    let (code, out) = verify(dir);
    assert_eq!(code, 1, "{out}");
    assert!(out.contains("! ALTERED  imu.csv: recorded sha256"), "{out}");
    assert!(out.contains("! ALTERED  table.csv: missing"), "{out}");
}

#[test]
fn a_manifest_that_no_longer_parses_is_altered() {
    let tmp = tempfile::tempdir().unwrap();
    write_run(tmp.path());
    std::fs::write(tmp.path().join("manifest.yaml"), "format: [unclosed\n  - :").unwrap();
    let (code, out) = verify(tmp.path());
    assert_eq!(code, 1);
    assert!(
        out.contains("ALTERED since the run: manifest.yaml"),
        "{out}"
    );
}

#[test]
fn an_unsealed_run_folder_is_not_intact() {
    let tmp = tempfile::tempdir().unwrap();
    write_run(tmp.path());
    std::fs::remove_file(tmp.path().join("seal.json")).unwrap();
    let (code, out) = verify(tmp.path());
    assert_eq!(code, 1);
    assert!(out.contains("! ALTERED  seal.json: missing"), "{out}");
}

#[test]
fn a_folder_without_manifest_is_an_error() {
    let tmp = tempfile::tempdir().unwrap();
    assert_eq!(verify(tmp.path()).0, 2);
}

fn ratecal(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_ratecal"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.code().unwrap(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn diff_exits_like_diff1() {
    let (code, out, _) = ratecal(&[
        "diff",
        "procedures/imu-2d-standard@1.0.0",
        "procedures/imu-2d-standard",
    ]);
    assert_eq!(code, 1, "{out}");
    assert!(
        out.contains(
            "LOOSENED  step gyro_scale / accept gyro.residual.std: <= 0.1 deg/s -> <= 0.15 deg/s"
        ),
        "{out}"
    );
    assert!(!out.contains('\x1b'), "no colour when not a terminal");

    let (code, out, _) = ratecal(&[
        "diff",
        "procedures/imu-2d-standard/1.0.0.rcal",
        "procedures/imu-2d-standard@1.1.0",
        "--format",
        "json",
    ]);
    assert_eq!(code, 1);
    let v: serde_json::Value = serde_json::from_str(&out).expect("stdout holds only JSON");
    assert_eq!(v["old"]["version"], "1.0.0");
    assert_eq!(v["new"]["version"], "1.1.0");
    assert_eq!(v["new"]["sha256"].as_str().unwrap().len(), 64);
    let kinds: Vec<&str> = v["changes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["kind"].as_str().unwrap())
        .collect();
    assert!(
        kinds.contains(&"loosened") && kinds.contains(&"added"),
        "{kinds:?}"
    );

    let (code, out, _) = ratecal(&[
        "diff",
        "procedures/imu-2d-standard@1.0.0",
        "procedures/imu-2d-standard/1.0.0.rcal",
    ]);
    assert_eq!(code, 0);
    assert!(out.contains("No semantic change."));

    assert_eq!(
        ratecal(&[
            "diff",
            "procedures/imu-2d-standard@9.9.9",
            "procedures/imu-2d-standard"
        ])
        .0,
        2
    );
    assert_eq!(
        ratecal(&["diff", "no/such/file.rcal", "procedures/imu-2d-standard"]).0,
        2
    );
}

#[test]
fn log_lists_every_version_with_hash_and_summary() {
    let (code, out, err) = ratecal(&["log", "procedures/imu-2d-standard"]);
    assert_eq!(code, 0, "{err}");
    let lines: Vec<&str> = out.lines().collect();
    assert!(
        lines[1].starts_with("1.0.0 ")
            && lines[1].contains("released")
            && lines[1].contains("first version")
    );
    assert!(
        lines[2].starts_with("1.1.0 ")
            && lines[2].contains("LOOSENED step gyro_scale / accept gyro.residual.std")
    );
    let canon = ratecal_grammar::canonical(
        &std::fs::read_to_string("procedures/imu-2d-standard/1.1.0.rcal").unwrap(),
    );
    assert!(lines[2].contains(&canon.unwrap().sha256));
}

/// A copy of the standard procedure folder to tamper with.
fn copy_standard(dir: &Path) {
    for f in ["1.0.0.rcal", "1.1.0.rcal", "versions.lock"] {
        std::fs::copy(Path::new("procedures/imu-2d-standard").join(f), dir.join(f)).unwrap();
    }
}

#[test]
fn check_refuses_a_released_version_changed_in_place() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    copy_standard(dir);
    let d = dir.to_str().unwrap();
    assert_eq!(ratecal(&["check", d]).0, 0);

    // layout only: the canonical text, hence the released hash, is the same
    let v1 = std::fs::read_to_string(dir.join("1.0.0.rcal")).unwrap();
    std::fs::write(dir.join("1.0.0.rcal"), v1.replace("  ", "\t")).unwrap();
    assert_eq!(ratecal(&["check", d]).0, 0);

    std::fs::write(
        dir.join("1.0.0.rcal"),
        v1.replace("<= 0.002 g", "<= 0.003 g"),
    )
    .unwrap();
    let (code, _, err) = ratecal(&["check", d]);
    assert_eq!(code, 1);
    assert!(
        err.contains("versions::released_changed")
            && err.contains("released version 1.0.0 changed"),
        "{err}"
    );
}

#[test]
fn check_refuses_a_version_that_does_not_increase() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    copy_standard(dir);
    let v = std::fs::read_to_string(dir.join("1.1.0.rcal")).unwrap();
    std::fs::write(
        dir.join("1.0.5.rcal"),
        v.replace("version 1.1.0", "version 1.0.5"),
    )
    .unwrap();
    let (code, _, err) = ratecal(&["check", dir.to_str().unwrap()]);
    assert_eq!(code, 1);
    assert!(err.contains("versions::not_increasing"), "{err}");
    assert!(err.contains("1.0.5.rcal"), "names the file: {err}");
}
