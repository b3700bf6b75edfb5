//! `ratecal run` end to end: exit codes, the run folder, aborts driven by station files,
//! `--resume`.

use crate::support;
use std::path::Path;
use std::process::Command;
use support::{MINI, code, ratecal, station_with, text};

fn manifest(dir: &Path) -> ratecal_recording::Manifest {
    ratecal_recording::parse_manifest(
        "manifest.yaml",
        &std::fs::read_to_string(dir.join("manifest.yaml")).unwrap(),
    )
    .unwrap()
}

#[test]
fn usage_and_input_errors() {
    let tmp = tempfile::tempdir().unwrap();
    assert_eq!(code(&ratecal(&["run"], tmp.path())), 2);
    assert_eq!(
        code(&ratecal(&["run", "nope.rcal", "--bogus"], tmp.path())),
        2
    );
    let o = ratecal(&["run", "missing.rcal"], tmp.path());
    assert_eq!(code(&o), 1, "{}", text(&o));
    std::fs::write(tmp.path().join("p.rcal"), MINI).unwrap();
    std::fs::write(
        tmp.path().join("bad.yaml"),
        "site: { latitude_deg: 55.7, gravity_mps2: 9.81 }\nbogus_key: 1\n",
    )
    .unwrap();
    let o = ratecal(&["run", "p.rcal", "--station", "bad.yaml"], tmp.path());
    assert_eq!(code(&o), 1, "{}", text(&o));
    assert!(text(&o).contains("bad.yaml"), "{}", text(&o));
    std::fs::write(
        tmp.path().join("broken.rcal"),
        "procedure broken version 1.0.0 {\n  step {\n",
    )
    .unwrap();
    let o = ratecal(&["run", "broken.rcal", "--dry-run"], tmp.path());
    assert_eq!(code(&o), 1, "{}", text(&o));
    assert!(
        !tmp.path().join("runs").exists(),
        "no run folder for an input error"
    );
}

#[test]
fn dry_run_writes_the_run_folder() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("p.rcal"), MINI).unwrap();
    let o = ratecal(
        &[
            "run",
            "p.rcal",
            "--dry-run",
            "--out",
            "r1",
            "--seed",
            "5",
            "--operator",
            "ada",
        ],
        tmp.path(),
    );
    assert!(matches!(code(&o), 0 | 3), "{}", text(&o));
    let dir = tmp.path().join("r1");
    for f in [
        "manifest.yaml",
        "imu.csv",
        "table.csv",
        "journal.jsonl",
        "procedure.rcal",
        "station.yaml",
        "results.json",
    ] {
        assert!(dir.join(f).exists(), "{f}");
    }
    let m = manifest(&dir);
    let ids: Vec<_> = m.segments.iter().map(|s| s.id.as_str()).collect();
    assert_eq!(
        ids,
        ["accel_static/1", "accel_static/2", "gyro_scale/outer/+50"]
    );
    let run = m.run.unwrap();
    assert_eq!(
        (
            run.status.as_str(),
            run.seed,
            run.operator.as_deref(),
            run.dry_run
        ),
        ("completed", Some(5), Some("ada"), true)
    );
    let canon = ratecal_grammar::canonical(MINI).unwrap();
    assert_eq!(m.procedure.unwrap().sha256, canon.sha256);
    let rec = ratecal_recording::read(&dir).unwrap();
    assert!(rec.imu.t[0] >= 0.0 && rec.imu.t[0] < 0.02);
    assert!(text(&o).contains("run folder"));
    // Same seed, same recording.
    let o = ratecal(
        &["run", "p.rcal", "--dry-run", "--out", "r2", "--seed", "5"],
        tmp.path(),
    );
    assert!(matches!(code(&o), 0 | 3));
    let same = std::fs::read(dir.join("imu.csv")).unwrap()
        == std::fs::read(tmp.path().join("r2/imu.csv")).unwrap();
    assert!(same, "same seed, different imu.csv");
}

#[test]
fn station_fault_aborts_with_4_and_resume_completes() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("p.rcal"), MINI).unwrap();
    // A lab excursion during the rate step (after both static segments).
    let fault = "faults: [ { temperature_excursion: { at: 36 s, delta: 4 degC, ramp: 1 s, duration: 600 s } } ]";
    std::fs::write(tmp.path().join("st.yaml"), station_with(fault)).unwrap();
    let o = ratecal(
        &[
            "run",
            "p.rcal",
            "--station",
            "st.yaml",
            "--dry-run",
            "--out",
            "r",
        ],
        tmp.path(),
    );
    assert_eq!(code(&o), 4, "{}", text(&o));
    assert!(text(&o).contains("ABORTED"));
    let dir = tmp.path().join("r");
    let m = manifest(&dir);
    let run = m.run.as_ref().unwrap();
    assert_eq!(run.status, "aborted");
    let abort = run.abort.as_ref().unwrap();
    assert!(abort.rule.contains("ambient.temperature"), "{}", abort.rule);
    let rec = ratecal_recording::read(&dir).unwrap();
    assert!(*rec.imu.t.last().unwrap() >= abort.t - 0.02);

    // The lab recovers; the run resumes with the station file it started with (the
    // excursion is timed from the start of each part, after the rest of this one).
    let o = ratecal(&["run", "--resume", "r"], tmp.path());
    assert_eq!(code(&o), 0, "{}", text(&o));
    let m = manifest(&dir);
    let ids: Vec<_> = m.segments.iter().map(|s| s.id.as_str()).collect();
    assert_eq!(
        ids,
        ["accel_static/1", "accel_static/2", "gyro_scale/outer/+50"]
    );
    assert_eq!(m.run.as_ref().unwrap().status, "completed");
    assert!(m.segments[2].t_start > abort.t);
    // The manifest and the report say where it was interrupted and when it resumed; the
    // folder is sealed again and verifies.
    let resumes = &m.run.as_ref().unwrap().resumes;
    assert_eq!(resumes.len(), 1, "{resumes:?}");
    assert_eq!(resumes[0].interrupted_status, "aborted");
    assert_eq!(resumes[0].step.as_deref(), Some("rates"));
    let report = std::fs::read_to_string(dir.join("report.md")).unwrap();
    assert!(report.contains("Interrupted (aborted) at t ="), "{report}");
    let o = ratecal(&["verify", "r"], tmp.path());
    assert_eq!(code(&o), 0, "{}", text(&o));
    // One recording, time increasing through the resume; it reads back.
    ratecal_recording::read(&dir).unwrap();
    // Nothing left to resume.
    assert_eq!(code(&ratecal(&["run", "--resume", "r"], tmp.path())), 1);
}

/// A procedure whose settle time comes from a lab file: the run folder keeps a copy of the
/// import, and `--resume` checks against that copy even after the lab file has gone.
#[test]
fn imports_are_kept_in_the_run_folder_and_resume_uses_them() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(tmp.path().join("procs")).unwrap();
    std::fs::create_dir_all(tmp.path().join("lab")).unwrap();
    let limits = "param settle_min = 5 s\n";
    std::fs::write(tmp.path().join("lab/limits.rcal"), limits).unwrap();
    let with_import = format!(
        "import \"../lab/limits.rcal\"\n\n{}",
        MINI.replace("at least 5 s", "at least settle_min")
    );
    std::fs::write(tmp.path().join("procs/p.rcal"), with_import).unwrap();
    let fault = "faults: [ { temperature_excursion: { at: 36 s, delta: 4 degC, ramp: 1 s, duration: 600 s } } ]";
    std::fs::write(tmp.path().join("st.yaml"), station_with(fault)).unwrap();
    let args = [
        "run",
        "procs/p.rcal",
        "--station",
        "st.yaml",
        "--dry-run",
        "--out",
        "r",
    ];
    let o = ratecal(&args, tmp.path());
    assert_eq!(code(&o), 4, "{}", text(&o));
    let dir = tmp.path().join("r");
    let copy = dir.join("imports/^/lab/limits.rcal");
    assert_eq!(std::fs::read_to_string(&copy).unwrap(), limits);

    // The lab file is gone by the time the run resumes.
    std::fs::remove_file(tmp.path().join("lab/limits.rcal")).unwrap();
    let o = ratecal(&["run", "--resume", "r"], tmp.path());
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert_eq!(manifest(&dir).run.as_ref().unwrap().status, "completed");

    // The copy is part of what `verify` checks.
    let o = ratecal(&["verify", "r"], tmp.path());
    assert_eq!(code(&o), 0, "{}", text(&o));
    std::fs::write(&copy, "param settle_min = 1 s\n").unwrap();
    let o = ratecal(&["verify", "r"], tmp.path());
    assert_eq!(code(&o), 1, "{}", text(&o));
    assert!(
        text(&o).contains("imports/^/lab/limits.rcal"),
        "{}",
        text(&o)
    );

    // A new run from the lab's files, now without the import, names what it lacks.
    let o = ratecal(
        &["run", "procs/p.rcal", "--dry-run", "--out", "r2"],
        tmp.path(),
    );
    assert_eq!(code(&o), 1, "{}", text(&o));
    assert!(text(&o).contains("limits.rcal"), "{}", text(&o));
}

#[test]
fn standard_procedure_dry_run_passes() {
    let tmp = tempfile::tempdir().unwrap();
    let proc_dir = concat!(env!("CARGO_MANIFEST_DIR"), "/procedures/imu-2d-standard");
    let o = ratecal(
        &["run", proc_dir, "--dry-run", "--out", "std", "--seed", "11"],
        tmp.path(),
    );
    assert_eq!(code(&o), 0, "{}", text(&o));
    let m = manifest(&tmp.path().join("std"));
    assert_eq!(m.procedure.as_ref().unwrap().name, "imu-2d-standard");
    let bias = m.segments.iter().find(|s| s.id == "gyro_bias").unwrap();
    assert!((bias.t_end - bias.t_start - 3600.0).abs() < 1e-9);
    assert_eq!(
        m.segments
            .iter()
            .filter(|s| s.id.starts_with("accel_static/"))
            .count(),
        6
    );
    // Its repeatability check (over 3 runs) is deferred, not failing: the verdict is pass.
    let results: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(tmp.path().join("std/results.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(results["verdict"], "pass", "{}", text(&o));
    let cv = results["acceptance"]
        .as_array()
        .unwrap()
        .iter()
        .find(|a| a["quantity"] == "repeatability.cv")
        .unwrap();
    assert_eq!(cv["verdict"], "deferred", "{cv}");
    let report = std::fs::read_to_string(tmp.path().join("std/report.md")).unwrap();
    assert!(
        report.contains("Deferred to the analysis over several runs"),
        "{report}"
    );
    assert!(text(&o).contains("verdict: PASS"), "{}", text(&o));
}

/// Ctrl-C (SIGINT) in the middle of a dry run: the run stops on the abort path, exit 4,
/// and the recording holds every sample up to the stop, readable as it is.
#[test]
fn ctrl_c_aborts_with_4_and_keeps_the_recording() {
    if Command::new("kill").arg("-l").output().is_err() {
        println!("skipped: no kill program");
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let proc_dir = concat!(env!("CARGO_MANIFEST_DIR"), "/procedures/imu-2d-standard");
    let mut child = Command::new(env!("CARGO_BIN_EXE_ratecal"))
        .args(["run", proc_dir, "--dry-run", "--out", "cut"])
        .current_dir(tmp.path())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let imu = tmp.path().join("cut/imu.csv");
    let t0 = std::time::Instant::now();
    // Wait for the first rows on disk (the run is under way), then interrupt.
    while std::fs::metadata(&imu).map_or(0, |m| m.len()) < 10_000 {
        assert!(t0.elapsed().as_secs() < 60, "the run never started writing");
        if child.try_wait().unwrap().is_some() {
            println!("skipped: the dry run ended before it could be interrupted");
            return;
        }
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
    let killed = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let out = child.wait_with_output().unwrap();
    let m = manifest(&tmp.path().join("cut"));
    let run = m.run.as_ref().unwrap();
    if out.status.code() == Some(0) {
        // Finished between the check and the signal: nothing to interrupt any more.
        println!("skipped: the dry run completed before the signal arrived");
        return;
    }
    assert_eq!(out.status.code(), Some(4), "{}", text(&out));
    assert_eq!(run.status, "aborted");
    assert!(
        run.abort.as_ref().unwrap().rule.contains("Ctrl-C"),
        "{:?}",
        run.abort
    );
    let rec = ratecal_recording::read(&tmp.path().join("cut")).unwrap();
    // Every sample up to the stop is on disk: the IMU stream reaches the abort time.
    let t_abort = run.abort.as_ref().unwrap().t;
    let last = rec.imu.t[rec.imu.t.len() - 1];
    assert!(
        last >= t_abort - 0.1,
        "imu ends at {last} s, abort at {t_abort} s"
    );
}
