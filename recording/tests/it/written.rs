//! A writer without the journal's chain (`create_exact_unchained`, an import's) writes the
//! same streams byte for byte as `create_exact`, records no `block` lines, and reports the
//! files as written (SHA-256 and length equal to reading them back); a folder hash given
//! those takes them only while the length is still the one written.

use ratecal_recording::{
    Columns, FileState, ImuSample, Manifest, RecordingWriter, TableSample, WrittenFile,
    hash_folder, hash_folder_known, parse_manifest, sha256_file,
};
use std::path::Path;

const MANIFEST: &str = "format: ratecal-recording/1
station:
  site: { latitude_deg: 55.7, gravity_mps2: 9.8156 }
  table: { outer_axis: [0, -1, 0], inner_axis: [1, 0, 0] }
segments: []
";

fn manifest() -> Manifest {
    parse_manifest("manifest.yaml", MANIFEST).unwrap()
}

/// Enough rows for several 64 KiB blocks of `imu.csv` (each would get a `block` line).
fn write(dir: &Path, chained: bool) -> Vec<WrittenFile> {
    let mut w = if chained {
        RecordingWriter::create_exact(dir, manifest(), Columns::default())
    } else {
        RecordingWriter::create_exact_unchained(dir, manifest(), Columns::default())
    }
    .unwrap();
    assert!(w.written().is_empty(), "nothing reported before finish");
    for i in 0..6000 {
        let t = i as f64 * 1e-3;
        let x = (i as f64 * 0.37).sin();
        w.write_imu(&[ImuSample {
            t,
            accel: [x * 1e-3, 0.1 + x, 9.80665 - x * 1e-6],
            gyro: [x / 3.0, -x, 1e-7 * i as f64],
            temp_c: None,
            t_host: None,
        }])
        .unwrap();
        if i % 10 == 0 {
            w.write_table(&[TableSample {
                t,
                outer_deg: x * 90.0,
                inner_deg: 0.0,
                outer_rate_dps: 10.0,
                inner_rate_dps: 0.0,
                ambient_c: None,
                t_host: None,
            }])
            .unwrap();
        }
    }
    w.finish().unwrap();
    assert!(w.write_failure().is_none());
    let files = w.written().to_vec();
    assert_eq!(w.close(), 0);
    files
}

fn blocks(dir: &Path) -> usize {
    std::fs::read_to_string(dir.join("journal.jsonl"))
        .unwrap()
        .lines()
        .filter(|l| l.contains("\"block\""))
        .count()
}

#[test]
fn unchained_streams_are_the_same_bytes_and_reported_as_written() {
    let d = tempfile::tempdir().unwrap();
    let (a, b) = (d.path().join("chained"), d.path().join("unchained"));
    let fa = write(&a, true);
    let fb = write(&b, false);
    for f in ["imu.csv", "table.csv"] {
        let (x, y) = (
            std::fs::read(a.join(f)).unwrap(),
            std::fs::read(b.join(f)).unwrap(),
        );
        assert!(x.len() > 1000, "{f} holds rows");
        assert!(x == y, "{f} differs between the writers");
    }
    assert!(blocks(&a) > 2, "the chained writer records its blocks");
    assert_eq!(blocks(&b), 0, "the unchained writer records none");
    assert_eq!(fa, fb);
    let names: Vec<&str> = fb.iter().map(|f| f.name.as_str()).collect();
    assert_eq!(names, ["imu.csv", "table.csv"]);
    for f in &fb {
        let (sha, len) = sha256_file(&b.join(&f.name)).unwrap();
        assert_eq!(
            (sha.as_str(), len),
            (f.sha256.as_str(), f.len),
            "{}",
            f.name
        );
    }
}

#[test]
fn known_hashes_are_taken_only_at_the_written_length() {
    let d = tempfile::tempdir().unwrap();
    std::fs::write(d.path().join("imu.csv"), b"t,ax\n0,1\n").unwrap();
    std::fs::write(d.path().join("table.csv"), b"t\n").unwrap();
    let real = hash_folder(d.path(), |_| false).unwrap();
    let fake = "f".repeat(64);
    let known = [
        // Same length as on disk: taken without reading.
        WrittenFile {
            name: "imu.csv".into(),
            sha256: fake.clone(),
            len: 9,
        },
        // Another length: the file changed since, so it is read.
        WrittenFile {
            name: "table.csv".into(),
            sha256: fake.clone(),
            len: 3,
        },
    ];
    let got = hash_folder_known(d.path(), |_| false, &known).unwrap();
    assert_eq!(
        got["imu.csv"],
        FileState::Hashed {
            sha256: fake,
            size: 9
        }
    );
    assert_eq!(got["table.csv"], real["table.csv"]);
    assert_ne!(got["imu.csv"], real["imu.csv"]);
}
