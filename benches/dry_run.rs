//! Dry run of the standard procedure on the default simulated station with the IMU at
//! 1 kHz, under the paused clock: interpreter, simulator and recording writer together.
//! Target: >= 2000x faster than real time. Run: `cargo bench --bench dry_run`.

use criterion::{Criterion, criterion_group, criterion_main};
use ratecal_drivers::{DEFAULT_STATION_YAML, Station};
use ratecal_plan::Plan;
use ratecal_recording::{Columns, Manifest, ManifestStation, RecordingWriter, TableAxes};
use ratecal_run::{NoProgress, RunOptions, RunStatus, execute};
use std::time::Instant;

/// The default station with the IMU sampled at 1 kHz, noise densities unchanged (the
/// settle criterion watches 0.1 s means, so it does not tighten with the sample rate).
fn station_1khz() -> Station {
    assert!(DEFAULT_STATION_YAML.contains("sample_rate: 100 Hz"));
    let yaml = DEFAULT_STATION_YAML.replace("sample_rate: 100 Hz", "sample_rate: 1000 Hz");
    Station::from_yaml(&yaml, "bench").expect("station")
}

/// `procedures/imu-2d-standard`, checked.
fn standard_plan() -> Plan {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/procedures/imu-2d-standard/1.0.0.rcal"
    );
    let text = std::fs::read_to_string(path).expect("standard procedure");
    let opts = ratecal_check::CheckOptions::default();
    match ratecal_check::check_text(path, &text, &ratecal_check::NoImports, &opts) {
        Ok(c) => c.plan,
        Err(d) => panic!("{d:?}"),
    }
}

fn manifest(st: &Station) -> Manifest {
    Manifest {
        format: String::new(),
        station: ManifestStation {
            site: st.site(),
            table: TableAxes {
                outer_axis: [0.0, -1.0, 0.0],
                inner_axis: [1.0, 0.0, 0.0],
                model: None,
            },
            mount: None,
        },
        imu: Default::default(),
        procedure: None,
        segments: vec![],
        environment: None,
        run: None,
    }
}

/// One dry run; returns the simulated duration, s.
fn dry_run(plan: &Plan, st: &Station, dir: &std::path::Path) -> f64 {
    let rt = tokio::runtime::Builder::new_current_thread()
        .enable_time()
        .start_paused(true)
        .build()
        .unwrap();
    rt.block_on(async {
        let (mut table, mut imu) = ratecal_drivers::build(st, 7).unwrap();
        let mut w = RecordingWriter::create(
            dir,
            manifest(st),
            Columns {
                imu_temp: true,
                ambient: true,
                ..Columns::default()
            },
        )
        .unwrap();
        let out = execute(
            plan,
            table.as_mut(),
            imu.as_mut(),
            &mut w,
            &mut NoProgress,
            &RunOptions::default(),
        )
        .await
        .unwrap();
        assert_eq!(out.status, RunStatus::Completed);
        out.t_end
    })
}

/// The process's peak resident memory so far (Linux `VmHWM`), as printed by the kernel.
fn peak_memory() -> String {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find_map(|l| l.strip_prefix("VmHWM:").map(|v| v.trim().to_string()))
        })
        .unwrap_or_else(|| "unknown (no /proc/self/status)".into())
}

fn bench(c: &mut Criterion) {
    let plan = standard_plan();
    let st = station_1khz();
    let dir = tempfile::tempdir().unwrap();
    let t0 = Instant::now();
    let simulated = dry_run(&plan, &st, dir.path());
    let wall = t0.elapsed().as_secs_f64();
    eprintln!(
        "standard procedure, IMU 1 kHz: {simulated:.0} s simulated in {wall:.2} s ({:.0}x real time), peak memory {}",
        simulated / wall,
        peak_memory()
    );
    let mut g = c.benchmark_group("dry_run");
    g.sample_size(10);
    g.bench_function("standard_1khz", |b| {
        b.iter(|| dry_run(&plan, &st, dir.path()))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
