//! Hardening, second round (issue 38): a link planted in a run folder is never written
//! through; outputs cannot name the folder's inputs; results written into a sealed folder
//! are computed from what the seal holds; approvals survive additions.

use crate::support;
use std::path::Path;
use support::*;

/// `approve r` with the key `keys/lab.key`.
const APPROVE: &[&str] = &[
    "approve",
    "r",
    "--signer",
    "A. M",
    "--role",
    "Head",
    "--key",
    "keys/lab.key",
];

/// A sealed MINI run in `tmp/r`.
fn sealed_run(tmp: &Path) -> std::path::PathBuf {
    let o = mini_run(tmp, "r", &[]);
    assert!(matches!(code(&o), 0 | 3), "{}", text(&o));
    tmp.join("r")
}

#[cfg(unix)]
fn link(target: &Path, at: &Path) {
    let _ = std::fs::remove_file(at);
    std::os::unix::fs::symlink(target, at).unwrap();
}

/// The commands that write into a run folder, each with the lock or the pending folder a
/// symlink to a file or folder outside it: refused, the link named, nothing written there.
#[cfg(unix)]
#[test]
fn planted_links_in_a_run_folder_are_never_written_through() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = sealed_run(tmp.path());
    let victim = tmp.path().join("victim.txt");
    let elsewhere = tmp.path().join("elsewhere");
    std::fs::create_dir(&elsewhere).unwrap();
    let o = ratecal(&["key", "new", "keys"], tmp.path());
    assert_eq!(code(&o), 0, "{}", text(&o));
    let commands: [&[&str]; 4] = [
        &["analyze", "r", "--out", "r/results.json"],
        &["report", "r", "--out", "r/again.md"],
        &["explain", "r"],
        APPROVE,
    ];
    for args in commands {
        // The lock a link to an existing file, then a dangling one.
        std::fs::write(&victim, "precious\n").unwrap();
        link(&victim, &dir.join(".ratecal.lock"));
        let o = ratecal(args, tmp.path());
        assert_ne!(code(&o), 0, "{args:?}: {}", text(&o));
        assert!(
            text(&o).contains("is a symbolic link"),
            "{args:?}: {}",
            text(&o)
        );
        assert!(text(&o).contains(".ratecal.lock"), "{args:?}: {}", text(&o));
        assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious\n");
        let gone = tmp.path().join("not-there");
        link(&gone, &dir.join(".ratecal.lock"));
        let o = ratecal(args, tmp.path());
        assert_ne!(code(&o), 0, "{args:?}: {}", text(&o));
        assert!(
            !gone.exists(),
            "{args:?} created the dangling link's target"
        );
        std::fs::remove_file(dir.join(".ratecal.lock")).unwrap();

        // The pending folder a link to a folder elsewhere.
        link(&elsewhere, &dir.join(".ratecal-pending"));
        let o = ratecal(args, tmp.path());
        assert_ne!(code(&o), 0, "{args:?}: {}", text(&o));
        assert!(
            text(&o).contains("is a symbolic link"),
            "{args:?}: {}",
            text(&o)
        );
        assert_eq!(
            std::fs::read_dir(&elsewhere).unwrap().count(),
            0,
            "{args:?} wrote through the pending link"
        );
        std::fs::remove_file(dir.join(".ratecal-pending")).unwrap();
    }
    assert!(!dir.join("again.md").exists());
    let o = ratecal(&["verify", "r"], tmp.path());
    assert_eq!(code(&o), 0, "{}", text(&o));
}

/// `run --resume` with a planted lock link.
#[cfg(unix)]
#[test]
fn resume_refuses_a_planted_lock_link() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("st.yaml"), station_with(EXCURSION)).unwrap();
    let o = mini_run(tmp.path(), "r", &["--station", "st.yaml"]);
    assert_eq!(code(&o), 4, "{}", text(&o));
    let dir = tmp.path().join("r");
    let victim = tmp.path().join("victim.txt");
    std::fs::write(&victim, "precious\n").unwrap();
    link(&victim, &dir.join(".ratecal.lock"));
    let o = ratecal(&["run", "--resume", "r"], tmp.path());
    assert_ne!(code(&o), 0, "{}", text(&o));
    assert!(text(&o).contains("is a symbolic link"), "{}", text(&o));
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious\n");
}

/// No output may name the recording, a recorded file or the seal (exit 1; explain 2):
/// refused before anything is computed, nothing written, the folder still intact.
#[test]
fn outputs_never_replace_a_run_folders_inputs() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = sealed_run(tmp.path());
    std::fs::write(tmp.path().join("st.yaml"), station_with("")).unwrap();
    let imu = std::fs::read(dir.join("imu.csv")).unwrap();
    let seal = std::fs::read(dir.join("seal.json")).unwrap();
    let cases: [(&[&str], i32); 7] = [
        (&["analyze", "r", "--out", "r/imu.csv"], 1),
        (&["analyze", "r", "--out", "r/seal.json"], 1),
        (&["analyze", "r", "--out", "r/../r/manifest.yaml"], 1),
        (&["report", "r", "--out", "r/imu.csv"], 1),
        (&["report", "r", "--out", "r/seal.sha256"], 1),
        (
            &[
                "certificate",
                "r",
                "--lab",
                "lab.yaml",
                "--out",
                "r/imu.csv",
            ],
            1,
        ),
        (
            &[
                "explain",
                "r",
                "--twin",
                "st.yaml",
                "--write-twin",
                "r/imu.csv",
            ],
            2,
        ),
    ];
    for (args, want) in cases {
        let o = ratecal(args, tmp.path());
        assert_eq!(code(&o), want, "{args:?}: {}", text(&o));
        assert!(
            text(&o).contains("run_folder::output_is_input"),
            "{args:?}: {}",
            text(&o)
        );
        assert!(
            text(&o).contains("nothing was written"),
            "{args:?}: {}",
            text(&o)
        );
        assert_eq!(std::fs::read(dir.join("imu.csv")).unwrap(), imu, "{args:?}");
        assert_eq!(
            std::fs::read(dir.join("seal.json")).unwrap(),
            seal,
            "{args:?}"
        );
    }
    // A hard link to the stream elsewhere is the stream.
    std::fs::hard_link(dir.join("imu.csv"), tmp.path().join("copy.csv")).unwrap();
    let o = ratecal(&["analyze", "r", "--out", "copy.csv"], tmp.path());
    assert_eq!(code(&o), 1, "{}", text(&o));
    assert_eq!(std::fs::read(dir.join("imu.csv")).unwrap(), imu);
    let o = ratecal(&["verify", "r"], tmp.path());
    assert_eq!(code(&o), 0, "{}", text(&o));
    // A derived file may still be written again.
    let o = ratecal(&["analyze", "r", "--out", "r/results.json"], tmp.path());
    assert!(matches!(code(&o), 0 | 3), "{}", text(&o));
}

/// An altered recording is not re-analysed into its folder (exit 4, nothing written), and
/// every addition records what it was computed from, which `verify` checks.
#[test]
fn results_written_into_a_sealed_folder_are_bound_to_what_the_seal_holds() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = sealed_run(tmp.path());
    let imu = std::fs::read(dir.join("imu.csv")).unwrap();
    let results = std::fs::read(dir.join("results.json")).unwrap();
    // Tamper, re-analyse into the folder, restore: refused before anything is written.
    let text_imu = String::from_utf8(imu.clone()).unwrap();
    let mut lines: Vec<&str> = text_imu.lines().collect();
    let tampered = lines[5].replacen(',', ",9", 2);
    lines[5] = &tampered;
    std::fs::write(dir.join("imu.csv"), lines.join("\n") + "\n").unwrap();
    let o = ratecal(&["analyze", "r", "--out", "r/results.json"], tmp.path());
    assert_eq!(code(&o), 4, "{}", text(&o));
    assert!(
        text(&o).contains("fails its seal (imu.csv)"),
        "{}",
        text(&o)
    );
    assert_eq!(std::fs::read(dir.join("results.json")).unwrap(), results);
    std::fs::write(dir.join("imu.csv"), &imu).unwrap();
    let o = ratecal(&["verify", "r"], tmp.path());
    assert_eq!(code(&o), 0, "{}", text(&o));

    // An intact folder: the addition records the hashes of the files it read.
    let o = ratecal(&["analyze", "r", "--out", "r/results.json"], tmp.path());
    assert!(matches!(code(&o), 0 | 3), "{}", text(&o));
    let seal = json(&dir.join("seal.json"));
    let last = seal["added"].as_array().unwrap().last().unwrap().clone();
    assert_eq!(
        last["inputs"]["imu.csv"], seal["files"]["imu.csv"],
        "{seal:#}"
    );
    assert!(last["inputs"].get("manifest.yaml").is_some(), "{seal:#}");

    // A forged record of what it read (the seal's own hash made to match): verify says so.
    let sealed = std::fs::read_to_string(dir.join("seal.json")).unwrap();
    let held = seal["files"]["imu.csv"].as_str().unwrap();
    // The last record of imu.csv is the one in the addition's inputs.
    let at = sealed.rfind(&format!("\"imu.csv\": \"{held}\"")).unwrap();
    let forged = format!(
        "{}{}",
        &sealed[..at],
        sealed[at..].replacen(held, &"0".repeat(64), 1)
    );
    assert_ne!(forged, sealed, "{sealed}");
    std::fs::write(dir.join("seal.json"), &forged).unwrap();
    use sha2::Digest;
    let h = hex::encode(sha2::Sha256::digest(forged.as_bytes()));
    std::fs::write(dir.join("seal.sha256"), format!("{h}  seal.json\n")).unwrap();
    let o = ratecal(&["verify", "r"], tmp.path());
    assert_eq!(code(&o), 1, "{}", text(&o));
    assert!(
        text(&o).contains("as read by `ratecal analyze"),
        "{}",
        text(&o)
    );
}

/// An approval covers what it approved: a later addition is listed after it and leaves it
/// standing; approving again replaces it; the run is still archived.
#[test]
fn an_approval_survives_later_additions() {
    let tmp = tempfile::tempdir().unwrap();
    sealed_run(tmp.path());
    let approve = |t: &Path| ratecal(APPROVE, t);
    let o = ratecal(&["key", "new", "keys"], tmp.path());
    assert_eq!(code(&o), 0, "{}", text(&o));
    let o = approve(tmp.path());
    assert_eq!(code(&o), 0, "{}", text(&o));
    let o = ratecal(&["report", "r", "--out", "r/again.md"], tmp.path());
    assert_eq!(code(&o), 0, "{}", text(&o));
    let o = ratecal(&["analyze", "r", "--out", "r/results.json"], tmp.path());
    assert!(matches!(code(&o), 0 | 3), "{}", text(&o));
    let o = ratecal(&["verify", "r"], tmp.path());
    assert_eq!(code(&o), 0, "{}", text(&o));
    let words = text(&o).split_whitespace().collect::<Vec<_>>().join(" ");
    assert!(words.contains("again.md (written by"), "{}", text(&o));
    assert!(
        words.contains("after the approval: not approved"),
        "{}",
        text(&o)
    );
    // Approving again replaces it, covering the additions.
    let o = approve(tmp.path());
    assert_eq!(code(&o), 0, "{}", text(&o));
    let o = ratecal(&["verify", "r"], tmp.path());
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert!(!text(&o).contains("after the approval"), "{}", text(&o));
    let o = ratecal(&["archive", "add", "r", "--archive", "archive"], tmp.path());
    assert_eq!(code(&o), 0, "{}", text(&o));
}

/// A rate that makes the span absurd (1e-300 Hz, 0.001 Hz, 1e300 Hz) is refused at the
/// map, located, before a row is written.
#[test]
fn an_absurd_sampling_rate_is_refused_before_anything_is_written() {
    let tmp = tempfile::tempdir().unwrap();
    let map = std::fs::read_to_string(import_map("ferraris.yaml")).unwrap();
    std::fs::write(tmp.path().join("s.csv"), "a,b\n1,2\n").unwrap();
    for rate in ["1e-300", "0.001", "1e300"] {
        let m = map.replace("rate_hz: 102.4", &format!("rate_hz: {rate}"));
        assert_ne!(m, map);
        std::fs::write(tmp.path().join("m.yaml"), m).unwrap();
        let o = ratecal(
            &["import", "s.csv", "--map", "m.yaml", "--out", "out"],
            tmp.path(),
        );
        assert_eq!(code(&o), 1, "{rate}: {}", text(&o));
        assert!(
            text(&o).contains("is no IMU's sampling rate"),
            "{rate}: {}",
            text(&o)
        );
        assert!(text(&o).contains("m.yaml:"), "{rate}: {}", text(&o));
        assert!(!tmp.path().join("out").exists(), "{rate}");
    }
}

/// A source with no line break is refused at a bounded length, and the diagnostic quotes a
/// bounded snippet of it (never the line).
#[test]
fn a_line_without_end_is_refused_with_a_bounded_diagnostic() {
    let tmp = tempfile::tempdir().unwrap();
    let map = std::fs::read_to_string(import_map("ferraris.yaml")).unwrap();
    std::fs::write(tmp.path().join("m.yaml"), map).unwrap();
    std::fs::write(tmp.path().join("s.csv"), "x".repeat(3 << 20)).unwrap();
    let o = ratecal(
        &["import", "s.csv", "--map", "m.yaml", "--out", "out"],
        tmp.path(),
    );
    assert_eq!(code(&o), 1, "{}", text(&o));
    assert!(
        o.stderr.len() < 8192,
        "{} bytes of diagnostic",
        o.stderr.len()
    );
    assert!(!tmp.path().join("out").exists());
}
