//! A certificate from a run folder, whole process: `ratecal certificate` spawned on an
//! approved, archived dry run of `procedures/imu-2d-standard` (seal verified, folder hashed
//! for its archive id, number from the archive, budget, PDF typeset twice for "page N of M").
//! Target: under 1 s. Run: `cargo bench --bench certificate`.

use criterion::{Criterion, criterion_group, criterion_main};
use std::path::Path;
use std::process::Command;

fn ratecal(args: &[&str], dir: &Path) {
    let o = Command::new(env!("CARGO_BIN_EXE_ratecal"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("ratecal runs");
    assert!(
        matches!(o.status.code(), Some(0 | 3)),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
}

fn bench(c: &mut Criterion) {
    let root = env!("CARGO_MANIFEST_DIR");
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let station = format!("{root}/docs/examples/station.yaml");
    let procedure = format!("{root}/procedures/imu-2d-standard");
    // The example laboratory, its signer's key the one made below.
    let lab = dir.join("lab.yaml").display().to_string();
    let example = std::fs::read_to_string(format!("{root}/docs/examples/lab.yaml")).unwrap();
    std::fs::write(&lab, example.replace("../../keys/lab.pub", "keys/lab.pub")).unwrap();
    ratecal(
        &[
            "run",
            &procedure,
            "--dry-run",
            "--station",
            &station,
            "--out",
            "cal",
        ],
        dir,
    );
    ratecal(&["key", "new", "keys"], dir);
    ratecal(
        &[
            "approve",
            "cal",
            "--signer",
            "A",
            "--role",
            "B",
            "--key",
            "keys/lab.key",
        ],
        dir,
    );
    ratecal(&["archive", "add", "cal", "--archive", "archive"], dir);
    let args = [
        "certificate",
        "cal",
        "--lab",
        &lab,
        "--archive",
        "archive",
        "--out",
        "c.pdf",
    ];
    let mut g = c.benchmark_group("certificate");
    g.sample_size(10);
    g.bench_function("pdf_whole_process", |b| b.iter(|| ratecal(&args, dir)));
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
