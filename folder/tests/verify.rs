//! Verification of a run folder against the hashes its manifest recorded.

use ratecal_folder::hashes::{Actual, Status, sha256_hex, verify_run};
use ratecal_recording::{Manifest, ManifestStation, ProcedureRef, RunInfo, TableAxes};
use std::collections::BTreeMap;

// SHA-256("hello"), from any sha256sum.
const HELLO: &str = "2cf24dba5fb0a30e26e83b2ac5b9e29e1b161e5c1fa7425e73043362938b9824";

fn manifest(files: &[(&str, &str)]) -> Manifest {
    Manifest {
        format: "ratecal-recording/1".into(),
        station: ManifestStation {
            site: serde_json::from_value(
                serde_json::json!({"latitude_deg": 55.7, "gravity_mps2": 9.8156}),
            )
            .unwrap(),
            table: TableAxes {
                outer_axis: [0.0, -1.0, 0.0],
                inner_axis: [1.0, 0.0, 0.0],
                model: None,
            },
            mount: None,
        },
        imu: BTreeMap::new(),
        procedure: Some(ProcedureRef {
            name: "imu-2d-standard".into(),
            version: "1.0.0".into(),
            sha256: HELLO.into(),
        }),
        segments: vec![],
        environment: None,
        run: Some(RunInfo {
            id: "r1".into(),
            ratecal_version: "0.1.0".into(),
            dry_run: true,
            started: "2026-01-01T00:00:00Z".into(),
            ended: Some("2026-01-01T01:00:00Z".into()),
            status: "completed".into(),
            abort: None,
            operator: None,
            seed: Some(1),
            station_sha256: Some(HELLO.into()),
            files_sha256: files
                .iter()
                .map(|(a, b)| (a.to_string(), b.to_string()))
                .collect(),
            failure: None,
            resumes: Vec::new(),
            changed_after_release: None,
            draft_procedure: None,
            sync: None,
            write_failure: None,
        }),
    }
}

#[test]
fn sha256_matches_a_known_value() {
    assert_eq!(sha256_hex(b"hello"), HELLO);
}

#[test]
fn an_untouched_run_is_intact() {
    let m = manifest(&[("imu.csv", HELLO), ("table.csv", HELLO)]);
    let r = verify_run(
        &m,
        |_| Some(b"hello".to_vec()),
        Some(("procedure.rcal".into(), Actual::Hash(HELLO.into()))),
        Some(("station.yaml".into(), Some(b"hello".to_vec()))),
    );
    assert!(r.intact(), "{}", r.text());
    assert_eq!(r.checks.len(), 4);
}

#[test]
fn altered_missing_and_unparsable_files_are_named() {
    let m = manifest(&[("imu.csv", HELLO), ("table.csv", HELLO)]);
    let read = |name: &str| match name {
        "imu.csv" => Some(b"hellO".to_vec()),
        _ => None,
    };
    let r = verify_run(
        &m,
        read,
        Some((
            "procedure.rcal".into(),
            Actual::Unparsable("line 3: expected `{`".into()),
        )),
        None,
    );
    assert!(!r.intact());
    let bad: Vec<(&str, &Status)> = r.altered().map(|c| (c.file.as_str(), &c.status)).collect();
    assert_eq!(bad.len(), 3);
    assert!(matches!(bad[0], ("imu.csv", Status::Altered { .. })));
    assert_eq!(bad[1], ("table.csv", &Status::Missing));
    assert!(matches!(bad[2].1, Status::Unparsable(_)));
    let text = r.text();
    assert!(
        text.contains("ALTERED since the run: imu.csv, table.csv, procedure.rcal"),
        "{text}"
    );
}

#[test]
fn nothing_recorded_is_not_intact() {
    let mut m = manifest(&[]);
    m.procedure = None;
    m.run.as_mut().unwrap().station_sha256 = None;
    assert!(!verify_run(&m, |_| None, None, None).intact());
}
