//! `ratecal import` of a 73-minute 1 kHz CSV (4.38 M rows: six columns in g and deg/s, a
//! static pose declared every minute), generated once into a temporary folder. Measured
//! as the whole process (the built `ratecal` binary spawned, as a lab runs it) and, for
//! comparison, the least a reader of that file does (split each line, parse six numbers).
//! The peak memory of the process (`/usr/bin/time`) is printed for a 7.3-minute and the
//! 73-minute file: the importer streams, so it does not grow with the length.
//! `cargo bench --bench import` (the files take ~0.5 GB of /tmp while it runs).

use criterion::{Criterion, Throughput, criterion_group};
use std::io::{BufRead, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::process::Command;

const HZ: usize = 1000;

/// Writes `minutes` of data and its map; returns (csv, map).
fn generate(dir: &Path, minutes: usize) -> (PathBuf, PathBuf) {
    let csv = dir.join(format!("daq-{minutes}.csv"));
    let mut w = BufWriter::with_capacity(1 << 20, std::fs::File::create(&csv).unwrap());
    writeln!(w, "acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z").unwrap();
    let faces = [
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, -1.0],
    ];
    let mut x = 12345u64;
    for i in 0..minutes * 60 * HZ {
        let f = faces[(i / (60 * HZ)) % faces.len()];
        let mut n = || {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((x >> 40) as f64 / (1u64 << 24) as f64 - 0.5) * 2e-3
        };
        writeln!(
            w,
            "{:.6},{:.6},{:.6},{:.5},{:.5},{:.5}",
            f[0] + n(),
            f[1] + n(),
            f[2] + n(),
            0.1 + 50.0 * n(),
            -0.2 + 50.0 * n(),
            0.05 + 50.0 * n()
        )
        .unwrap();
    }
    w.flush().unwrap();
    let mut map = String::from(
        "source: { format: csv }
imu:
  time: { rate_hz: 1000 }
  columns: { ax: acc_x, ay: acc_y, az: acc_z, gx: gyr_x, gy: gyr_y, gz: gyr_z }
  units: { accel: g, gyro: deg/s }
segments:
",
    );
    let ups = ["+z", "+x", "+y", "-z"];
    for m in 0..minutes {
        let s = m * 60 * HZ;
        map.push_str(&format!(
            "  - {{ id: pose{m}, kind: static, samples: [{}, {}], up: \"{}\" }}\n",
            s + 5 * HZ,
            s + 55 * HZ,
            ups[m % 4]
        ));
    }
    map.push_str("table: none\nsite: { latitude_deg: 49.57, gravity_mps2: 9.8096 }\n");
    let map_path = dir.join(format!("map-{minutes}.yaml"));
    std::fs::write(&map_path, map).unwrap();
    (csv, map_path)
}

/// Runs the import; returns the peak resident memory in kB when /usr/bin/time is there.
fn import(csv: &Path, map: &Path, out: &Path) -> Option<u64> {
    let _ = std::fs::remove_dir_all(out);
    let bin = env!("CARGO_BIN_EXE_ratecal");
    let args = [
        "import",
        csv.to_str().unwrap(),
        "--map",
        map.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    let timed = Path::new("/usr/bin/time").exists();
    let o = if timed {
        Command::new("/usr/bin/time")
            .arg("-f")
            .arg("maxrss_kb=%M")
            .arg(bin)
            .args(args)
            .output()
    } else {
        Command::new(bin).args(args).output()
    }
    .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let err = String::from_utf8_lossy(&o.stderr);
    let kb = err
        .lines()
        .find_map(|l| l.strip_prefix("maxrss_kb="))
        .and_then(|v| v.trim().parse().ok());
    let _ = std::fs::remove_dir_all(out);
    kb
}

/// The least a reader does: every line split at commas, six numbers parsed.
fn read_only(csv: &Path) -> f64 {
    let f = std::io::BufReader::with_capacity(1 << 16, std::fs::File::open(csv).unwrap());
    let mut sum = 0.0;
    for line in f.lines().skip(1) {
        for c in line.unwrap().split(',') {
            sum += c.parse::<f64>().unwrap();
        }
    }
    sum
}

fn bench(c: &mut Criterion) {
    let dir = tempfile::tempdir_in(std::env::temp_dir()).unwrap();
    let (short_csv, short_map) = generate(dir.path(), 7);
    let (csv, map) = generate(dir.path(), 73);
    let out = dir.path().join("run");
    let short = import(&short_csv, &short_map, &out);
    let long = import(&csv, &map, &out);
    println!(
        "peak memory of the process: {} kB for 7 min, {} kB for 73 min (4.38 M rows)",
        short.map_or("?".into(), |k| k.to_string()),
        long.map_or("?".into(), |k| k.to_string())
    );
    let mut g = c.benchmark_group("import");
    g.sample_size(10);
    g.throughput(Throughput::Elements((73 * 60 * HZ) as u64));
    g.bench_function("73min_1kHz_csv_whole_process", |b| {
        b.iter(|| import(&csv, &map, &out))
    });
    g.bench_function("73min_1kHz_csv_read_and_parse_only", |b| {
        b.iter(|| read_only(&csv))
    });
    g.finish();
}

criterion_group!(benches, bench);

fn main() {
    benches();
    Criterion::default().configure_from_args().final_summary();
}
