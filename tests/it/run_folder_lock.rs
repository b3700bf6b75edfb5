//! One writer per run folder (issue 26, item 3): two `run --resume` of one folder at once,
//! the second refused at once naming the first; `analyze --out`, `report --out` and
//! `explain` refused too while it writes; a killed writer leaves no stale lock.

use crate::support;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};
use support::*;

/// An aborted (sealed) run of MINI in `tmp/r`, to resume.
fn aborted_run(tmp: &Path) {
    std::fs::write(tmp.join("st.yaml"), station_with(EXCURSION)).unwrap();
    let o = mini_run(tmp, "r", &["--station", "st.yaml"]);
    assert_eq!(code(&o), 4, "{}", text(&o));
}

/// `ratecal run --resume r` that holds the folder's lock `hold_ms` before going on.
fn slow_resume(tmp: &Path, hold_ms: u64) -> Child {
    Command::new(env!("CARGO_BIN_EXE_ratecal"))
        .args(["run", "--resume", "r"])
        .current_dir(tmp)
        .env("RATECAL_TEST_HOLD_LOCK_MS", hold_ms.to_string())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// Waits until the lock file names `pid` (the holder has the lock).
fn wait_for_holder(dir: &Path, pid: u32) {
    let start = Instant::now();
    let want = format!("pid {pid}\n");
    while !std::fs::read_to_string(dir.join(".ratecal.lock")).is_ok_and(|t| t.starts_with(&want)) {
        assert!(
            start.elapsed() < Duration::from_secs(30),
            "process {pid} never took the lock"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn a_second_writer_is_refused_at_once_and_the_folder_then_verifies() {
    let tmp = tempfile::tempdir().unwrap();
    aborted_run(tmp.path());
    let dir = tmp.path().join("r");
    let first = slow_resume(tmp.path(), 5000);
    let pid = first.id();
    wait_for_holder(&dir, pid);

    // The second resume: refused at once, naming the first, exit 1.
    let t0 = Instant::now();
    let o = ratecal(&["run", "--resume", "r"], tmp.path());
    let took = t0.elapsed();
    assert_eq!(code(&o), 1, "{}", text(&o));
    let msg = text(&o);
    assert!(
        msg.contains(&format!("in use by process {pid} since ")),
        "{msg}"
    );
    assert!(msg.contains("run_folder::in_use"), "{msg}");
    assert!(took < Duration::from_secs(3), "refused after {took:?}");
    assert!(!msg.contains("resuming"), "{msg}");

    // The other writers are refused too while it holds the folder.
    let o = ratecal(&["analyze", "r", "--out", "r/results.json"], tmp.path());
    assert_eq!(code(&o), 1, "{}", text(&o));
    assert!(
        text(&o).contains(&format!("in use by process {pid}")),
        "{}",
        text(&o)
    );
    let o = ratecal(&["report", "r", "--out", "r/again.md"], tmp.path());
    assert_eq!(code(&o), 1, "{}", text(&o));
    assert!(
        text(&o).contains(&format!("in use by process {pid}")),
        "{}",
        text(&o)
    );
    assert!(!dir.join("again.md").exists());
    let o = ratecal(&["explain", "r"], tmp.path());
    assert_eq!(code(&o), 2, "{}", text(&o));
    assert!(
        text(&o).contains(&format!("in use by process {pid}")),
        "{}",
        text(&o)
    );
    // Reading is never refused.
    let o = ratecal(&["report", "r"], tmp.path());
    assert_eq!(code(&o), 0, "{}", text(&o));

    // The first completes; the folder is sealed whole and verifies (the lock file is
    // neither sealed nor unknown).
    let out = first.wait_with_output().unwrap();
    assert_eq!(code(&out), 0, "{}", text(&out));
    let o = ratecal(&["verify", "r"], tmp.path());
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert!(!text(&o).contains(".ratecal.lock"), "{}", text(&o));
    let seal = json(&dir.join("seal.json"));
    assert!(seal["files"].get(".ratecal.lock").is_none(), "{seal}");
    ratecal_recording::read(&dir).unwrap();
}

#[test]
fn a_killed_writer_leaves_no_stale_lock() {
    let tmp = tempfile::tempdir().unwrap();
    aborted_run(tmp.path());
    let dir = tmp.path().join("r");
    let mut first = slow_resume(tmp.path(), 30_000);
    wait_for_holder(&dir, first.id());
    first.kill().unwrap(); // SIGKILL
    first.wait().unwrap();
    // The kernel released the lock with the process: the next resume proceeds.
    let o = ratecal(&["run", "--resume", "r"], tmp.path());
    assert_eq!(code(&o), 0, "{}", text(&o));
    let o = ratecal(&["verify", "r"], tmp.path());
    assert_eq!(code(&o), 0, "{}", text(&o));
}
