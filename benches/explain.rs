//! `ratecal explain` on a standard-procedure recording with a 15-minute gyro block at 100 Hz
//! (about 28 minutes, 170,000 IMU rows), every candidate of the catalogue tried: the whole
//! process from the command line (the figure: under 1 s on this machine).
//! The recording is the analyze bench's (`target/analyze-bench-recording/`).

#[path = "../analysis/tests/fit_support/mod.rs"]
mod fit_support;

use criterion::{Criterion, criterion_group, criterion_main};
use std::path::PathBuf;
use std::process::Command;
use std::time::Duration;

fn recording() -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/analyze-bench-recording");
    fit_support::bench_recording(&dir);
    dir
}

/// A dry run of `procedures/imu-2d-standard` at 100 Hz (1 h 13 min, 437,000 IMU rows): the
/// figure issue 27 names.
fn standard_dry_run() -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/explain-bench-standard");
    if !dir.join("imu.csv").exists() {
        let _ = std::fs::remove_dir_all(&dir);
        let st = Command::new(env!("CARGO_BIN_EXE_ratecal"))
            .args(["run", "procedures/imu-2d-standard", "--dry-run", "--out"])
            .arg(&dir)
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .stdout(std::process::Stdio::null())
            .status()
            .expect("ratecal runs");
        assert!(st.code().is_some_and(|c| c == 0 || c == 3), "{st}");
    }
    dir
}

/// One `ratecal explain DIR --format json`, the whole process.
fn explain_cli(dir: &std::path::Path) {
    let st = Command::new(env!("CARGO_BIN_EXE_ratecal"))
        .arg("explain")
        .arg(dir)
        .arg("--format")
        .arg("json")
        .stdout(std::process::Stdio::null())
        .status()
        .expect("ratecal runs");
    assert!(st.code().is_some_and(|c| c == 0 || c == 1), "{st}");
}

fn bench(c: &mut Criterion) {
    let dir = recording();
    let standard = standard_dry_run();
    let mut g = c.benchmark_group("explain");
    g.sample_size(10).measurement_time(Duration::from_secs(20));
    g.bench_function("cli_standard_dry_run", |b| {
        b.iter(|| explain_cli(&standard))
    });
    g.bench_function("cli", |b| b.iter(|| explain_cli(&dir)));
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
