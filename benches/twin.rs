//! `ratecal explain RUN --twin STATION` on a dry run of `procedures/imu-2d-standard` at
//! 100 Hz (1 h 13 min, 437,000 IMU rows) made on the lever-arm station, against the default
//! station's twin (which lacks the lever arm): the whole process from the command line,
//! the corrected twin written (the figure: under 1 s).

use criterion::{Criterion, criterion_group, criterion_main};
use std::path::PathBuf;
use std::process::Command;
use std::time::Duration;

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

fn real_run() -> PathBuf {
    let dir = PathBuf::from(ROOT).join("target/twin-bench-real");
    if !dir.join("imu.csv").exists() {
        let _ = std::fs::remove_dir_all(&dir);
        let st = Command::new(env!("CARGO_BIN_EXE_ratecal"))
            .args([
                "run",
                "procedures/imu-2d-standard",
                "--dry-run",
                "--station",
            ])
            .arg("drivers/stations/with-lever-arm.yaml")
            .arg("--out")
            .arg(&dir)
            .current_dir(ROOT)
            .stdout(std::process::Stdio::null())
            .status()
            .expect("ratecal runs");
        assert!(st.code().is_some_and(|c| c == 0 || c == 3), "{st}");
    }
    dir
}

fn twin_cli(dir: &std::path::Path, out: &std::path::Path) {
    let st = Command::new(env!("CARGO_BIN_EXE_ratecal"))
        .arg("explain")
        .arg(dir)
        .args(["--twin", "drivers/stations/default.yaml", "--write-twin"])
        .arg(out)
        .args(["--format", "json"])
        .current_dir(ROOT)
        .stdout(std::process::Stdio::null())
        .status()
        .expect("ratecal runs");
    assert_eq!(st.code(), Some(1), "{st}");
}

fn bench(c: &mut Criterion) {
    let dir = real_run();
    let out = PathBuf::from(ROOT).join("target/twin-bench-updated.yaml");
    let mut g = c.benchmark_group("twin");
    g.sample_size(10).measurement_time(Duration::from_secs(20));
    g.bench_function("cli_standard_dry_run", |b| b.iter(|| twin_cli(&dir, &out)));
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
