//! Sustained ingest from hardware links: `ratecal emulate` (its own process) serves an IMU
//! at 2 kHz and table feedback at 1 kHz over loopback TCP; this process reads both through
//! the registry's drivers on a 20 ms control tick and writes them with the recording writer,
//! flushing to the disk every 0.5 s, as `ratecal run` does. Criterion measures the CPU time
//! of this process (every thread: the link reader, the loop, the writer thread) per
//! session; each session also reports the samples received and lost, corrupted frames and
//! the delay from a sample's stamp (its arrival, to the link delay) to the flush that put
//! it on the disk. Sessions last `RATECAL_INGEST_S` seconds (default 3, under Criterion).
//! From 60 s on, one session runs alone, without Criterion's repetitions, and prints its
//! figures: the full figure is `RATECAL_INGEST_S=600 cargo bench --bench ingest`.
//! The delay to the disk is reported per sample from its stamp (device time mapped onto
//! the host clock) and from its arrival (`t_host`, the instant of the read that delivered
//! it; both on the drivers' host clock, which starts within microseconds of the session's).

use criterion::{Criterion, Throughput, criterion_group};
use ratecal_drivers::Station;
use ratecal_recording::{Columns, Manifest, ManifestStation, RecordingWriter, TableAxes};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

const IMU_HZ: f64 = 2000.0;
const TABLE_HZ: f64 = 1000.0;

fn secs() -> f64 {
    std::env::var("RATECAL_INGEST_S")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(3.0)
}

/// CPU time of every thread of this process so far (Linux `schedstat`, ns).
fn cpu_time() -> Duration {
    let mut ns = 0u64;
    if let Ok(tasks) = std::fs::read_dir("/proc/self/task") {
        for t in tasks.flatten() {
            if let Ok(s) = std::fs::read_to_string(t.path().join("schedstat")) {
                ns += s
                    .split(' ')
                    .next()
                    .and_then(|v| v.parse().ok())
                    .unwrap_or(0);
            }
        }
    }
    Duration::from_nanos(ns)
}

struct Emulator(Child);

impl Drop for Emulator {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Starts the emulator at 2 kHz / 1 kHz; returns it and the connecting station.
fn emulator(dir: &Path) -> (Emulator, Station) {
    let yaml = ratecal_drivers::DEFAULT_STATION_YAML
        .replace("sample_rate: 100 Hz", &format!("sample_rate: {IMU_HZ} Hz"))
        .replace(
            "feedback_rate: 50 Hz",
            &format!("feedback_rate: {TABLE_HZ} Hz"),
        );
    let emulated = dir.join("emulated.yaml");
    std::fs::write(&emulated, yaml).unwrap();
    let conn: PathBuf = dir.join("connect.yaml");
    let child = Command::new(env!("CARGO_BIN_EXE_ratecal"))
        .arg("emulate")
        .arg("--station")
        .arg(&emulated)
        .arg("--write-station")
        .arg(&conn)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let emu = Emulator(child);
    let t0 = Instant::now();
    while !conn.exists() {
        assert!(
            t0.elapsed() < Duration::from_secs(30),
            "emulator did not start"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    let text = std::fs::read_to_string(&conn).unwrap();
    (emu, Station::from_yaml(&text, "connect.yaml").unwrap())
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

/// One session's figures.
#[derive(Debug, Default)]
struct Session {
    imu: u64,
    table: u64,
    lost: u64,
    corrupted: u64,
    cpu: Duration,
    /// Per sample, flush time minus stamp, ms.
    from_stamp_ms: Vec<f32>,
    /// Per sample, flush time minus its host arrival, ms.
    from_arrival_ms: Vec<f32>,
}

impl Session {
    fn report(&self, k: usize, secs: f64) -> String {
        let n = self.imu + self.table;
        format!(
            "session {k}: {secs} s, imu {} (expected {:.0}), table {} (expected {:.0}), lost {}, corrupted {}, cpu {:.2} us/sample, to disk from stamp {}, from arrival {}",
            self.imu,
            IMU_HZ * secs,
            self.table,
            TABLE_HZ * secs,
            self.lost,
            self.corrupted,
            self.cpu.as_secs_f64() * 1e6 / n.max(1) as f64,
            percentiles(&self.from_stamp_ms),
            percentiles(&self.from_arrival_ms),
        )
    }
}

/// `p50 / p95 / p99 / max` of delays in ms.
fn percentiles(v: &[f32]) -> String {
    let mut v = v.to_vec();
    v.sort_by(f32::total_cmp);
    let at = |q: f64| {
        v.get(((v.len() as f64 - 1.0) * q).round() as usize)
            .copied()
    };
    match (at(0.5), at(0.95), at(0.99), v.last()) {
        (Some(a), Some(b), Some(c), Some(d)) => {
            format!("p50 {a:.0} / p95 {b:.0} / p99 {c:.0} / max {d:.0} ms")
        }
        _ => "no samples".into(),
    }
}

fn session(st: &Station, secs: f64, dir: &Path) -> Session {
    let rt = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .unwrap();
    let cpu0 = cpu_time();
    let mut out = rt.block_on(async {
        let t0 = tokio::time::Instant::now();
        let (mut table, mut imu) = ratecal_drivers::build(st, 1).unwrap();
        let columns = Columns {
            imu_temp: true,
            ambient: true,
            imu_t_host: true,
            table_t_host: true,
        };
        let mut w = RecordingWriter::create(dir, manifest(st), columns).unwrap();
        let (mut ib, mut tb) = (Vec::new(), Vec::new());
        let mut s = Session::default();
        // (stamp, arrival) of every sample written since the last flush.
        let mut pending: Vec<(f64, f64)> = Vec::new();
        let mut tick = tokio::time::interval(Duration::from_millis(20));
        let mut last_sync = Instant::now();
        while t0.elapsed().as_secs_f64() < secs {
            tick.tick().await;
            ib.clear();
            tb.clear();
            let _ = imu.read(&mut ib).await;
            let _ = table.read(&mut tb).await;
            w.write_imu(&ib).unwrap();
            w.write_table(&tb).unwrap();
            s.imu += ib.len() as u64;
            s.table += tb.len() as u64;
            // A link driver stamps every sample's arrival; the tick that drained it is the
            // latest it can have arrived, should one not.
            let drained = t0.elapsed().as_secs_f64();
            let times = ib.iter().map(|x| (x.t, x.t_host));
            let times = times.chain(tb.iter().map(|x| (x.t, x.t_host)));
            pending.extend(times.map(|(t, h)| (t, h.unwrap_or(drained))));
            if last_sync.elapsed() >= Duration::from_millis(500) {
                last_sync = Instant::now();
                w.sync().unwrap();
                let h = t0.elapsed().as_secs_f64();
                for (t, a) in pending.drain(..) {
                    s.from_stamp_ms.push(((h - t) * 1e3) as f32);
                    s.from_arrival_ms.push(((h - a) * 1e3) as f32);
                }
            }
        }
        w.finish().unwrap();
        let (si, stt) = (imu.link_stats(), table.link_stats());
        let (si, stt) = (si.unwrap_or_default(), stt.unwrap_or_default());
        s.lost = si.lost + stt.lost;
        s.corrupted = si.corrupted + stt.corrupted;
        s
    });
    out.cpu = cpu_time() - cpu0;
    out
}

fn bench(c: &mut Criterion) {
    let tmp = tempfile::tempdir().unwrap();
    let (_emu, station) = emulator(tmp.path());
    let secs = secs();
    let mut g = c.benchmark_group("ingest");
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(1))
        .measurement_time(Duration::from_secs_f64(secs * 10.0))
        .throughput(Throughput::Elements(((IMU_HZ + TABLE_HZ) * secs) as u64));
    let mut k = 0;
    g.bench_function("imu 2 kHz + table 1 kHz, cpu time", |b| {
        b.iter_custom(|iters| {
            let mut cpu = Duration::ZERO;
            for _ in 0..iters {
                k += 1;
                let s = session(&station, secs, &tmp.path().join(format!("run{k}")));
                eprintln!("{}", s.report(k, secs));
                cpu += s.cpu;
            }
            cpu
        })
    });
    g.finish();
}

criterion_group!(benches, bench);

fn main() {
    let secs = secs();
    if secs < 60.0 {
        benches();
        Criterion::default().configure_from_args().final_summary();
        return;
    }
    // A long session is the figure itself: once, not ten times under Criterion.
    let tmp = tempfile::tempdir().unwrap();
    let (_emu, station) = emulator(tmp.path());
    let s = session(&station, secs, &tmp.path().join("run"));
    println!("{}", s.report(1, secs));
}
