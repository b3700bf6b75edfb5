//! Analysis of a standard-procedure recording with a 15-minute gyro block at 100 Hz
//! (about 170,000 IMU rows), CSV loading included. The recording is written once to
//! `target/analyze-bench-recording/` (also read by `benches/analyze_pandas.py`).
//!
//! `analyze/cli` is the figure: the whole `ratecal analyze` process from the command
//! line (which reads the IMU stream a window at a time: `open+stream+json` in process). Beside it, when python3 with pandas, numpy and PyYAML is installed, the equivalent
//! script `benches/analyze_pandas.py` is timed the same way (whole process) and the ratio
//! printed.

#[path = "../analysis/tests/fit_support/mod.rs"]
mod fit_support;

use criterion::{Criterion, criterion_group, criterion_main};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

fn recording() -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/analyze-bench-recording");
    fit_support::bench_recording(&dir);
    dir
}

/// `ratecal analyze DIR` as a user runs it (results into a temporary file).
fn cli(dir: &Path, out: &Path) {
    let st = Command::new(env!("CARGO_BIN_EXE_ratecal"))
        .arg("analyze")
        .arg(dir)
        .arg("--out")
        .arg(out)
        .stderr(std::process::Stdio::null())
        .status()
        .expect("ratecal runs");
    assert!(st.code().is_some_and(|c| c == 0 || c == 3), "{st}");
}

/// Median wall time of `runs` whole-process runs of the pandas script; `None` without
/// python3, pandas, numpy or PyYAML.
fn pandas(dir: &Path, runs: usize) -> Option<Duration> {
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/benches/analyze_pandas.py");
    let once = || {
        let t0 = Instant::now();
        let ok = Command::new("python3")
            .arg(script)
            .arg(dir)
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .status()
            .ok()?
            .success();
        ok.then(|| t0.elapsed())
    };
    let mut times: Vec<Duration> = (0..runs).map(|_| once()).collect::<Option<_>>()?;
    times.sort();
    Some(times[runs / 2])
}

fn bench(c: &mut Criterion) {
    let dir = recording();
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("results.json");
    let mut g = c.benchmark_group("analyze");
    g.sample_size(20);
    g.bench_function("read", |b| {
        b.iter(|| ratecal_recording::read(&dir).unwrap())
    });
    let rec = ratecal_recording::read(&dir).unwrap();
    g.bench_function("fit", |b| {
        b.iter(|| ratecal_analysis::fit::analyze(&rec, None))
    });
    g.bench_function("read+fit+json", |b| {
        b.iter(|| {
            let rec = ratecal_recording::read(&dir).unwrap();
            ratecal_analysis::fit::analyze(&rec, None).to_json()
        })
    });
    // What `ratecal analyze` does: the IMU stream read a window at a time.
    g.bench_function("open+stream+json", |b| {
        b.iter(|| {
            let src = ratecal_analysis::fit::Streamed::open(&dir).unwrap();
            let opts = ratecal_analysis::fit::Options::default();
            let res = ratecal_analysis::fit::analyze_source(&src, None, &opts).unwrap();
            res.to_json()
        })
    });
    g.bench_function("cli", |b| b.iter(|| cli(&dir, &out)));
    g.finish();
    let mut ours: Vec<Duration> = (0..21)
        .map(|_| {
            let t0 = Instant::now();
            cli(&dir, &out);
            t0.elapsed()
        })
        .collect();
    ours.sort();
    let ours = ours[10];
    match pandas(&dir, 7) {
        Some(p) => eprintln!(
            "whole process, median: ratecal analyze {:.1} ms, pandas + numpy script {:.1} ms: {:.1}x",
            ours.as_secs_f64() * 1e3,
            p.as_secs_f64() * 1e3,
            p.as_secs_f64() / ours.as_secs_f64()
        ),
        None => eprintln!(
            "whole process, median: ratecal analyze {:.1} ms (pandas comparison skipped: python3 with pandas, numpy and PyYAML not installed)",
            ours.as_secs_f64() * 1e3
        ),
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
