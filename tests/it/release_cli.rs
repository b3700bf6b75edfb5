//! Releases (issue 39, item 1): `ratecal release FOLDER@VERSION --signer --key` writes the
//! signed line of `versions.lock`; `check` and `log` verify it; the folder form runs the
//! newest released version; a draft runs only with `--draft`, says DRAFT PROCEDURE in the
//! manifest, results, report and console, and gets no certificate.

use crate::support::*;
use std::path::Path;

/// A procedure folder `lab/mini` with MINI as 1.0.0 and a changed copy as 1.1.0, and a key.
fn folder(dir: &Path) -> std::path::PathBuf {
    let f = dir.join("lab/mini");
    std::fs::create_dir_all(&f).unwrap();
    std::fs::write(f.join("1.0.0.rcal"), MINI).unwrap();
    let v11 = MINI
        .replace("version 1.0.0", "version 1.1.0")
        .replace("at least 5 s", "at least 6 s");
    std::fs::write(f.join("1.1.0.rcal"), v11).unwrap();
    let o = ratecal(&["key", "new", "keys"], dir);
    assert_eq!(code(&o), 0, "{}", text(&o));
    f
}

fn release(dir: &Path, spec: &str) -> std::process::Output {
    ratecal(
        &[
            "release",
            spec,
            "--signer",
            "Ada Lovelace",
            "--key",
            "keys/lab.key",
        ],
        dir,
    )
}

fn manifest_version(run: &Path) -> String {
    let m = std::fs::read_to_string(run.join("manifest.yaml")).unwrap();
    let m = ratecal_recording::parse_manifest("manifest.yaml", &m).unwrap();
    m.procedure.unwrap().version
}

#[test]
fn release_writes_a_signed_line_that_check_and_log_verify() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    folder(dir);
    let o = release(dir, "lab/mini@1.0.0");
    assert_eq!(code(&o), 0, "{}", text(&o));
    let lock = std::fs::read_to_string(dir.join("lab/mini/versions.lock")).unwrap();
    let line = lock
        .lines()
        .find(|l| l.starts_with("1.0.0 "))
        .expect("the release line");
    assert!(line.ends_with(" Ada Lovelace"), "{line}");
    assert_eq!(line.split_whitespace().count(), 6, "{line}");
    // Released once only.
    let o = release(dir, "lab/mini@1.0.0");
    assert_eq!(code(&o), 1, "{}", text(&o));
    assert!(text(&o).contains("already released"), "{}", text(&o));

    let o = ratecal(&["log", "lab/mini"], dir);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let out = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(out.contains("released (signed by Ada Lovelace)"), "{out}");
    assert!(out.contains("unreleased (draft)"), "{out}");
    let o = ratecal(&["check", "lab/mini"], dir);
    assert_eq!(code(&o), 0, "{}", text(&o));

    // A line edited by hand (another signer) no longer verifies.
    let forged = lock.replace("Ada Lovelace", "Eve");
    std::fs::write(dir.join("lab/mini/versions.lock"), forged).unwrap();
    let o = ratecal(&["check", "lab/mini"], dir);
    assert_eq!(code(&o), 1, "{}", text(&o));
    assert!(text(&o).contains("versions::bad_signature"), "{}", text(&o));
    let o = ratecal(&["check", "lab/mini@1.0.0"], dir);
    assert_eq!(code(&o), 1, "{}", text(&o));
    let o = ratecal(&["log", "lab/mini"], dir);
    assert_eq!(code(&o), 2, "{}", text(&o));
    assert!(text(&o).contains("BAD SIGNATURE"), "{}", text(&o));
}

#[test]
fn hash_only_lines_stay_releases() {
    let root = env!("CARGO_MANIFEST_DIR");
    let o = ratecal(&["log", "procedures/imu-2d-standard"], Path::new(root));
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert!(
        String::from_utf8_lossy(&o.stdout).contains("released (unsigned)"),
        "{}",
        text(&o)
    );
}

#[test]
fn check_warns_on_a_draft_however_it_is_named() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    folder(dir);
    assert_eq!(code(&release(dir, "lab/mini@1.0.0")), 0);
    for spec in ["lab/mini@1.1.0", "lab/mini/1.1.0.rcal"] {
        let o = ratecal(&["check", spec], dir);
        assert_eq!(code(&o), 0, "{}", text(&o));
        assert!(
            text(&o).contains("versions::unreleased") && text(&o).contains("1.1.0 is not released"),
            "{spec}: {}",
            text(&o)
        );
    }
    let o = ratecal(&["check", "lab/mini@1.0.0"], dir);
    assert!(!text(&o).contains("versions::unreleased"), "{}", text(&o));
}

#[test]
fn the_folder_runs_its_newest_release_and_a_draft_needs_draft() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    folder(dir);
    assert_eq!(code(&release(dir, "lab/mini@1.0.0")), 0);

    // The folder form: 1.0.0, the newest released, not the newer draft 1.1.0.
    let o = ratecal(&["run", "lab/mini", "--dry-run", "--out", "r1"], dir);
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert_eq!(manifest_version(&dir.join("r1")), "1.0.0");
    assert!(!text(&o).contains("DRAFT PROCEDURE"), "{}", text(&o));

    // The draft, named: refused without --draft, before a folder is made.
    let o = ratecal(&["run", "lab/mini@1.1.0", "--dry-run", "--out", "r2"], dir);
    assert_eq!(code(&o), 1, "{}", text(&o));
    assert!(text(&o).contains("not released"), "{}", text(&o));
    assert!(!dir.join("r2").exists());

    // With --draft the folder form takes the newest version, and every output says so.
    let o = ratecal(
        &["run", "lab/mini", "--draft", "--dry-run", "--out", "r3"],
        dir,
    );
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert!(text(&o).contains("DRAFT PROCEDURE"), "{}", text(&o));
    let r3 = dir.join("r3");
    assert_eq!(manifest_version(&r3), "1.1.0");
    let manifest = std::fs::read_to_string(r3.join("manifest.yaml")).unwrap();
    assert!(manifest.contains("DRAFT PROCEDURE"), "{manifest}");
    let results = json(&r3.join("results.json"));
    assert!(
        results["draft_procedure"]
            .as_str()
            .is_some_and(|s| s.starts_with("DRAFT PROCEDURE")),
        "{results}"
    );
    let report = std::fs::read_to_string(r3.join("report.md")).unwrap();
    assert!(report.contains("DRAFT PROCEDURE"), "{report}");

    // No certificate for it, whatever else is given (refused before anything else).
    let o = ratecal(&["certificate", "r3", "--lab", "no-such-lab.yaml"], dir);
    assert_eq!(code(&o), 1, "{}", text(&o));
    assert!(
        text(&o).contains("certificate::draft_procedure"),
        "{}",
        text(&o)
    );
}
