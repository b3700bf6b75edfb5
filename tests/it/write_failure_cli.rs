//! A failed write aborts the run (issue 26, item 10): under a file-size limit set in the
//! spawned shell (`ulimit -f`; the workspace forbids the unsafe `pre_exec` that `setrlimit`
//! would need), the write of imu.csv fails; the run names the file and the error, aborts to
//! its safe state (exit 4), cuts the partial last line, says so in the manifest, and seals a
//! folder that reads back, analyses, and resumes once the limit is gone.

use crate::support;
use std::process::Command;
use support::*;

#[cfg(unix)]
#[test]
fn a_file_size_limit_aborts_the_run_and_what_is_sealed_reads_back() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("p.rcal"), MINI).unwrap();
    // 400 blocks of 512 bytes: imu.csv outgrows it during the second static attitude.
    let limit_bytes = 400 * 512;
    let o = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -f 400 && exec '{}' run p.rcal --dry-run --out r",
            env!("CARGO_BIN_EXE_ratecal")
        ))
        .current_dir(tmp.path())
        .output()
        .unwrap();
    let out = text(&o);
    assert_eq!(code(&o), 4, "{out}");
    assert!(out.contains("recording error"), "{out}");
    assert!(out.contains("imu.csv: File too large (os error"), "{out}");
    assert!(out.contains("a write failed (imu.csv"), "{out}");
    assert!(out.contains("ratecal run --resume r"), "{out}");
    // The summary counts the segments the recording kept, not those handed to the writer.
    assert!(out.contains("segments: 1\n"), "{out}");

    let dir = tmp.path().join("r");
    let m = ratecal_recording::read(&dir)
        .unwrap_or_else(|e| panic!("sealed but unreadable: {e}"))
        .manifest;
    let run = m.run.as_ref().unwrap();
    assert_eq!(run.status, "aborted");
    let f = run
        .write_failure
        .as_ref()
        .expect("the manifest records the failure");
    assert_eq!(f.file, "imu.csv");
    assert!(f.error.contains("os error"), "{f:?}");
    // Cut after its last full line, within the limit; every row whole.
    let imu = std::fs::read(dir.join("imu.csv")).unwrap();
    assert!(imu.len() <= limit_bytes, "{}", imu.len());
    assert!(imu.len() + f.cut_bytes as usize <= limit_bytes);
    assert_eq!(imu.last(), Some(&b'\n'));
    let imu = String::from_utf8(imu).unwrap();
    let cols = imu.lines().next().unwrap().split(',').count();
    assert!(imu.lines().all(|l| l.split(',').count() == cols));
    // Only segments whose data was written are recorded.
    assert_eq!(m.segments.len(), 1, "{:?}", m.segments);
    // The abort names when the data ends, not only when the run noticed: the stamp of
    // imu.csv's last whole row, in the manifest and in what was printed.
    let last_t: f64 = imu
        .lines()
        .last()
        .unwrap()
        .split(',')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    let end = f
        .data_end_s
        .expect("the manifest records where the data ends");
    assert!((end - last_t).abs() < 1e-6, "{end} vs {last_t}");
    assert!(
        out.contains(&format!("the data at t = {end:.3} s: imu.csv ends there")),
        "{out}"
    );

    let o = ratecal(&["verify", "r"], tmp.path());
    assert_eq!(code(&o), 0, "{}", text(&o));
    let o = ratecal(&["analyze", "r"], tmp.path());
    assert_eq!(code(&o), 3, "{}", text(&o));

    // Space again: the run continues and completes.
    let o = ratecal(&["run", "--resume", "r"], tmp.path());
    assert_eq!(code(&o), 0, "{}", text(&o));
    let o = ratecal(&["verify", "r"], tmp.path());
    assert_eq!(code(&o), 0, "{}", text(&o));
    let m = ratecal_recording::read(&dir).unwrap().manifest;
    assert_eq!(m.segments.len(), 3, "{:?}", m.segments);
    assert!(m.run.unwrap().write_failure.is_none());
}
