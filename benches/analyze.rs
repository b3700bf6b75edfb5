//! Analysis of a standard-procedure recording with a 15-minute gyro block at 100 Hz
//! (about 170,000 IMU rows), CSV loading included. The recording is written once to
//! `target/analyze-bench-recording/` (also read by `benches/analyze_pandas.py`).

#[path = "../engine/tests/fit_support/mod.rs"]
mod fit_support;

use criterion::{Criterion, criterion_group, criterion_main};
use std::path::PathBuf;

fn recording() -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/analyze-bench-recording");
    if !dir.join("manifest.yaml").exists() {
        std::fs::create_dir_all(&dir).unwrap();
        let mut spec = fit_support::SimSpec::tactical(42);
        spec.block_s = 900.0;
        spec.temp = Some((22.0, 1.5));
        // About 28 minutes in all, like the standard procedure with its settling times.
        spec.settle_s = 40.0;
        let windows = fit_support::standard_windows(spec.block_s);
        fit_support::write(&dir, &spec, &windows);
    }
    dir
}

fn bench(c: &mut Criterion) {
    let dir = recording();
    let mut g = c.benchmark_group("analyze");
    g.sample_size(20);
    g.bench_function("read", |b| {
        b.iter(|| ratecal_engine::recording::read(&dir).unwrap())
    });
    let rec = ratecal_engine::recording::read(&dir).unwrap();
    g.bench_function("fit", |b| {
        b.iter(|| ratecal_engine::fit::analyze(&rec, None))
    });
    g.bench_function("read+fit+json", |b| {
        b.iter(|| {
            let rec = ratecal_engine::recording::read(&dir).unwrap();
            ratecal_engine::fit::analyze(&rec, None).to_json()
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
