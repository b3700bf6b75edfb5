//! `ratecal import` of MATLAB v5 binary files written by scipy.io.savemat (a writer of the
//! format no one here made: `tests/fixtures/import_mat/make.py`), from the public MPU-6050
//! session. The MATLAB path must give exactly what the CSV path gives on the same samples:
//! compressed (MATLAB's default) and not, int16 counts, doubles and singles. A v7.3 (HDF5)
//! file, a missing variable, a character array, a 3-D array and a column outside the matrix
//! are refused (exit 1, nothing written) with the file, where, and what to do.

use crate::support;
use support::*;

use std::path::{Path, PathBuf};

fn fixture(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/import_mat")
        .join(name)
        .to_str()
        .unwrap()
        .to_string()
}

fn docs_map(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("docs/examples/import")
        .join(name)
        .to_str()
        .unwrap()
        .to_string()
}

/// docs/examples/import/mpu6050.yaml with the source a MATLAB matrix (columns by index).
fn mat_map(variable: &str) -> String {
    let text = std::fs::read_to_string(docs_map("mpu6050.yaml")).unwrap();
    let text = text
        .replace(
            "source: { format: csv, skip_lines: 4 }",
            &format!("source: {{ format: mat, variable: {variable} }}"),
        )
        .replace(
            "columns: { ax: ax, ay: ay, az: az, gx: gx, gy: gy, gz: gz }",
            "columns: { ax: 0, ay: 1, az: 2, gx: 3, gy: 4, gz: 5 }",
        );
    assert!(text.contains("format: mat") && text.contains("ax: 0"));
    text
}

fn import(dir: &Path, source: &str, map_text: &str, out: &str) -> std::process::Output {
    let map = dir.join(format!("{out}.yaml"));
    std::fs::write(&map, map_text).unwrap();
    ratecal(
        &[
            "import",
            source,
            "--map",
            map.to_str().unwrap(),
            "--out",
            out,
        ],
        dir,
    )
}

/// The manifest without its provenance (which names the sources and their columns).
fn manifest_body(run: &Path) -> String {
    let m = std::fs::read_to_string(run.join("manifest.yaml")).unwrap();
    m.split("provenance:").next().unwrap().to_string()
}

fn same_recording(a: &Path, b: &Path) {
    for f in ["imu.csv", "table.csv"] {
        let (x, y) = (
            std::fs::read(a.join(f)).unwrap(),
            std::fs::read(b.join(f)).unwrap(),
        );
        assert!(x.len() > 1000, "{f} is {} bytes", x.len());
        assert!(x == y, "{f} differs between {a:?} and {b:?}");
    }
    assert_eq!(manifest_body(a), manifest_body(b));
}

#[test]
fn mat_int16_and_double_compressed_or_not_equal_the_csv_import_exactly() {
    let Some(csv) = shared_path("real/mpu6050/example_data_calibration.csv") else {
        return;
    };
    let tmp = tempfile::tempdir().unwrap();
    let o = ratecal(
        &[
            "import",
            csv.to_str().unwrap(),
            "--map",
            &docs_map("mpu6050.yaml"),
            "--out",
            "from_csv",
        ],
        tmp.path(),
    );
    assert_eq!(code(&o), 0, "{}", text(&o));
    let from_csv: PathBuf = tmp.path().join("from_csv");
    // The detected segments are there to compare (the session has its six poses).
    assert!(manifest_body(&from_csv).matches("kind: static").count() >= 3);
    for (k, file) in [
        "mpu6050_int16.mat",
        "mpu6050_int16_v6.mat",
        "mpu6050_double.mat",
    ]
    .iter()
    .enumerate()
    {
        let out = format!("from_mat{k}");
        let o = import(tmp.path(), &fixture(file), &mat_map("cal_data"), &out);
        assert_eq!(code(&o), 0, "{file}: {}", text(&o));
        same_recording(&from_csv, &tmp.path().join(&out));
        // The provenance hashes the MATLAB file itself.
        let m = std::fs::read_to_string(tmp.path().join(&out).join("manifest.yaml")).unwrap();
        let sha = ratecal_recording::sha256_hex(&std::fs::read(fixture(file)).unwrap());
        assert!(m.contains(&sha), "{file}: no {sha} in {m}");
    }
}

#[test]
fn mat_singles_equal_their_csv_twin_exactly() {
    let tmp = tempfile::tempdir().unwrap();
    let body = "imu:
  time: { rate_hz: 100 }
  COLUMNS
  units: { accel: g, gyro: deg/s }
site: { latitude_deg: 0.0, gravity_mps2: 9.80665 }
";
    let csv_map = format!("source: {{ format: csv }}\n{body}").replace(
        "COLUMNS",
        "columns: { ax: ax, ay: ay, az: az, gx: gx, gy: gy, gz: gz }",
    );
    let mat_map = format!("source: {{ format: mat, variable: cal_data }}\n{body}").replace(
        "COLUMNS",
        "columns: { ax: 0, ay: 1, az: 2, gx: 3, gy: 4, gz: 5 }",
    );
    let o = import(tmp.path(), &fixture("mpu6050_single.csv"), &csv_map, "a");
    assert_eq!(code(&o), 0, "{}", text(&o));
    let o = import(tmp.path(), &fixture("mpu6050_single_v6.mat"), &mat_map, "b");
    assert_eq!(code(&o), 0, "{}", text(&o));
    same_recording(&tmp.path().join("a"), &tmp.path().join("b"));
    let rec = ratecal_recording::read(&tmp.path().join("b")).unwrap();
    assert_eq!(rec.imu.t.len(), 1000);
}

/// Exit 1, nothing written, and the message holds each of `want`.
fn refused(dir: &Path, source: &str, map_text: &str, want: &[&str]) {
    let o = import(dir, source, map_text, "refused");
    // miette wraps long lines: one line, without its gutter.
    let t = text(&o).replace('│', " ");
    let t = t.split_whitespace().collect::<Vec<_>>().join(" ");
    assert_eq!(code(&o), 1, "{t}");
    assert!(!dir.join("refused").exists(), "{t}");
    for w in want {
        assert!(t.contains(w), "no `{w}` in:\n{t}");
    }
    assert!(t.contains("help"), "{t}");
}

#[test]
fn mat_refusals_name_the_file_and_what_to_do() {
    let tmp = tempfile::tempdir().unwrap();
    let int16 = fixture("mpu6050_int16.mat");
    // A variable that is not there: the ones that are, with their classes.
    refused(
        tmp.path(),
        &int16,
        &mat_map("imu"),
        &[
            "mpu6050_int16.mat",
            "has no variable `imu`",
            "notes (char)",
            "fs (double)",
            "meta (struct)",
            "cal_data (int16)",
        ],
    );
    refused(
        tmp.path(),
        &int16,
        &mat_map("notes"),
        &["`notes` is a char array, not a numeric matrix"],
    );
    refused(tmp.path(), &int16, &mat_map("cube"), &["has 3 dimensions"]);
    // A column the matrix does not have: located in the map.
    let wide = mat_map("cal_data").replace("gz: 5", "gz: 6");
    refused(
        tmp.path(),
        &int16,
        &wide,
        &["refused.yaml:", "column 6", "is 10245 x 6 (int16)"],
    );
    // v7.3 is HDF5: a 512-byte user block with MATLAB's text, then the HDF5 signature.
    let mut v73 = b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Thu Nov 26 12:00:00 2026 HDF5 schema 1.00 .".to_vec();
    v73.resize(512, b' ');
    v73.extend_from_slice(b"\x89HDF\r\n\x1a\n");
    v73.resize(2048, 0);
    let p = tmp.path().join("v73.mat");
    std::fs::write(&p, v73).unwrap();
    refused(
        tmp.path(),
        p.to_str().unwrap(),
        &mat_map("cal_data"),
        &["v73.mat", "v7.3", "save with -v7"],
    );
    // A text file named .mat is pointed to `format: csv`.
    refused(
        tmp.path(),
        &fixture("mpu6050_single.csv"),
        &mat_map("cal_data"),
        &["not a MATLAB v5 binary file", "format: csv"],
    );
}
