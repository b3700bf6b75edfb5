//! Issue 41's whole-process rows at 1 kHz, and the 100 Hz dry run beside them: `ratecal run
//! procedures/imu-2d-standard --dry-run` on the default station with the IMU at 100 Hz and at
//! 1 kHz (4370 s simulated: 437,000 and 4.4 million rows), then `ratecal analyze` and
//! `ratecal explain` of the 1 kHz run. Each figure is the whole process from the command line,
//! as a user (or a lab's scheduler) starts it. Run: `cargo bench --bench one_khz`; the figures
//! and their targets are in docs/performance.md.

use criterion::{BatchSize::PerIteration, Criterion, criterion_group, criterion_main};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Duration;

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// The default station with the IMU sampled at `hz`, written under `target/`.
fn station(hz: u32) -> PathBuf {
    let text = ratecal_drivers::DEFAULT_STATION_YAML;
    assert!(text.contains("sample_rate: 100 Hz"));
    std::fs::create_dir_all(Path::new(ROOT).join("target")).expect("target/ made");
    let path = Path::new(ROOT).join(format!("target/bench-station-{hz}hz.yaml"));
    let yaml = text.replace("sample_rate: 100 Hz", &format!("sample_rate: {hz} Hz"));
    std::fs::write(&path, yaml).expect("station written");
    path
}

/// `ratecal args`, the whole process, its exit code one of `ok`.
fn ratecal(args: &[&std::ffi::OsStr], ok: &[i32]) {
    let st = Command::new(env!("CARGO_BIN_EXE_ratecal"))
        .args(args)
        .current_dir(ROOT)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .expect("ratecal runs");
    assert!(st.code().is_some_and(|c| ok.contains(&c)), "{args:?}: {st}");
}

/// A dry run of the standard procedure at `hz` into `out` (replaced).
fn dry_run(hz: u32, out: &Path) {
    run_into(&clear(hz, out), out);
}

/// Removes `out` (the last run's folder) and writes the station at `hz`: outside the timed
/// part, since neither is the dry run's work.
fn clear(hz: u32, out: &Path) -> PathBuf {
    let _ = std::fs::remove_dir_all(out);
    station(hz)
}

/// The dry run of the standard procedure on station file `st` into `out` (absent).
fn run_into(st: &Path, out: &Path) {
    ratecal(
        &[
            "run".as_ref(),
            "procedures/imu-2d-standard".as_ref(),
            "--dry-run".as_ref(),
            "--station".as_ref(),
            st.as_os_str(),
            "--out".as_ref(),
            out.as_os_str(),
        ],
        &[0, 3],
    );
}

fn bench(c: &mut Criterion) {
    let target = Path::new(ROOT).join("target");
    let mut g = c.benchmark_group("one_khz");
    g.sample_size(10).measurement_time(Duration::from_secs(60));
    let r100 = target.join("bench-dry-run-100hz");
    let timed = |hz: u32, out: PathBuf| {
        move |b: &mut criterion::Bencher| {
            b.iter_batched(|| clear(hz, &out), |st| run_into(&st, &out), PerIteration)
        }
    };
    g.bench_function("dry_run_100hz", timed(100, r100));
    let r1k = target.join("bench-dry-run-1khz");
    g.bench_function("dry_run_1khz", timed(1000, r1k.clone()));
    // The last dry run's folder stays for the two that read it (made here when the
    // dry run was filtered out).
    if !r1k.join("seal.json").exists() {
        dry_run(1000, &r1k);
    }
    let results = target.join("bench-1khz-results.json");
    g.bench_function("analyze_1khz", |b| {
        b.iter(|| {
            let args = ["analyze".as_ref(), r1k.as_os_str(), "--out".as_ref()];
            let mut args = args.to_vec();
            args.push(results.as_os_str());
            ratecal(&args, &[0, 3])
        })
    });
    g.bench_function("explain_1khz", |b| {
        b.iter(|| {
            ratecal(
                &[
                    "explain".as_ref(),
                    r1k.as_os_str(),
                    "--format".as_ref(),
                    "json".as_ref(),
                ],
                &[0, 1],
            )
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
