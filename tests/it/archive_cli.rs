//! `ratecal archive` on a folder archive (embedded SQLite + file store) in a temporary
//! folder: round trip through `ratecal run`, refusal of altered folders, filters, a manifest
//! without a serial, two processes adding at once, a process killed mid-add, a corrupted
//! stored file.

use crate::archive_common;
use archive_common::*;
use std::path::Path;

const MINI: &str = r#"procedure mini version 1.0.0 {
  title "One attitude"
  imu class tactical

  step statics "One static attitude" {
    move to pitch 0 deg, roll 0 deg
    settle {
      at least 2 s
      table.attitude_error <= 5 arcsec
      timeout 60 s -> abort
    }
    acquire accel, gyro, table for 5 s at 100 Hz as "accel_static/1"
  }
}
"#;

#[test]
fn run_adds_itself_and_export_gives_the_folder_back() {
    let tmp = tempfile::tempdir().unwrap();
    let cwd = tmp.path();
    std::fs::write(cwd.join("p.rcal"), MINI).unwrap();
    let o = ratecal(
        &[
            "run",
            "p.rcal",
            "--dry-run",
            "--out",
            "r1",
            "--archive",
            "arch",
        ],
        cwd,
    );
    assert!(matches!(code(&o), 0 | 3), "{}", text(&o));
    assert!(text(&o).contains("archived"), "{}", text(&o));
    // A dry run is archived, but listed only on request.
    assert!(list("arch", &[], cwd).is_empty());
    let runs = list("arch", &["--include-dry-runs"], cwd);
    assert_eq!(runs.len(), 1);
    let r = &runs[0];
    for key in [
        "id",
        "serial",
        "model",
        "procedure",
        "version",
        "started",
        "verdict",
        "dry_run",
    ] {
        assert!(r.get(key).is_some(), "{key} in {r}");
    }
    assert_eq!(r["serial"], "SIM-0001");
    assert_eq!(r["procedure"], "mini");
    assert_eq!(r["dry_run"], true);
    let id = r["id"].as_str().unwrap().to_string();

    // Adding the same folder again changes nothing.
    let o = ratecal(&["archive", "add", "r1", "--archive", "arch"], cwd);
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert!(text(&o).contains("already archived"));
    assert_eq!(list("arch", &["--include-dry-runs"], cwd).len(), 1);

    // Export by id prefix: byte-identical, and `ratecal verify` passes on it.
    let o = ratecal(
        &["archive", "export", &id[..8], "back", "--archive", "arch"],
        cwd,
    );
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert_eq!(tree(&cwd.join("r1")), tree(&cwd.join("back")));
    let o = ratecal(&["verify", "back"], cwd);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let o = ratecal(&["report", "back", "--out", "back-report.md"], cwd);
    assert_eq!(code(&o), 0, "{}", text(&o));

    let o = ratecal(
        &[
            "archive",
            "show",
            &id,
            "--format",
            "json",
            "--archive",
            "arch",
        ],
        cwd,
    );
    assert_eq!(code(&o), 0, "{}", text(&o));
    let show: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(show["id"], id.as_str());
    assert!(show["files"].as_array().unwrap().len() >= 6);

    // An altered folder is refused, with the reason.
    std::fs::write(cwd.join("r1/imu.csv"), "t,ax\n0,1\n").unwrap();
    let o = ratecal(&["archive", "add", "r1", "--archive", "arch"], cwd);
    assert_eq!(code(&o), 1, "{}", text(&o));
    assert!(
        text(&o).contains("altered") && text(&o).contains("imu.csv"),
        "{}",
        text(&o)
    );
    let o = ratecal(&["archive", "check", "--archive", "arch"], cwd);
    assert_eq!(code(&o), 0, "{}", text(&o));
}

#[test]
fn filters_env_default_and_a_manifest_without_serial() {
    let tmp = tempfile::tempdir().unwrap();
    let cwd = tmp.path();
    write_run(
        &cwd.join("a"),
        Some("1234"),
        "2025-03-01T10:00:00Z",
        0.01,
        &[],
    );
    write_run(
        &cwd.join("b"),
        Some("1234"),
        "2026-03-01T10:00:00Z",
        0.012,
        &[],
    );
    write_run(&cwd.join("c"), None, "2026-06-15T08:30:00Z", 0.02, &[]);
    // Default archive: ./archive/.
    let o = ratecal(&["archive", "add", "a", "b", "c"], cwd);
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert!(cwd.join("archive/index.sqlite").exists());
    assert_eq!(list("archive", &["--serial", "1234"], cwd).len(), 2);
    let unknown = list(
        "archive",
        &["--since", "2026-06-15", "--until", "2026-06-15"],
        cwd,
    );
    assert_eq!(unknown.len(), 1);
    assert_eq!(unknown[0]["serial"], "unknown");
    assert_eq!(list("archive", &["--serial", "unknown"], cwd).len(), 1);
    assert_eq!(
        list(
            "archive",
            &["--verdict", "pass", "--model", "SIM-TAC-100"],
            cwd
        )
        .len(),
        3
    );
    assert!(list("archive", &["--verdict", "fail"], cwd).is_empty());
    assert_eq!(list("archive", &["--until", "2025-12-31"], cwd).len(), 1);
    // RATECAL_ARCHIVE names the archive.
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_ratecal"))
        .args(["archive", "list", "--format", "json", "--serial", "1234"])
        .env("RATECAL_ARCHIVE", cwd.join("archive"))
        .output()
        .unwrap();
    let v: Vec<serde_json::Value> = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v.len(), 2);
    // Trend: two dates, a limit; JSON and SVG.
    let o = ratecal(
        &[
            "archive",
            "trend",
            "1234",
            "--param",
            "accel.bias.x",
            "--format",
            "json",
        ],
        cwd,
    );
    assert_eq!(code(&o), 0, "{}", text(&o));
    let t: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(t["parameters"][0]["drift_status"], "determined");
    assert!(t["parameters"][0]["recalibration_days"].as_f64().unwrap() > 0.0);
    let o = ratecal(&["archive", "trend", "1234", "--format", "svg"], cwd);
    assert!(String::from_utf8_lossy(&o.stdout).starts_with("<svg"));
    // One calibration: undetermined, still exit 0.
    let o = ratecal(&["archive", "trend", "unknown"], cwd);
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert!(text(&o).contains("undetermined"), "{}", text(&o));
    // User errors are diagnostics, not panics.
    let o = ratecal(&["archive", "list", "--since", "last tuesday"], cwd);
    assert_eq!(code(&o), 1);
    assert!(text(&o).contains("archive::bad_date"), "{}", text(&o));
    let o = ratecal(&["archive", "show", "ffffffff"], cwd);
    assert_eq!(code(&o), 1);
    assert!(text(&o).contains("archive::no_such_run"), "{}", text(&o));
    let o = ratecal(&["archive", "list", "--archive", "no-such-archive"], cwd);
    assert_eq!(code(&o), 1);
    assert!(text(&o).contains("archive::no_archive"), "{}", text(&o));
    assert!(!cwd.join("no-such-archive").exists());
    let o = ratecal(&["archive", "add", "nowhere"], cwd);
    assert_eq!(code(&o), 1);
    assert!(text(&o).contains("not a run folder"), "{}", text(&o));
    // Backup: another archive that opens and holds the same runs.
    let o = ratecal(&["archive", "backup", "copy"], cwd);
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert_eq!(list("copy", &[], cwd), list("archive", &[], cwd));
    let o = ratecal(&["archive", "check", "--archive", "copy"], cwd);
    assert_eq!(code(&o), 0, "{}", text(&o));
}

#[test]
fn two_processes_adding_at_once_lose_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let cwd = tmp.path();
    let names: Vec<String> = (0..8).map(|i| format!("r{i}")).collect();
    for (i, n) in names.iter().enumerate() {
        let day = format!("2026-01-{:02}T00:00:00Z", i + 1);
        write_run(&cwd.join(n), Some("42"), &day, 0.001 * i as f64, &[]);
    }
    let spawn = |runs: &[String]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_ratecal"))
            .args(["archive", "add", "--archive", "arch"])
            .args(runs)
            .current_dir(cwd)
            .env_remove("RATECAL_ARCHIVE")
            .output()
    };
    let (a, b) = std::thread::scope(|s| {
        let a = s.spawn(|| spawn(&names[..4]).unwrap());
        let b = s.spawn(|| spawn(&names[4..]).unwrap());
        (a.join().unwrap(), b.join().unwrap())
    });
    assert_eq!(code(&a), 0, "{}", text(&a));
    assert_eq!(code(&b), 0, "{}", text(&b));
    assert_eq!(list("arch", &["--serial", "42"], cwd).len(), 8);
    let o = ratecal(&["archive", "check", "--archive", "arch"], cwd);
    assert_eq!(code(&o), 0, "{}", text(&o));
}

fn count_blobs(files: &Path) -> usize {
    std::fs::read_dir(files)
        .map(|rd| {
            rd.flatten()
                .filter(|e| e.file_name() != "tmp" && e.path().is_dir())
                .map(|e| std::fs::read_dir(e.path()).map_or(0, |r| r.count()))
                .sum()
        })
        .unwrap_or(0)
}

#[test]
fn a_process_killed_mid_add_leaves_the_archive_consistent() {
    let tmp = tempfile::tempdir().unwrap();
    let cwd = tmp.path();
    // Many files, so that the add is still storing them when it is killed.
    let extra: Vec<(String, Vec<u8>)> = (0..120)
        .map(|i| (format!("extra/f{i:03}.bin"), vec![i as u8; 150_000]))
        .collect();
    let extra_ref: Vec<(&str, Vec<u8>)> =
        extra.iter().map(|(n, b)| (n.as_str(), b.clone())).collect();
    write_run(
        &cwd.join("big"),
        Some("9"),
        "2026-02-02T00:00:00Z",
        0.0,
        &extra_ref,
    );
    // The archive exists (schema made, one run) before the add starts.
    write_run(
        &cwd.join("small"),
        Some("9"),
        "2026-02-01T00:00:00Z",
        0.1,
        &[],
    );
    let o = ratecal(&["archive", "add", "small", "--archive", "arch"], cwd);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_ratecal"))
        .args(["archive", "add", "big", "--archive", "arch"])
        .current_dir(cwd)
        .env_remove("RATECAL_ARCHIVE")
        .stdout(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let files = cwd.join("arch/files");
    let start = std::time::Instant::now();
    while count_blobs(&files) < 5 && start.elapsed().as_secs() < 30 {
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
    child.kill().unwrap();
    let status = child.wait().unwrap();
    let runs = list("arch", &[], cwd);
    if status.success() {
        eprintln!("note: the add finished before it could be killed");
    } else {
        // Files first, index last: the run is not visible.
        assert_eq!(runs.len(), 1, "{runs:?}");
    }
    let o = ratecal(&["archive", "check", "--archive", "arch"], cwd);
    assert_eq!(code(&o), 0, "{}", text(&o));
    // Adding it again completes it.
    let o = ratecal(&["archive", "add", "big", "--archive", "arch"], cwd);
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert_eq!(list("arch", &[], cwd).len(), 2);
    let o = ratecal(&["archive", "check", "--archive", "arch"], cwd);
    assert_eq!(code(&o), 0, "{}", text(&o));
}

#[test]
fn a_corrupted_stored_file_is_found_by_check() {
    let tmp = tempfile::tempdir().unwrap();
    let cwd = tmp.path();
    write_run(
        &cwd.join("r"),
        Some("5"),
        "2026-04-01T00:00:00Z",
        0.003,
        &[],
    );
    let o = ratecal(&["archive", "add", "r", "--archive", "arch"], cwd);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let imu_sha = sha(&std::fs::read(cwd.join("r/imu.csv")).unwrap());
    let stored = cwd.join("arch/files").join(&imu_sha[..2]).join(&imu_sha);
    std::fs::write(&stored, b"bit rot").unwrap();
    let o = ratecal(&["archive", "check", "--archive", "arch"], cwd);
    assert_eq!(code(&o), 1, "{}", text(&o));
    assert!(
        text(&o).contains("CORRUPTED") && text(&o).contains("imu.csv"),
        "{}",
        text(&o)
    );
    let id = list("arch", &[], cwd)[0]["id"]
        .as_str()
        .unwrap()
        .to_string();
    let o = ratecal(&["archive", "export", &id, "out", "--archive", "arch"], cwd);
    assert_eq!(code(&o), 1);
    assert!(text(&o).contains("archive::missing_file"), "{}", text(&o));
    // A missing stored file too.
    std::fs::remove_file(&stored).unwrap();
    let o = ratecal(
        &["archive", "check", "--archive", "arch", "--format", "json"],
        cwd,
    );
    assert_eq!(code(&o), 1);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["missing"].as_array().unwrap().len(), 1);
}

/// The report's conclusions use the unit's history when an archive is named: how many
/// calibrations since when, each determined drift per year, and the recalibration interval
/// the drift implies against the acceptance limit; without an archive they keep the
/// procedure's (or the default) interval.
#[test]
fn the_report_concludes_from_the_archived_history() {
    let tmp = tempfile::tempdir().unwrap();
    let cwd = tmp.path();
    write_run(
        &cwd.join("a"),
        Some("1234"),
        "2025-03-01T10:00:00Z",
        0.01,
        &[],
    );
    write_run(
        &cwd.join("b"),
        Some("1234"),
        "2026-03-01T10:00:00Z",
        0.012,
        &[],
    );
    let o = ratecal(&["archive", "add", "a", "b"], cwd);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let o = ratecal(&["report", "b", "--archive", "archive"], cwd);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let md = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(
        md.contains("The lab's archive holds 2 calibrations of serial 1234 since 2025-03-01."),
        "{md}"
    );
    // 0.010 -> 0.012 m/s^2 in a year: 0.0020 m/s^2 per year.
    assert!(md.contains("accel.bias.x 0.0020"), "{md}");
    assert!(md.contains("m/s²/year.\n- Recalibrate every"), "{md}");
    // The limit is 0.05 m/s^2: the drift reaches it years on; the interval says by when.
    let t = ratecal(
        &[
            "archive",
            "trend",
            "1234",
            "--param",
            "accel.bias.x",
            "--format",
            "json",
        ],
        cwd,
    );
    let t: serde_json::Value = serde_json::from_slice(&t.stdout).unwrap();
    let by = t["parameters"][0]["recalibrate_by"].as_str().unwrap();
    assert!(
        md.contains(&format!("(by {by}: the archive's trend of accel.bias.x")),
        "{md}"
    );
    // Without an archive: no history, the default interval.
    let o = ratecal(&["report", "b"], cwd);
    let md = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(!md.contains("The lab's archive holds"), "{md}");
    assert!(md.contains("Recalibrate every 12 months"), "{md}");
}
