//! `report` and `explain` on a run folder whose seal fails, or that was never sealed
//! (issue 26, item 8): refused with exit 4, nothing written, the seal unchanged.

use crate::support;
use support::*;

#[test]
fn report_and_explain_refuse_an_altered_folder_and_never_add_to_its_seal() {
    let tmp = tempfile::tempdir().unwrap();
    let o = mini_run(tmp.path(), "r", &[]);
    assert!(matches!(code(&o), 0 | 3), "{}", text(&o));
    let dir = tmp.path().join("r");
    // Intact: both work.
    let o = ratecal(&["report", "r"], tmp.path());
    assert_eq!(code(&o), 0, "{}", text(&o));

    // imu.csv cut in half.
    let imu = std::fs::read(dir.join("imu.csv")).unwrap();
    std::fs::write(dir.join("imu.csv"), &imu[..imu.len() / 2]).unwrap();
    let seal = std::fs::read(dir.join("seal.json")).unwrap();
    let o = ratecal(&["report", "r", "--out", "r/again.md"], tmp.path());
    assert_eq!(code(&o), 4, "{}", text(&o));
    assert!(
        text(&o).contains("fails its seal (imu.csv)"),
        "{}",
        text(&o)
    );
    assert!(text(&o).contains("verify::altered"), "{}", text(&o));
    assert!(!text(&o).contains("PASS"), "{}", text(&o));
    assert!(!dir.join("again.md").exists());
    let o = ratecal(&["report", "r"], tmp.path());
    assert_eq!(code(&o), 4, "{}", text(&o));
    assert!(o.stdout.is_empty(), "{}", text(&o));
    let o = ratecal(&["explain", "r"], tmp.path());
    assert_eq!(code(&o), 4, "{}", text(&o));
    assert!(
        text(&o).contains("fails its seal (imu.csv)"),
        "{}",
        text(&o)
    );
    assert!(!dir.join("explain.json").exists());
    assert_eq!(std::fs::read(dir.join("seal.json")).unwrap(), seal);

    // Never sealed: named as such, with the way to finish it.
    std::fs::write(dir.join("imu.csv"), &imu).unwrap();
    std::fs::remove_file(dir.join("seal.json")).unwrap();
    std::fs::remove_file(dir.join("seal.sha256")).unwrap();
    for args in [&["report", "r"][..], &["explain", "r"][..]] {
        let o = ratecal(args, tmp.path());
        assert_eq!(code(&o), 4, "{}", text(&o));
        assert!(text(&o).contains("was never sealed"), "{}", text(&o));
        // The help wraps where the terminal width falls.
        let words = text(&o).split_whitespace().collect::<Vec<_>>().join(" ");
        assert!(words.contains("ratecal run --resume r`"), "{}", text(&o));
    }
    assert!(!dir.join("seal.json").exists());
}
