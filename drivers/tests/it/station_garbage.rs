//! Garbage station files never panic: any text ends in a station or in a diagnostic that
//! names the file, a line and a column, with a help line. A station that loads also runs:
//! the simulated table and IMU built from it answer a short script with finite samples,
//! without panicking or hanging. (The `fuzz/` target `station_yaml` is the same property
//! for longer runs.)

use proptest::prelude::*;
use proptest::sample::Index;
use ratecal_drivers::station::{DropoutMode, FaultSpec};
use ratecal_drivers::{ImuSample, Station, StationError, TableAxisId, TableCommand, TableSample};
use std::time::Duration;

const FILE: &str = "lab.yaml";

const STATIONS: [&str; 7] = [
    include_str!("../../stations/default.yaml"),
    include_str!("../../stations/all-effects.yaml"),
    include_str!("../../stations/faulty-table.yaml"),
    include_str!("../../stations/imu-dropout.yaml"),
    include_str!("../../stations/runaway-table.yaml"),
    include_str!("../../stations/temperature-excursion.yaml"),
    include_str!("../../stations/with-lever-arm.yaml"),
];

fn render(err: &StationError) -> String {
    let mut out = String::new();
    miette::GraphicalReportHandler::new_themed(miette::GraphicalTheme::unicode_nocolor())
        .render_report(&mut out, err)
        .expect("a station error renders");
    out
}

/// Whatever `text` is: no panic; a refusal is located and helpful; a station runs.
fn assert_graceful(text: &str) {
    let input = changed(text);
    match Station::from_yaml(text, FILE) {
        Err(err) => {
            let shown = render(&err);
            let (Some(line), Some(column)) = (err.line, err.column) else {
                panic!("no line/column: {shown}\ninput: {input}");
            };
            // (miette counts columns in bytes, the parser in characters: for non-ASCII text
            // only the lines must agree.)
            let at = if text.is_ascii() {
                format!("{FILE}:{line}:{column}")
            } else {
                format!("{FILE}:{line}:")
            };
            assert!(
                column >= 1 && shown.contains(&at),
                "the rendered error does not name {FILE}:{line}:{column}:\n{shown}\ninput: {input}"
            );
            assert!(err.span.is_some(), "no span: {shown}\ninput: {input}");
            assert!(!err.help.trim().is_empty(), "no help: {shown}");
            assert!(shown.contains("help:"), "no help line: {shown}");
        }
        Ok(station) => run_briefly(&station, text),
    }
}

/// Builds the station's drivers and, for the simulated station, runs a short script on a
/// paused clock, on a thread of its own so that a hang fails the test instead of blocking.
fn run_briefly(station: &Station, text: &str) {
    let input = changed(text);
    let simulated = ratecal_drivers::registry::simulated(station);
    if !simulated {
        // Replay and TCP drivers touch files and sockets named in the text: not here.
        return;
    }
    let station = station.clone();
    let (tx, rx) = std::sync::mpsc::channel();
    let worker = std::thread::spawn(move || {
        let rt = tokio::runtime::Builder::new_current_thread()
            .enable_time()
            .start_paused(true)
            .build()
            .unwrap();
        let out = rt.block_on(script(&station));
        let _ = tx.send(());
        out
    });
    match rx.recv_timeout(Duration::from_secs(20)) {
        Ok(()) => {
            let (table, imu, station) = worker.join().unwrap_or_else(|p| {
                std::panic::resume_unwind(p);
            });
            check_samples(&station, &table, &imu, text);
        }
        Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => {
            // The worker panicked: report its panic.
            if let Err(p) = worker.join() {
                eprintln!("input: {input}");
                std::panic::resume_unwind(p);
            }
        }
        Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {
            panic!("the simulated station hangs\ninput: {input}")
        }
    }
}

async fn sleep(s: f64) {
    tokio::time::sleep(Duration::from_secs_f64(s)).await;
}

/// Moves, turns, sways and stops, reading both streams in between; long enough to reach
/// the station's faults when they come early, and never more than ~60k samples.
async fn script(station: &Station) -> (Vec<TableSample>, Vec<ImuSample>, Station) {
    let (mut table, mut imu) = ratecal_drivers::build(station, 5).expect("sim drivers build");
    let (mut fb, mut samples) = (Vec::new(), Vec::new());
    let fastest = station.imu.sample_rate.0.max(station.table.feedback_rate.0);
    let budget = (60_000.0 / fastest).min(600.0);
    let step = budget / 8.0;
    let cmds = [
        TableCommand::MoveTo {
            outer_deg: 30.0,
            inner_deg: -45.0,
        },
        TableCommand::Rate {
            axis: TableAxisId::Outer,
            rate_dps: 10.0,
        },
        TableCommand::Oscillate {
            axis: TableAxisId::Inner,
            center_deg: 0.0,
            amplitude_deg: 1.0,
            period_s: 2.0,
        },
        TableCommand::Stop {
            axis: TableAxisId::Outer,
        },
        TableCommand::SafeStop,
    ];
    for cmd in cmds {
        // Refusing a command the table cannot do is fine; panicking is not.
        let _ = table.command(cmd).await;
        sleep(step).await;
        table.read(&mut fb).await.expect("sim table reads");
        imu.read(&mut samples).await.expect("sim IMU reads");
    }
    sleep(3.0 * step).await;
    table.read(&mut fb).await.expect("sim table reads");
    imu.read(&mut samples).await.expect("sim IMU reads");
    (fb, samples, station.clone())
}

fn check_samples(station: &Station, fb: &[TableSample], imu: &[ImuSample], text: &str) {
    let input = changed(text);
    let nan_dropouts: Vec<(f64, f64)> = station
        .faults
        .iter()
        .filter_map(|f| match f {
            FaultSpec::ImuDropout {
                at,
                duration,
                mode: DropoutMode::Nan,
            } => Some((at.0, at.0 + duration.0)),
            _ => None,
        })
        .collect();
    assert!(!fb.is_empty(), "no table samples\ninput: {input}");
    for w in fb.windows(2) {
        assert!(w[1].t > w[0].t, "table time {:?}\ninput: {input}", w);
    }
    for s in fb {
        let v = [
            s.t,
            s.outer_deg,
            s.inner_deg,
            s.outer_rate_dps,
            s.inner_rate_dps,
            s.ambient_c.unwrap_or(0.0),
        ];
        assert!(
            v.iter().all(|x| x.is_finite()),
            "non-finite table sample {s:?}\ninput: {input}"
        );
    }
    for w in imu.windows(2) {
        assert!(w[1].t > w[0].t, "IMU time {:?}\ninput: {input}", w);
    }
    for s in imu {
        assert!(s.t.is_finite(), "IMU time {s:?}\ninput: {input}");
        if nan_dropouts.iter().any(|&(a, b)| s.t >= a && s.t < b) {
            continue;
        }
        let v = s.accel.iter().chain(&s.gyro).chain(&s.temp_c);
        assert!(
            v.into_iter().all(|x| x.is_finite()),
            "non-finite IMU sample {s:?}\ninput: {input}"
        );
    }
}

/// The lines of `text` that no example station has (the whole text if that is short).
fn changed(text: &str) -> String {
    let known: std::collections::HashSet<&str> = STATIONS.iter().flat_map(|s| s.lines()).collect();
    let new: Vec<String> = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !known.contains(l))
        .map(|(i, l)| format!("{}: {l:?}", i + 1))
        .collect();
    if text.len() < 400 {
        format!("{text:?}")
    } else {
        format!(
            "{} lines; new or changed:\n{}",
            text.lines().count(),
            new.join("\n")
        )
    }
}

/// Odd values a hand-edited station file may hold where a number was.
const TOKENS: &[&str] = &[
    "1e400",
    "-1e400",
    "-0",
    "0",
    "nan",
    ".nan",
    ".inf",
    "-.inf",
    "inf",
    "\"\"",
    "[",
    "]",
    "{",
    "}",
    "~",
    "null",
    "-1",
    "1e-300",
    "5e-324",
    "1e300",
    "1e18",
    "0x10",
    "1_000",
    "1.2.3",
    "+.5",
    "-",
    ".",
    "e5",
    "99999999999999999999999",
    "0.0000001",
    "true",
    "'x'",
    "&a",
    "*a",
    "!!str",
    ":",
    "#",
    "- 1",
    "1,2",
];

/// Units (of every kind) and things that are not units, for where a unit was.
const UNITS: &[&str] = &[
    "deg",
    "rad",
    "arcsec",
    "deg/s",
    "rad/s",
    "deg/h",
    "rpm",
    "g",
    "mg",
    "ug",
    "m/s^2",
    "s",
    "ms",
    "min",
    "h",
    "Hz",
    "kHz",
    "degC",
    "K",
    "degC/h",
    "%",
    "ppm",
    "kPa",
    "Pa",
    "deg/s/rtHz",
    "ug/rtHz",
    "deg/s/rts",
    "/rtHz",
    "/rts",
    "/√Hz",
    "√",
    "",
    " ",
    "furlongs",
    "Hz Hz",
    "deg/s/",
    "é",
    "deg/s #",
];

#[derive(Debug, Clone)]
enum Mutation {
    DeleteRange(Index, usize),
    DuplicateLine(Index),
    SwapLines(Index, Index),
    DeleteLine(Index),
    ReplaceNumber(Index, usize),
    ReplaceUnit(Index, usize),
    Indent(Index, usize),
    Dedent(Index),
    InsertTab(Index),
    InsertByte(Index, u8),
    InsertText(Index, usize),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (any::<Index>(), 1usize..40).prop_map(|(i, n)| Mutation::DeleteRange(i, n)),
        any::<Index>().prop_map(Mutation::DuplicateLine),
        (any::<Index>(), any::<Index>()).prop_map(|(a, b)| Mutation::SwapLines(a, b)),
        any::<Index>().prop_map(Mutation::DeleteLine),
        (any::<Index>(), 0..TOKENS.len()).prop_map(|(i, t)| Mutation::ReplaceNumber(i, t)),
        (any::<Index>(), 0..UNITS.len()).prop_map(|(i, u)| Mutation::ReplaceUnit(i, u)),
        (any::<Index>(), 1usize..5).prop_map(|(i, n)| Mutation::Indent(i, n)),
        any::<Index>().prop_map(Mutation::Dedent),
        any::<Index>().prop_map(Mutation::InsertTab),
        (any::<Index>(), any::<u8>()).prop_map(|(i, b)| Mutation::InsertByte(i, b)),
        (any::<Index>(), 0..TOKENS.len()).prop_map(|(i, t)| Mutation::InsertText(i, t)),
    ]
}

/// Byte ranges of the numbers in `text` (digits with their sign, point and exponent).
fn numbers(text: &str) -> Vec<(usize, usize)> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        if b[i].is_ascii_digit() {
            let mut s = i;
            if s > 0 && (b[s - 1] == b'-' || b[s - 1] == b'.') {
                s -= 1;
            }
            while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'.' || b[i] == b'-') {
                // Stop before a unit glued to nothing: `e` only inside an exponent.
                if b[i].is_ascii_alphabetic() && !matches!(b[i], b'e' | b'E') {
                    break;
                }
                i += 1;
            }
            out.push((s, i));
        } else {
            i += 1;
        }
    }
    out
}

/// Byte ranges of the units in `text`: what follows `<number> ` up to a `,`, `]`, `}`,
/// `#` or the line end.
fn units(text: &str) -> Vec<(usize, usize)> {
    let b = text.as_bytes();
    numbers(text)
        .into_iter()
        .filter(|&(_, e)| {
            b.get(e) == Some(&b' ') && b.get(e + 1).is_some_and(|c| !b" #,]}".contains(c))
        })
        .map(|(_, e)| {
            let s = e + 1;
            let n = b[s..]
                .iter()
                .position(|c| b",]}#\n".contains(c))
                .unwrap_or(b.len() - s);
            let mut end = s + n;
            while end > s && b[end - 1] == b' ' {
                end -= 1;
            }
            (s, end)
        })
        .collect()
}

fn lines(text: &str) -> Vec<String> {
    text.split_inclusive('\n').map(str::to_string).collect()
}

fn apply(text: &str, m: &Mutation) -> String {
    let mut bytes = text.as_bytes().to_vec();
    let mut ls = lines(text);
    let at = |i: &Index, n: usize| if n == 0 { 0 } else { i.index(n) };
    match m {
        Mutation::DeleteRange(i, n) => {
            let s = at(i, bytes.len());
            let e = (s + n).min(bytes.len());
            bytes.drain(s..e);
        }
        Mutation::InsertByte(i, b) => {
            let s = at(i, bytes.len() + 1);
            bytes.insert(s, *b);
        }
        Mutation::InsertTab(i) => {
            let s = at(i, bytes.len() + 1);
            bytes.insert(s, b'\t');
        }
        Mutation::InsertText(i, t) => {
            let s = at(i, bytes.len() + 1);
            bytes.splice(s..s, TOKENS[*t].bytes());
        }
        Mutation::ReplaceNumber(i, t) => {
            let spans = numbers(text);
            if !spans.is_empty() {
                let (s, e) = spans[i.index(spans.len())];
                bytes.splice(s..e, TOKENS[*t].bytes());
            }
        }
        Mutation::ReplaceUnit(i, u) => {
            let spans = units(text);
            if !spans.is_empty() {
                let (s, e) = spans[i.index(spans.len())];
                bytes.splice(s..e, UNITS[*u].bytes());
            }
        }
        _ if ls.is_empty() => {}
        Mutation::DuplicateLine(i) => {
            let k = i.index(ls.len());
            let l = ls[k].clone();
            ls.insert(k, l);
            return ls.concat();
        }
        Mutation::SwapLines(a, b) => {
            let (a, b) = (a.index(ls.len()), b.index(ls.len()));
            ls.swap(a, b);
            return ls.concat();
        }
        Mutation::DeleteLine(i) => {
            ls.remove(i.index(ls.len()));
            return ls.concat();
        }
        Mutation::Indent(i, n) => {
            let k = i.index(ls.len());
            ls[k] = format!("{}{}", " ".repeat(*n), ls[k]);
            return ls.concat();
        }
        Mutation::Dedent(i) => {
            let k = i.index(ls.len());
            ls[k] = ls[k].trim_start().to_string();
            return ls.concat();
        }
    }
    String::from_utf8_lossy(&bytes).into_owned()
}

proptest! {
    // 256 cases; PROPTEST_CASES=N runs longer (proptest's default reads it).
    #![proptest_config(ProptestConfig {
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn random_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
        assert_graceful(&String::from_utf8_lossy(&bytes));
    }

    #[test]
    fn mutated_station_files_load_or_are_located(
        base in 0..STATIONS.len(),
        muts in proptest::collection::vec(mutation(), 1..4),
    ) {
        let mut text = STATIONS[base].to_string();
        for m in &muts {
            text = apply(&text, m);
        }
        assert_graceful(&text);
    }

    /// One odd token for one number: the most common hand edit, tried on every number.
    #[test]
    fn every_number_replaced_by_an_odd_token(
        base in 0..STATIONS.len(),
        at in any::<Index>(),
        token in 0..TOKENS.len(),
    ) {
        assert_graceful(&apply(STATIONS[base], &Mutation::ReplaceNumber(at, token)));
    }

    #[test]
    fn every_unit_replaced(
        base in 0..STATIONS.len(),
        at in any::<Index>(),
        unit in 0..UNITS.len(),
    ) {
        assert_graceful(&apply(STATIONS[base], &Mutation::ReplaceUnit(at, unit)));
    }
}

#[test]
fn the_example_stations_run_the_script() {
    for text in STATIONS {
        assert_graceful(text);
        assert!(Station::from_yaml(text, FILE).is_ok());
    }
}

#[test]
fn mutation_helpers_find_numbers_and_units() {
    let text =
        "  max_rate: 500 deg/s\n  accel_bias: [1.2 mg, -0.8 mg, 2.1 mg]\n  x: 1e-6 deg/s/rts # c\n";
    let n: Vec<&str> = numbers(text).iter().map(|&(s, e)| &text[s..e]).collect();
    assert_eq!(n, ["500", "1.2", "-0.8", "2.1", "1e-6"]);
    let u: Vec<&str> = units(text).iter().map(|&(s, e)| &text[s..e]).collect();
    assert_eq!(u, ["deg/s", "mg", "mg", "mg", "deg/s/rts"]);
}
