//! The archive removes the unfinished writes a killed `archive add` left (issue 26, item
//! 10's second half): on the next add, or with `archive check --fix`, which `check`
//! suggests; a write a running add is making is left alone.

use crate::support;
use support::*;

#[test]
fn unfinished_writes_are_removed_by_the_next_add_or_check_fix() {
    let tmp = tempfile::tempdir().unwrap();
    let o = mini_run(tmp.path(), "r1", &[]);
    assert!(matches!(code(&o), 0 | 3), "{}", text(&o));
    let o = ratecal(&["archive", "add", "r1", "--archive", "arc"], tmp.path());
    assert_eq!(code(&o), 0, "{}", text(&o));
    let tmp_dir = tmp.path().join("arc/files/tmp");
    std::fs::create_dir_all(&tmp_dir).unwrap();
    // A killed add's write (no such process), and one a live process is making.
    let dead = tmp_dir.join(format!("{}.999999999.1", "ab".repeat(32)));
    let live = tmp_dir.join(format!("{}.{}.2", "cd".repeat(32), std::process::id()));
    std::fs::write(&dead, b"half a file").unwrap();
    std::fs::write(&live, b"being written").unwrap();

    let o = ratecal(&["archive", "check", "--archive", "arc"], tmp.path());
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert!(text(&o).contains("2 unfinished write(s)"), "{}", text(&o));
    assert!(text(&o).contains("archive check --fix"), "{}", text(&o));
    assert!(dead.exists());

    let o = ratecal(
        &["archive", "check", "--fix", "--archive", "arc"],
        tmp.path(),
    );
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert!(
        text(&o).contains("removed 1 unfinished write(s)"),
        "{}",
        text(&o)
    );
    assert!(!dead.exists());
    assert!(live.exists(), "a running add's write was removed");

    // The next add removes another one.
    std::fs::write(&dead, b"half a file").unwrap();
    let o = mini_run(tmp.path(), "r2", &["--seed", "2"]);
    assert!(matches!(code(&o), 0 | 3), "{}", text(&o));
    let o = ratecal(&["archive", "add", "r2", "--archive", "arc"], tmp.path());
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert!(!dead.exists());
    assert!(live.exists());
    let o = ratecal(&["archive", "check", "--archive", "arc"], tmp.path());
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert!(text(&o).contains("1 unfinished write(s)"), "{}", text(&o));
}
