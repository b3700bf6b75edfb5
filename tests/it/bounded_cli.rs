//! Bounded resources (issue 26, items 5 to 7): a 100 MB NUL-filled or newline-less imu.csv
//! is refused in well under a second and 100 MB of memory with a short, escaped snippet;
//! files are hashed streaming; a FIFO is refused, located, instead of hanging; a symlink is
//! followed alike by verify, archive add and export; a dangling one is named.

use crate::support;
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};
use support::*;

const SIZE: usize = 100_000_000;

/// Runs `ratecal args` in `cwd` under `/usr/bin/time` when this machine has it: the output,
/// the wall time and the peak resident memory in KB (`None` without /usr/bin/time).
fn measured(args: &[&str], cwd: &Path) -> (Output, Duration, Option<u64>) {
    let time = Path::new("/usr/bin/time");
    let t0 = Instant::now();
    if !time.exists() {
        let o = ratecal(args, cwd);
        return (o, t0.elapsed(), None);
    }
    let report = cwd.join("rss.txt");
    let o = Command::new(time)
        .arg("-f")
        .arg("%M")
        .arg("-o")
        .arg(&report)
        .arg(env!("CARGO_BIN_EXE_ratecal"))
        .args(args)
        .current_dir(cwd)
        .output()
        .unwrap();
    let wall = t0.elapsed();
    let text = std::fs::read_to_string(&report).unwrap();
    // /usr/bin/time adds "Command exited with non-zero status N" before the figure.
    let kb = text
        .lines()
        .filter_map(|l| l.trim().parse().ok())
        .next_back();
    (o, wall, kb)
}

/// Runs `ratecal args` and fails the test if it has not ended after `limit`.
fn within(args: &[&str], cwd: &Path, limit: Duration) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_ratecal"))
        .args(args)
        .current_dir(cwd)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let t0 = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if t0.elapsed() > limit {
            child.kill().unwrap();
            child.wait().unwrap();
            panic!("`ratecal {}` still running after {limit:?}", args.join(" "));
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

fn assert_bounded(what: &str, o: &Output, wall: Duration, kb: Option<u64>) {
    println!("{what}: {:.3} s, peak {kb:?} KB", wall.as_secs_f64());
    assert!(wall < Duration::from_secs(1), "{what}: {wall:?}");
    if let Some(kb) = kb {
        assert!(kb < 100_000, "{what}: peak {kb} KB");
    }
    assert!(
        o.stderr.len() < 8_000,
        "{what}: {} bytes of stderr",
        o.stderr.len()
    );
    assert!(!o.stderr.contains(&0u8), "{what}: raw NUL bytes on stderr");
}

#[test]
fn a_100_mb_nul_filled_or_newline_less_imu_csv_is_refused_quickly_and_briefly() {
    let tmp = tempfile::tempdir().unwrap();
    let o = mini_run(tmp.path(), "r", &[]);
    assert!(matches!(code(&o), 0 | 3), "{}", text(&o));
    let dir = tmp.path().join("r");
    let header = std::fs::read_to_string(dir.join("imu.csv"))
        .unwrap()
        .lines()
        .next()
        .unwrap()
        .to_string();

    // Zeroed by a crash: one "line" of 100 MB of NUL bytes.
    std::fs::write(dir.join("imu.csv"), vec![0u8; SIZE]).unwrap();
    let (o, wall, kb) = measured(&["analyze", "r"], tmp.path());
    assert_eq!(code(&o), 1, "{}", text(&o));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("recording::line_too_long"), "{err}");
    assert!(err.contains("r/imu.csv:1: a line of more than"), "{err}");
    assert!(err.contains("\\0\\0\\0"), "NUL bytes escaped: {err}");
    assert!(err.contains("help:"), "{err}");
    assert_bounded("analyze, NUL-filled", &o, wall, kb);

    // verify hashes it streaming: altered, in flat memory.
    let (o, wall, kb) = measured(&["verify", "r"], tmp.path());
    assert_eq!(code(&o), 1, "{}", text(&o));
    assert!(text(&o).contains("ALTERED  imu.csv"), "{}", text(&o));
    assert_bounded("verify, NUL-filled", &o, wall, kb);

    // Preallocated after a valid header: line 2 never ends.
    let mut bytes = format!("{header}\n").into_bytes();
    bytes.resize(SIZE, b'7');
    std::fs::write(dir.join("imu.csv"), bytes).unwrap();
    let (o, wall, kb) = measured(&["analyze", "r"], tmp.path());
    assert_eq!(code(&o), 1, "{}", text(&o));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("r/imu.csv:2: a line of more than"), "{err}");
    // The header is shown as context, line-numbered as in the file.
    assert!(err.contains(&format!(" 1 │ {header}")), "{err}");
    assert!(err.contains(" 2 │ 7777"), "{err}");
    assert_bounded("analyze, newline-less", &o, wall, kb);
}

#[test]
fn a_fifo_is_refused_located_instead_of_hanging() {
    let tmp = tempfile::tempdir().unwrap();
    let o = mini_run(tmp.path(), "r", &[]);
    assert!(matches!(code(&o), 0 | 3), "{}", text(&o));
    let dir = tmp.path().join("r");
    std::fs::remove_file(dir.join("imu.csv")).unwrap();
    let made = Command::new("mkfifo").arg(dir.join("imu.csv")).status();
    if !made.is_ok_and(|s| s.success()) {
        println!("skipped: no mkfifo on this machine");
        return;
    }
    let limit = Duration::from_secs(20);
    let o = within(&["analyze", "r"], tmp.path(), limit);
    assert_eq!(code(&o), 1, "{}", text(&o));
    assert!(
        text(&o).contains("cannot read r/imu.csv: not a regular file (a FIFO)"),
        "{}",
        text(&o)
    );
    let o = within(&["verify", "r"], tmp.path(), limit);
    assert_eq!(code(&o), 1, "{}", text(&o));
    assert!(
        text(&o).contains("! UNREADABLE imu.csv: not a regular file (a FIFO)"),
        "{}",
        text(&o)
    );
    // explain checks the seal first: the FIFO fails it, named, at once.
    let o = within(&["explain", "r"], tmp.path(), limit);
    assert_eq!(code(&o), 4, "{}", text(&o));
    assert!(
        text(&o).contains("fails its seal (imu.csv)"),
        "{}",
        text(&o)
    );
    let o = within(
        &["archive", "add", "r", "--archive", "arc"],
        tmp.path(),
        limit,
    );
    assert_ne!(code(&o), 0, "{}", text(&o));
    assert!(
        text(&o).contains("imu.csv: not a regular file (a FIFO)"),
        "{}",
        text(&o)
    );
}

#[cfg(unix)]
#[test]
fn symlinks_are_followed_alike_by_verify_add_and_export_and_a_dangling_one_is_named() {
    let tmp = tempfile::tempdir().unwrap();
    let o = mini_run(tmp.path(), "r", &[]);
    assert!(matches!(code(&o), 0 | 3), "{}", text(&o));
    let dir = tmp.path().join("r");
    std::fs::rename(dir.join("imu.csv"), tmp.path().join("elsewhere.csv")).unwrap();
    std::os::unix::fs::symlink(tmp.path().join("elsewhere.csv"), dir.join("imu.csv")).unwrap();
    let o = ratecal(&["verify", "r"], tmp.path());
    assert_eq!(code(&o), 0, "{}", text(&o));
    let o = ratecal(&["archive", "add", "r", "--archive", "arc"], tmp.path());
    assert_eq!(code(&o), 0, "{}", text(&o));
    let files = json(&dir.join("seal.json"))["files"]
        .as_object()
        .unwrap()
        .len();
    // Every sealed file and the seal's own two: none skipped.
    assert!(
        text(&o).contains(&format!("({} file(s))", files + 2)),
        "{files}: {}",
        text(&o)
    );
    let id = text(&o)
        .split(" as ")
        .nth(1)
        .and_then(|s| s.split_whitespace().next())
        .unwrap()
        .to_string();
    let o = ratecal(
        &["archive", "export", &id, "out", "--archive", "arc"],
        tmp.path(),
    );
    assert_eq!(code(&o), 0, "{}", text(&o));
    let exported = tmp.path().join("out/imu.csv");
    assert!(std::fs::symlink_metadata(&exported).unwrap().is_file());
    assert_eq!(
        std::fs::read(&exported).unwrap(),
        std::fs::read(tmp.path().join("elsewhere.csv")).unwrap()
    );
    let o = ratecal(&["verify", "out"], tmp.path());
    assert_eq!(code(&o), 0, "{}", text(&o));

    // Dangling: named, exit 1 (not "not a run folder").
    std::fs::remove_file(tmp.path().join("elsewhere.csv")).unwrap();
    let o = ratecal(&["verify", "r"], tmp.path());
    assert_eq!(code(&o), 1, "{}", text(&o));
    assert!(
        text(&o).contains("! UNREADABLE imu.csv: a dangling symlink"),
        "{}",
        text(&o)
    );
    // A dangling manifest.yaml: still a run folder, the entry named.
    std::fs::rename(dir.join("manifest.yaml"), tmp.path().join("m.yaml")).unwrap();
    std::os::unix::fs::symlink(tmp.path().join("gone.yaml"), dir.join("manifest.yaml")).unwrap();
    let o = ratecal(&["verify", "r"], tmp.path());
    assert_eq!(code(&o), 1, "{}", text(&o));
    assert!(
        text(&o).contains("! UNREADABLE manifest.yaml: a dangling symlink"),
        "{}",
        text(&o)
    );
}
