//! The archive at lab scale: 10,000 runs in the index (100 units x 100 calibrations, a dozen
//! parameters each; index rows only), then the whole `ratecal` process for
//! `archive list --serial S` (target < 50 ms) and `archive trend S` over 100 calibrations
//! (target < 100 ms). Run: `cargo bench --bench archive`.
//! Measured 2026-11-24 on the shared 2-core machine (load ~9), test profile (opt-level 1,
//! dependencies 2): list 6.9 ms, trend 21 ms per whole process; building the 10,000 rows 4 s.

use criterion::{Criterion, criterion_group, criterion_main};
use ratecal_archive::{Archive, Folder, IndexFacts, LimitRow, Location, ParamRow, iso_date};
use std::path::Path;
use std::process::Command;

const UNITS: usize = 100;
const CALIBRATIONS: usize = 100;
const PARAMS: [&str; 12] = [
    "accel.bias.x",
    "accel.bias.y",
    "accel.bias.z",
    "accel.scale.x",
    "accel.scale.y",
    "accel.scale.z",
    "gyro.bias.x",
    "gyro.bias.y",
    "gyro.bias.z",
    "gyro.scale.x",
    "gyro.scale.y",
    "gyro.scale.z",
];

fn run(unit: usize, cal: usize) -> Folder {
    let day = 18_000.0 + 30.0 * cal as f64 + unit as f64 * 0.01;
    Folder {
        dir: Default::default(),
        files: Vec::new(),
        facts: IndexFacts {
            id: format!("{:08x}{:08x}", unit, cal),
            name: format!("unit{unit}-cal{cal}"),
            serial: format!("SN{unit:04}"),
            model: "SIM-TAC-100".into(),
            procedure: "imu-2d-standard".into(),
            version: "1.0.0".into(),
            station: "sim".into(),
            started: format!("{}T10:00:00Z", iso_date(day)),
            status: "completed".into(),
            verdict: "pass".into(),
            imu: "{}".into(),
            parameters: PARAMS
                .iter()
                .enumerate()
                .map(|(k, p)| ParamRow {
                    name: p.to_string(),
                    value: 0.01 + 1e-5 * (cal * (k + 1)) as f64,
                    u: 1e-3,
                    unit: "m/s^2".into(),
                })
                .collect(),
            limits: vec![LimitRow {
                quantity: "abs(accel.bias.x)".into(),
                op: "<=".into(),
                limit: 0.05,
                unit: "m/s^2".into(),
            }],
            ..IndexFacts::default()
        },
    }
}

fn build(dir: &Path) {
    let rt = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .unwrap();
    rt.block_on(async {
        let a = Archive::open(&Location::Folder(dir.to_path_buf()))
            .await
            .unwrap();
        let runs: Vec<Folder> = (0..UNITS)
            .flat_map(|u| (0..CALIBRATIONS).map(move |c| run(u, c)))
            .collect();
        a.insert_many(&runs).await.unwrap();
        a.close().await;
    });
}

fn ratecal(args: &[&str]) {
    let o = Command::new(env!("CARGO_BIN_EXE_ratecal"))
        .args(args)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

fn bench(c: &mut Criterion) {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("archive");
    let t = std::time::Instant::now();
    build(&dir);
    eprintln!(
        "built 10,000 index rows in {:.1} s",
        t.elapsed().as_secs_f64()
    );
    let d = dir.to_str().unwrap();
    let mut g = c.benchmark_group("archive");
    g.sample_size(20);
    g.bench_function("list --serial (process, 10k runs)", |b| {
        b.iter(|| {
            ratecal(&[
                "archive",
                "list",
                "--serial",
                "SN0042",
                "--format",
                "json",
                "--archive",
                d,
            ])
        })
    });
    g.bench_function("trend over 100 calibrations (process, 10k runs)", |b| {
        b.iter(|| {
            ratecal(&[
                "archive",
                "trend",
                "SN0042",
                "--format",
                "json",
                "--archive",
                d,
            ])
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
