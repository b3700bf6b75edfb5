//! Crash-consistent run folders (issue 26): the real binary is stopped at named points
//! (`RATECAL_CRASH_AT`, an abort as abrupt as a kill) and by SIGKILL at moments across
//! `run`, `run --resume`, `analyze --out` and `archive add`; after each, the folder must be
//! in a named state that `verify` names (0 sealed and intact, 4 never sealed; never
//! "altered"), that `run --resume` finishes, and that `archive add` then takes: nothing
//! lost, nothing sealed that does not read back. The wide time sweep is ignored in CI:
//! `cargo test --test it crash_cli:: -- --ignored`.

use crate::support;
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::Duration;
use support::*;

/// `ratecal args` in `cwd`, aborting at the named point.
fn crash_at(point: &str, args: &[&str], cwd: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_ratecal"))
        .args(args)
        .current_dir(cwd)
        .env("RATECAL_CRASH_AT", point)
        .output()
        .unwrap()
}

/// `ratecal args` in `cwd`, SIGKILLed after `ms` (if still running); whether it was killed.
fn kill_after(ms: u64, args: &[&str], cwd: &Path) -> bool {
    let mut child = Command::new(env!("CARGO_BIN_EXE_ratecal"))
        .args(args)
        .current_dir(cwd)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(ms));
    let killed = matches!(child.try_wait(), Ok(None));
    let _ = child.kill();
    child.wait().unwrap();
    killed
}

/// `verify`'s verdict on a folder a crash left: 0 (sealed, intact) or 4 (never sealed, or a
/// change left unfinished), with its output; never 1 (altered) or anything else. `None`
/// when the crash came before the run folder held a manifest (nothing was recorded).
fn named_state(dir: &Path, cwd: &Path, what: &str) -> Option<i32> {
    if !dir.join("manifest.yaml").exists() {
        return None;
    }
    let o = ratecal(&["verify", &dir.display().to_string()], cwd);
    let c = code(&o);
    assert!(matches!(c, 0 | 4), "{what}: verify exit {c}\n{}", text(&o));
    if c == 4 {
        assert!(text(&o).contains("ratecal run --resume"), "{}", text(&o));
    }
    Some(c)
}

/// Resumes until the folder is a completed run, sealed (at most `max` resumes), then
/// requires that it verifies, reads back whole (every segment of MINI), and is archived.
fn finish_and_check(dir: &Path, cwd: &Path, what: &str) {
    let d = dir.display().to_string();
    for _ in 0..4 {
        let o = ratecal(&["run", "--resume", &d], cwd);
        if text(&o).contains("nothing to resume") {
            break;
        }
        assert!(matches!(code(&o), 0 | 4), "{what}: resume\n{}", text(&o));
    }
    let o = ratecal(&["verify", &d], cwd);
    assert_eq!(code(&o), 0, "{what}: {}", text(&o));
    let rec = ratecal_recording::read(dir)
        .unwrap_or_else(|e| panic!("{what}: sealed but unreadable: {e}"));
    let run = rec.manifest.run.as_ref().unwrap();
    assert_eq!(run.status, "completed", "{what}");
    let ids: Vec<&str> = rec
        .manifest
        .segments
        .iter()
        .map(|s| s.id.as_str())
        .collect();
    assert_eq!(
        ids,
        ["accel_static/1", "accel_static/2", "gyro_scale/outer/+50"],
        "{what}"
    );
    assert!(rec.imu.t.windows(2).all(|w| w[1] > w[0]), "{what}");
    let o = ratecal(&["archive", "add", &d, "--archive", "arc"], cwd);
    assert_eq!(code(&o), 0, "{what}: {}", text(&o));
}

/// Named points of a new run, from its first file to its seal.
const RUN_POINTS: &[&str] = &[
    "before-rename-manifest.yaml",
    "after-create",
    "after-checkpoint#2",
    "after-checkpoint#3",
    "after-manifest",
    "after-results",
    "after-reports",
    "before-seal-intent",
    "after-intent",
    "after-move-seal.json",
];

#[test]
fn a_run_stopped_at_any_named_point_is_finished_by_resume() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("p.rcal"), MINI).unwrap();
    for (k, point) in RUN_POINTS.iter().enumerate() {
        let out = format!("r{k}");
        let o = crash_at(
            point,
            &["run", "p.rcal", "--dry-run", "--out", &out],
            tmp.path(),
        );
        assert_eq!(o.status.code(), None, "{point}: did not stop\n{}", text(&o));
        let dir = tmp.path().join(&out);
        let state = named_state(&dir, tmp.path(), point);
        if state.is_none() {
            // Stopped before its first manifest: never a recording; `run --out` starts again.
            let o = ratecal(&["run", "p.rcal", "--dry-run", "--out", &out], tmp.path());
            assert!(matches!(code(&o), 0 | 3), "{point}: {}", text(&o));
        }
        // A run that ended but was never sealed says so, and its streams still vouch for it.
        if ["after-manifest", "after-results", "after-reports"].contains(point) {
            assert_eq!(state, Some(4), "{point}");
            let o = ratecal(&["verify", &out], tmp.path());
            assert!(text(&o).contains("recorded-unsealed"), "{}", text(&o));
            // Not archived, not reported from, before it is sealed.
            let o = ratecal(&["archive", "add", &out, "--archive", "arc"], tmp.path());
            assert_ne!(code(&o), 0, "{point}: {}", text(&o));
        }
        finish_and_check(&dir, tmp.path(), point);
    }
}

#[test]
fn a_tail_written_after_the_last_record_is_cut_by_resume_and_said() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("p.rcal"), MINI).unwrap();
    let o = crash_at(
        "after-checkpoint#2",
        &["run", "p.rcal", "--dry-run", "--out", "r"],
        tmp.path(),
    );
    assert_eq!(o.status.code(), None, "{}", text(&o));
    let o = ratecal(&["verify", "r"], tmp.path());
    assert_eq!(code(&o), 4, "{}", text(&o));
    assert!(
        text(&o).contains("NEVER SEALED r (recording)"),
        "{}",
        text(&o)
    );
    // Rows the crash wrote after the journal's last block record (a torn one last).
    let path = tmp.path().join("r/imu.csv");
    let tail = "9000.000000,0,0,9.8,0,0,0,20.0\n9000.010000,0,0,9.";
    let mut f = std::fs::OpenOptions::new()
        .append(true)
        .open(&path)
        .unwrap();
    std::io::Write::write_all(&mut f, tail.as_bytes()).unwrap();
    drop(f);
    let o = ratecal(&["verify", "r"], tmp.path());
    assert_eq!(code(&o), 4, "{}", text(&o));
    let o = ratecal(&["run", "--resume", "r"], tmp.path());
    assert_eq!(code(&o), 0, "{}", text(&o));
    let m = ratecal_recording::read(&tmp.path().join("r"))
        .unwrap()
        .manifest;
    let resumes = m.run.unwrap().resumes;
    assert_eq!(resumes.len(), 1);
    assert_eq!(resumes[0].interrupted_status, "running");
    assert_eq!(
        resumes[0].cut_tail.get("imu.csv"),
        Some(&(tail.len() as u64))
    );
    assert!(!std::fs::read_to_string(&path).unwrap().contains("9000.0"));
    assert_eq!(code(&ratecal(&["verify", "r"], tmp.path())), 0);
}

#[test]
fn an_unsealed_run_whose_stream_was_edited_is_altered_not_sealed() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("p.rcal"), MINI).unwrap();
    let o = crash_at(
        "after-manifest",
        &["run", "p.rcal", "--dry-run", "--out", "r"],
        tmp.path(),
    );
    assert_eq!(o.status.code(), None, "{}", text(&o));
    // One digit of one sample changed, the file's size kept.
    let path = tmp.path().join("r/table.csv");
    let mut t = std::fs::read_to_string(&path).unwrap();
    let at = t.find("\n1").unwrap() + 3;
    let digit = if &t[at..=at] == "7" { "8" } else { "7" };
    t.replace_range(at..=at, digit);
    std::fs::write(&path, t).unwrap();
    let o = ratecal(&["verify", "r"], tmp.path());
    assert_eq!(code(&o), 1, "{}", text(&o));
    assert!(text(&o).contains("ALTERED"), "{}", text(&o));
    assert!(text(&o).contains("table.csv"), "{}", text(&o));
    let o = ratecal(&["run", "--resume", "r"], tmp.path());
    assert_eq!(code(&o), 1, "{}", text(&o));
    assert!(text(&o).contains("run::resume_altered"), "{}", text(&o));
    assert!(!tmp.path().join("r/seal.json").exists());
}

/// An aborted run of MINI in `tmp/<out>` (the lab's temperature leaves its range), sealed.
fn aborted(tmp: &Path, out: &str) {
    if !tmp.join("st.yaml").exists() {
        std::fs::write(tmp.join("st.yaml"), station_with(EXCURSION)).unwrap();
    }
    let o = mini_run(tmp, out, &["--station", "st.yaml"]);
    assert_eq!(code(&o), 4, "{}", text(&o));
}

/// Named points of a resume of a sealed aborted run, before and after its commit.
const RESUME_POINTS: &[(&str, bool)] = &[
    ("after-stage", false),
    ("after-checkpoint#2", false),
    ("after-manifest", false),
    ("after-intent", true),
    ("after-move-imu.csv", true),
    ("after-move-manifest.yaml", true),
    ("after-results", true),
    ("before-seal-intent", true),
    ("after-intent#2", true),
];

#[test]
fn a_resume_stopped_at_any_named_point_leaves_the_sealed_run_or_the_new_one() {
    let tmp = tempfile::tempdir().unwrap();
    aborted(tmp.path(), "a");
    let original = json(&tmp.path().join("a/seal.json"));
    for (k, (point, committed)) in RESUME_POINTS.iter().enumerate() {
        let out = format!("a{k}");
        copy_dir(&tmp.path().join("a"), &tmp.path().join(&out));
        let o = crash_at(point, &["run", "--resume", &out], tmp.path());
        assert_eq!(o.status.code(), None, "{point}: did not stop\n{}", text(&o));
        let dir = tmp.path().join(&out);
        let state = named_state(&dir, tmp.path(), point);
        if !committed {
            // Before the commit the sealed aborted recording is as it was, and verifies.
            assert_eq!(state, Some(0), "{point}");
            assert_eq!(json(&dir.join("seal.json")), original, "{point}");
            let o = ratecal(
                &["archive", "add", &out, "--archive", "arc-old"],
                tmp.path(),
            );
            assert_eq!(code(&o), 0, "{point}: {}", text(&o));
        }
        finish_and_check(&dir, tmp.path(), point);
        // The resume is on record, and the resumed part's streams continue the old ones.
        let m = ratecal_recording::read(&dir).unwrap().manifest;
        assert!(!m.run.unwrap().resumes.is_empty(), "{point}");
    }
}

#[test]
fn a_second_resume_after_a_crashed_one_and_two_resumes_at_once() {
    let tmp = tempfile::tempdir().unwrap();
    aborted(tmp.path(), "a");
    // Killed while resuming (at a few moments), then resumed by two processes at once.
    for (k, ms) in [5u64, 40, 120].iter().enumerate() {
        let out = format!("c{k}");
        copy_dir(&tmp.path().join("a"), &tmp.path().join(&out));
        kill_after(*ms, &["run", "--resume", &out], tmp.path());
        named_state(
            &tmp.path().join(&out),
            tmp.path(),
            &format!("killed at {ms} ms"),
        );
        let spawn = || {
            Command::new(env!("CARGO_BIN_EXE_ratecal"))
                .args(["run", "--resume", &out])
                .current_dir(tmp.path())
                .stdout(Stdio::piped())
                .stderr(Stdio::piped())
                .spawn()
                .unwrap()
        };
        let (a, b) = (spawn(), spawn());
        let (a, b) = (a.wait_with_output().unwrap(), b.wait_with_output().unwrap());
        // One finishes it; the other is refused (in use, or nothing left to resume).
        let codes = [code(&a), code(&b)];
        // The killed resume may have finished before the kill landed (a fast machine):
        // then one is told there is nothing to resume and the other that, or that the
        // folder is in use by the first.
        let done = |o: &std::process::Output| code(o) == 1 && text(o).contains("nothing to resume");
        let busy = |o: &std::process::Output| code(o) == 1 && text(o).contains("is in use by");
        if (done(&a) && (done(&b) || busy(&b))) || (done(&b) && busy(&a)) {
            finish_and_check(&tmp.path().join(&out), tmp.path(), &format!("c{k}"));
            continue;
        }
        assert!(codes.contains(&0), "{}\n{}", text(&a), text(&b));
        assert!(codes.contains(&1), "{}\n{}", text(&a), text(&b));
        let refused = if code(&a) == 1 { &a } else { &b };
        let why = text(refused);
        assert!(
            why.contains("is in use by") || why.contains("nothing to resume"),
            "{why}"
        );
        finish_and_check(&tmp.path().join(&out), tmp.path(), &format!("c{k}"));
        // No interleaved lines: every row has the header's column count.
        let imu = std::fs::read_to_string(tmp.path().join(&out).join("imu.csv")).unwrap();
        let cols = imu.lines().next().unwrap().split(',').count();
        assert!(imu.lines().all(|l| l.split(',').count() == cols));
    }
}

#[test]
fn analyze_out_and_archive_add_stopped_leave_a_named_state() {
    let tmp = tempfile::tempdir().unwrap();
    let o = mini_run(tmp.path(), "r", &[]);
    assert!(matches!(code(&o), 0 | 3), "{}", text(&o));
    for point in [
        "before-seal-intent",
        "after-intent",
        "after-move-again.json",
    ] {
        let o = crash_at(
            point,
            &["analyze", "r", "--out", "r/again.json"],
            tmp.path(),
        );
        assert_eq!(o.status.code(), None, "{point}: did not stop\n{}", text(&o));
        let state = named_state(&tmp.path().join("r"), tmp.path(), point);
        // Before the intent the addition never happened; after it, resume finishes it.
        assert_eq!(
            state,
            Some(if point == "before-seal-intent" { 0 } else { 4 })
        );
        let o = ratecal(&["run", "--resume", "r"], tmp.path());
        assert!(text(&o).contains("nothing to resume"), "{}", text(&o));
        // Finishing the interrupted change is a resume that succeeded (issue 38).
        let want = if point == "before-seal-intent" { 1 } else { 0 };
        assert_eq!(code(&o), want, "{point}: {}", text(&o));
        let o = ratecal(&["verify", "r"], tmp.path());
        assert_eq!(code(&o), 0, "{point}: {}", text(&o));
        assert_eq!(
            tmp.path().join("r/again.json").exists(),
            point != "before-seal-intent"
        );
        std::fs::remove_file(tmp.path().join("r/again.json")).ok();
        let o = ratecal(&["analyze", "r", "--out", "r/again.json"], tmp.path());
        assert!(matches!(code(&o), 0 | 3), "{}", text(&o));
        assert_eq!(code(&ratecal(&["verify", "r"], tmp.path())), 0);
        std::fs::remove_file(tmp.path().join("r/again.json")).ok();
        // (The seal keeps the record of the addition; the file is named missing until
        // written again, so the next round writes it again.)
        let o = ratecal(&["analyze", "r", "--out", "r/again.json"], tmp.path());
        assert!(matches!(code(&o), 0 | 3), "{}", text(&o));
    }
    // archive add stopped between its files and its index, then before a file's rename.
    for point in ["archive-after-files", "archive-before-rename"] {
        let arc = format!("arc-{point}");
        let o = crash_at(
            point,
            &["archive", "add", "r", "--archive", &arc],
            tmp.path(),
        );
        assert_eq!(o.status.code(), None, "{point}: did not stop\n{}", text(&o));
        let o = ratecal(&["archive", "check", "--archive", &arc], tmp.path());
        assert_eq!(code(&o), 0, "{point}: {}", text(&o));
        let o = ratecal(&["archive", "add", "r", "--archive", &arc], tmp.path());
        assert_eq!(code(&o), 0, "{point}: {}", text(&o));
        let o = ratecal(&["archive", "check", "--archive", &arc], tmp.path());
        assert_eq!(code(&o), 0, "{point}: {}", text(&o));
        assert!(
            text(&o).contains(" 0 unfinished write(s)"),
            "{point}: {}",
            text(&o)
        );
        assert!(
            text(&o).contains(" 0 unreferenced"),
            "{point}: {}",
            text(&o)
        );
    }
}

/// SIGKILL at moments across a whole `run` (`moments` in ms).
fn kill_sweep(moments: impl Iterator<Item = u64>) {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("p.rcal"), MINI).unwrap();
    for ms in moments {
        let out = format!("k{ms}");
        let args = ["run", "p.rcal", "--dry-run", "--out", &out];
        if !kill_after(ms, &args, tmp.path()) {
            continue;
        }
        let dir = tmp.path().join(&out);
        let what = format!("killed at {ms} ms");
        if named_state(&dir, tmp.path(), &what).is_none() {
            // Killed before the recording existed: a new run in its place.
            let o = ratecal(&["run", "p.rcal", "--dry-run", "--out", &out], tmp.path());
            assert!(matches!(code(&o), 0 | 3), "{what}: {}", text(&o));
        }
        finish_and_check(&dir, tmp.path(), &what);
    }
}

#[test]
fn a_run_killed_at_moments_is_finished_by_resume() {
    kill_sweep([2u64, 15, 40, 80, 160].into_iter());
}

#[test]
#[ignore = "a wide sweep: cargo test --test it crash_cli:: -- --ignored"]
fn a_run_killed_every_few_milliseconds_is_finished_by_resume() {
    kill_sweep((1..120).map(|k| k * 3));
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        if e.file_type().unwrap().is_file() {
            std::fs::copy(e.path(), to.join(e.file_name())).unwrap();
        }
    }
}
