//! `procedures/station-check` in real time against `ratecal emulate` over loopback: a clean
//! run over TCP and over pseudo-terminals, and one run per fault type (each ends cleanly:
//! exit 4, the manifest says why and when, the recording is one `ratecal analyze` reads;
//! the faults a run survives are counted in `run.sync`; a clean run's per-sample host
//! arrival times agree with it, `host_times.rs`). The scenarios run side by side
//! (they mostly wait on the clock), so the whole file takes about one run's time.

#[path = "emulate_e2e/host_times.rs"]
mod host_times;

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

const BIN: &str = env!("CARGO_BIN_EXE_ratecal");

fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// A running emulator, stopped (by its own pid) when dropped.
struct Emulator(Child);

impl Drop for Emulator {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// The default station at 200 Hz with these faults, emulated; returns the emulator and
/// the connecting station file.
fn emulate(dir: &Path, faults: &str, pty: bool) -> (Emulator, PathBuf) {
    let yaml = std::fs::read_to_string(repo().join("drivers/stations/default.yaml"))
        .unwrap()
        .replace("sample_rate: 100 Hz", "sample_rate: 200 Hz")
        .replace("faults: []", &format!("faults:\n{faults}"));
    let station = dir.join("emulated.yaml");
    std::fs::write(&station, yaml).unwrap();
    let conn = dir.join("connect.yaml");
    let mut cmd = Command::new(BIN);
    cmd.arg("emulate")
        .arg("--station")
        .arg(&station)
        .arg("--write-station")
        .arg(&conn)
        .stdout(Stdio::null())
        .stderr(Stdio::null());
    if pty {
        cmd.arg("--pty");
    }
    let child = Emulator(cmd.spawn().unwrap());
    let t0 = Instant::now();
    while !conn.exists() {
        assert!(
            t0.elapsed() < Duration::from_secs(20),
            "the emulator did not start"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    (child, conn)
}

/// What a scenario saw.
struct Seen {
    name: &'static str,
    code: i32,
    output: String,
    manifest: String,
    /// `manifest.yaml`, `imu.csv` and `table.csv` as written.
    files: [String; 3],
    analyze_code: i32,
}

/// `ratecal run procedures/station-check --station CONN --out OUT`, its output piped.
fn spawn_station_check(conn: &Path, out: &Path) -> Child {
    Command::new(BIN)
        .args(["run", "procedures/station-check", "--station"])
        .arg(conn)
        .arg("--out")
        .arg(out)
        .current_dir(repo())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

fn run_scenario(name: &'static str, faults: &str, pty: bool, interrupt_at: Option<f64>) -> Seen {
    let tmp = tempfile::tempdir().unwrap();
    let (_emu, conn) = emulate(tmp.path(), faults, pty);
    let out = tmp.path().join("run");
    let child = spawn_station_check(&conn, &out);
    if let Some(t) = interrupt_at {
        std::thread::sleep(Duration::from_secs_f64(t));
        // Twice: the second Ctrl-C must not skip the safe stop, nor change the exit code.
        for _ in 0..2 {
            let _ = Command::new("kill")
                .args(["-INT", &child.id().to_string()])
                .status();
            std::thread::sleep(Duration::from_millis(100));
        }
    }
    let o: Output = child.wait_with_output().unwrap();
    // The journal and the report ride along with the manifest: the journal records the
    // safe stop, the report the synchronisation.
    let manifest = ["manifest.yaml", "journal.jsonl", "report.md"]
        .iter()
        .map(|f| std::fs::read_to_string(out.join(f)).unwrap_or_default())
        .collect::<String>();
    let files = ["manifest.yaml", "imu.csv", "table.csv"]
        .map(|f| std::fs::read_to_string(out.join(f)).unwrap_or_default());
    let analyze = Command::new(BIN)
        .arg("analyze")
        .arg(&out)
        .current_dir(repo())
        .output()
        .unwrap();
    Seen {
        name,
        code: o.status.code().unwrap_or(-1),
        output: format!(
            "{}{}",
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        ),
        manifest,
        files,
        analyze_code: analyze.status.code().unwrap_or(-1),
    }
}

/// Checks one scenario; returns what is wrong.
fn check(s: &Seen, code: i32, status: &str, needles: &[&str]) -> Vec<String> {
    let mut wrong = Vec::new();
    let ctx = || {
        format!(
            "{}\n--- output\n{}\n--- manifest\n{}",
            s.name, s.output, s.manifest
        )
    };
    if s.code != code {
        wrong.push(format!("exit {} (expected {code}): {}", s.code, ctx()));
    }
    if !s.manifest.contains(&format!("status: {status}")) {
        wrong.push(format!("status is not {status}: {}", ctx()));
    }
    for n in needles {
        if *n == "corrupted > 0" {
            let counted = s
                .output
                .lines()
                .find_map(|l| l.strip_prefix("imu link: "))
                .and_then(|l| l.split(", ").nth(1)?.split(' ').next()?.parse::<u64>().ok());
            if counted.is_none_or(|c| c == 0) {
                wrong.push(format!("no corrupted frame counted: {}", ctx()));
            }
        } else if *n == "no lost frames" {
            // `NAME link: N samples, C corrupted (skipped), L lost, ...`, for both links.
            let lost: Vec<Option<u64>> = ["imu link: ", "table link: "]
                .iter()
                .map(|p| {
                    let l = s.output.lines().find_map(|l| l.strip_prefix(p))?;
                    l.split(", ").nth(2)?.split(' ').next()?.parse().ok()
                })
                .collect();
            if lost.iter().any(|l| *l != Some(0)) {
                wrong.push(format!("lost frames {lost:?} (expected none): {}", ctx()));
            }
        } else if *n == "host times" {
            let [manifest, imu, table] = &s.files;
            for w in host_times::check(s.name, manifest, imu, table) {
                wrong.push(format!("{w}: {}", s.name));
            }
        } else if !s.manifest.contains(n) && !s.output.contains(n) {
            wrong.push(format!("`{n}` missing: {}", ctx()));
        }
    }
    // The recording kept is one analyze reads (3: the verdict of an aborted run).
    if ![0, 3].contains(&s.analyze_code) {
        wrong.push(format!("analyze exit {}: {}", s.analyze_code, ctx()));
    }
    wrong
}

#[test]
fn station_check_against_the_emulator() {
    type Scenario = (
        &'static str,
        &'static str,
        bool,
        Option<f64>,
        i32,
        &'static str,
        &'static [&'static str],
    );
    let scenarios: Vec<Scenario> = vec![
        (
            "clean over tcp",
            "  []",
            false,
            None,
            0,
            "completed",
            &[
                "table_minus_imu_s",
                "imu link: ",
                "Table-to-IMU sync",
                "behind the run clock (device stamp = t - this)",
                "no lost frames",
                "host times",
            ],
        ),
        #[cfg(unix)]
        (
            "clean over pty",
            "  []",
            true,
            None,
            0,
            "completed",
            &["table_minus_imu_s", "no lost frames", "host times"],
        ),
        (
            "link back within its timeout, corrupted frames",
            "  - link_drop: { at: 3 s, link: table, duration: 0.3 s }\n  - link_drop: { at: 6 s, link: imu }\n  - corrupt_frames: { at: 2 s, duration: 5 s, every: 10 }",
            false,
            None,
            0,
            "completed",
            &["reconnects: 1", "corrupted > 0"],
        ),
        (
            "imu link dropped for good",
            "  - link_drop: { at: 3 s, link: imu, duration: 60 s }",
            false,
            None,
            4,
            "aborted",
            &["abort:", "ABORTED"],
        ),
        (
            "table link dropped for good",
            "  - link_drop: { at: 3 s, link: table, duration: 60 s }",
            false,
            None,
            4,
            "aborted",
            &[
                "abort:",
                "\"safe_state\",\"at_rest\":false",
                "WARNING: the table was NOT confirmed at rest",
            ],
        ),
        (
            "imu stall",
            "  - stall: { at: 3 s, link: imu, duration: 10 s }",
            false,
            None,
            4,
            "aborted",
            &["abort:"],
        ),
        (
            "table stall",
            "  - stall: { at: 3 s, link: table, duration: 10 s }",
            false,
            None,
            4,
            "aborted",
            &["abort:"],
        ),
        (
            "table fault flag",
            "  - table_fault_flag: { at: 3 s }",
            false,
            None,
            4,
            "aborted",
            &["Instrument", "FAULT"],
        ),
        (
            "imu saturation",
            "  - imu_saturation: { at: 3 s, duration: 5 s }",
            false,
            None,
            4,
            "aborted",
            &["imu.output abnormal"],
        ),
        (
            "simulated table fault",
            "  - table: { at: 3 s, axis: outer, mode: stuck }",
            false,
            None,
            4,
            "aborted",
            &["abort:"],
        ),
        (
            "ctrl-c twice",
            "  []",
            false,
            Some(4.0),
            4,
            "aborted",
            &["Ctrl-C", "\"safe_state\",\"at_rest\":true"],
        ),
    ];
    let handles: Vec<_> = scenarios
        .into_iter()
        .map(|(name, faults, pty, int, code, status, needles)| {
            std::thread::spawn(move || {
                let seen = run_scenario(name, faults, pty, int);
                check(&seen, code, status, needles)
            })
        })
        .collect();
    let wrong: Vec<String> = handles
        .into_iter()
        .flat_map(|h| h.join().unwrap())
        .collect();
    assert!(wrong.is_empty(), "{}", wrong.join("\n\n"));
}

/// The emulator stops mid-run (issue 26, item 9): the table cannot answer the safe stop.
/// The refusal and the table not seen at rest are counted warnings, the summary's count is
/// the journal's, and the console's last line says plainly to check the table.
#[test]
fn a_refused_safe_stop_is_counted_and_printed_last() {
    let tmp = tempfile::tempdir().unwrap();
    let (emu, conn) = emulate(tmp.path(), "  []", false);
    let out = tmp.path().join("run");
    let child = spawn_station_check(&conn, &out);
    std::thread::sleep(Duration::from_secs(3));
    drop(emu); // killed: nothing answers any more
    let o = child.wait_with_output().unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout).into_owned();
    let all = format!("{stdout}{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(o.status.code(), Some(4), "{all}");
    let journal = std::fs::read_to_string(out.join("journal.jsonl")).unwrap();
    assert!(journal.contains("\"at_rest\":false"), "{journal}");
    let warnings = journal
        .lines()
        .filter(|l| l.contains("\"event\":\"warning\"") || l.contains("\"action\":\"warn\""))
        .count();
    assert!(warnings >= 1, "{journal}");
    // Every warning the journal holds is listed as one of the run's, and the summary's count
    // is that of the warnings it lists (the run's and the analysis's).
    let during = stdout
        .lines()
        .filter(|l| l.starts_with("  warning: during the run"))
        .count();
    assert_eq!(during, warnings, "{all}\n{journal}");
    let listed = stdout
        .lines()
        .filter(|l| l.starts_with("  warning: "))
        .count();
    assert!(
        all.contains(&format!("warnings: {listed}\n")),
        "the summary's count is not the {listed} listed: {all}\n{journal}"
    );
    let last = stdout
        .lines()
        .rev()
        .find(|l| !l.trim().is_empty())
        .unwrap_or("");
    assert_eq!(
        last, "WARNING: the table was NOT confirmed at rest: check it before approaching",
        "{all}"
    );
    assert!(!all.contains("warnings: 0"), "{all}");
}
