//! `ratecal verify` on run folders: intact, altered, missing, no longer parsing.

use std::path::Path;
use std::process::Command;

fn sha(bytes: &[u8]) -> String {
    ratecal_engine::audit::verify::sha256_hex(bytes)
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
    assert!(out.contains("intact: 4 file(s)"), "{out}");

    // re-indenting the procedure copy keeps its canonical hash
    let p = std::fs::read_to_string(dir.join("procedure.rcal")).unwrap();
    std::fs::write(dir.join("procedure.rcal"), p.replace("  ", "    ")).unwrap();
    assert_eq!(verify(dir).0, 0);

    std::fs::write(
        dir.join("imu.csv"),
        IMU.replace("9.8,0,0,0\n0.01", "9.9,0,0,0\n0.01"),
    )
    .unwrap();
    std::fs::remove_file(dir.join("table.csv")).unwrap();
    std::fs::write(dir.join("procedure.rcal"), "procedure broken {").unwrap();
    let (code, out) = verify(dir);
    assert_eq!(code, 1, "{out}");
    assert!(out.contains("! ALTERED  imu.csv: recorded sha256"), "{out}");
    assert!(out.contains("! ALTERED  table.csv: missing"), "{out}");
    assert!(
        out.contains("procedure.rcal (procedure imu-2d-standard 1.0.0): no longer parses"),
        "{out}"
    );
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
fn a_folder_without_manifest_is_an_error() {
    let tmp = tempfile::tempdir().unwrap();
    assert_eq!(verify(tmp.path()).0, 2);
}
