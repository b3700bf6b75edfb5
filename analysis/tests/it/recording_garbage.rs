//! Garbage recordings never panic: any three files end in a recording that keeps what
//! `read` promises (and that the analysis takes without panicking), or in a diagnostic
//! naming the file, a line and a column, with a help line. The fast CSV path and the exact
//! one read the same numbers alike. (The `fuzz/` target `recording_read` is the same
//! property for longer runs.)

use miette::{Diagnostic, GraphicalReportHandler, GraphicalTheme};
use proptest::prelude::*;
use proptest::sample::Index;
use ratecal_recording::{self as recording, Recording, RecordingError};

const FILES: [&str; 3] = ["manifest.yaml", "imu.csv", "table.csv"];

const MANIFEST: &str = "format: ratecal-recording/1
station:
  site: { latitude_deg: 55.7, gravity_mps2: 9.8156 }
  table: { outer_axis: [0, -1, 0], inner_axis: [1, 0, 0] }
  mount:
    rotation: [[1, 0, 0], [0, 1, 0], [0, 0, 1]]
imu: { model: X, serial: \"1\" }
segments:
  - { id: a, kind: static, t_start: 0.0, t_end: 0.25 }
  - { id: \"b/+10\", kind: rate, axis: outer, rate_dps: 10.0, t_start: 0.3, t_end: 0.5 }
  - id: c
    kind: oscillation
    axis: inner
    amplitude_deg: 1.5
    period_s: 0.2
    center_deg: 0
    t_start: 0.55
    t_end: 0.7
environment: { temperature_c: 21.5 }
";

fn imu_text() -> String {
    let mut s = String::from("t,ax,ay,az,gx,gy,gz,temp\n");
    for i in 0..16 {
        let t = i as f64 * 0.05;
        s += &format!(
            "{t:.2},0.0{i},-0.02,9.81,{:.3},0.2,-0.3,22.{i}\n",
            if t > 0.28 && t < 0.52 { 10.1 } else { 0.1 }
        );
    }
    s
}

fn table_text() -> String {
    let mut s = String::from("t,outer,inner,outer_rate,inner_rate,ambient\n");
    for i in 0..9 {
        let t = i as f64 * 0.1;
        let rate = if t > 0.28 && t < 0.52 { 10.0 } else { 0.0 };
        s += &format!("{t:.1},{:.2},0,{rate},0,21.5\n", rate * t);
    }
    s
}

fn valid() -> [Vec<u8>; 3] {
    [
        MANIFEST.as_bytes().to_vec(),
        imu_text().into_bytes(),
        table_text().into_bytes(),
    ]
}

fn render(e: &RecordingError) -> String {
    let mut out = String::new();
    GraphicalReportHandler::new_themed(GraphicalTheme::unicode_nocolor())
        .with_width(120)
        .render_report(&mut out, e)
        .expect("a recording error renders");
    out
}

/// Whether `shown` holds `path:LINE:COLUMN`.
fn names_line_and_column(shown: &str, path: &str) -> bool {
    shown.match_indices(path).any(|(i, _)| {
        let rest = &shown[i + path.len()..];
        let mut parts = rest.splitn(3, ':');
        parts.next() == Some("")
            && parts
                .next()
                .is_some_and(|l| !l.is_empty() && l.bytes().all(|b| b.is_ascii_digit()))
            && parts
                .next()
                .is_some_and(|c| c.bytes().next().is_some_and(|b| b.is_ascii_digit()))
    })
}

/// Writes the three files (a `None` is left out), reads, and checks the outcome.
fn check(files: &[Option<&[u8]>; 3]) -> Option<Recording> {
    let tmp = tempfile::tempdir().unwrap();
    for (name, bytes) in FILES.iter().zip(files) {
        if let Some(b) = bytes {
            std::fs::write(tmp.path().join(name), b).unwrap();
        }
    }
    let shown_input = || {
        files
            .iter()
            .map(|f| f.map(String::from_utf8_lossy))
            .collect::<Vec<_>>()
    };
    match recording::read(tmp.path()) {
        Err(e) => {
            let shown = render(&e);
            if let RecordingError::Io { .. } = e {
                return None;
            }
            let named = FILES
                .iter()
                .map(|f| tmp.path().join(f).display().to_string())
                .any(|p| names_line_and_column(&shown, &p));
            assert!(
                named,
                "not located (file:line:column):\n{shown}\ninput: {:?}",
                shown_input()
            );
            // The snippet's header shows the line the message names.
            if let Some(line) = line_of(&e) {
                let header = FILES
                    .iter()
                    .map(|f| format!("[{}:{line}:", tmp.path().join(f).display()))
                    .any(|h| shown.contains(&h));
                assert!(
                    header,
                    "the snippet is not on line {line}:\n{shown}\ninput: {:?}",
                    shown_input()
                );
            }
            assert!(e.help().is_some(), "no help: {shown}");
            assert!(shown.contains("help:"), "no help line: {shown}");
            None
        }
        Ok(rec) => {
            check_promises(&rec, &format!("{:?}", shown_input()));
            // Odd but valid recordings are analysed without panicking.
            let _ = ratecal_analysis::fit::analyze(&rec, None);
            Some(rec)
        }
    }
}

/// The line an error names in its message, if it names one.
fn line_of(e: &RecordingError) -> Option<u64> {
    use RecordingError::*;
    match e {
        NotANumber { line, .. }
        | RaggedRow { line, .. }
        | TimeNotIncreasing { line, .. }
        | EmptyStream { line, .. }
        | Manifest { line, .. }
        | UnknownFormat { line, .. }
        | SegmentOutside { line, .. }
        | EmptySegment { line, .. } => Some(*line),
        MissingColumn { .. } => Some(1),
        _ => None,
    }
}

/// What `read` promises about a recording it returns.
fn check_promises(rec: &Recording, input: &str) {
    let (imu, table) = (&rec.imu, &rec.table);
    assert!(imu.t.len() >= 2 && table.t.len() >= 2, "{input}");
    for t in [&imu.t, &table.t] {
        assert!(t.windows(2).all(|w| w[1] > w[0]), "time {t:?}\n{input}");
    }
    let n = imu.t.len();
    assert!(
        imu.accel.iter().chain(&imu.gyro).all(|c| c.len() == n),
        "{input}"
    );
    assert!(imu.temp.as_ref().is_none_or(|c| c.len() == n), "{input}");
    let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
    assert!(finite(&imu.t), "{input}");
    assert!(
        imu.accel.iter().chain(&imu.gyro).all(|c| finite(c)),
        "{input}"
    );
    assert!(imu.temp.as_deref().is_none_or(finite), "{input}");
    let m = table.t.len();
    for c in [
        &table.outer,
        &table.inner,
        &table.outer_rate,
        &table.inner_rate,
    ] {
        assert!(c.len() == m && finite(c), "{input}");
    }
    assert!(
        table
            .ambient
            .as_ref()
            .is_none_or(|c| c.len() == m && finite(c))
    );
    for s in &rec.manifest.segments {
        assert!(
            s.t_start.is_finite() && s.t_end.is_finite() && s.t_end > s.t_start,
            "{s:?}\n{input}"
        );
        assert!(
            imu.t.iter().any(|&t| t >= s.t_start && t <= s.t_end),
            "empty segment {s:?}\n{input}"
        );
    }
}

/// Odd cells: not numbers, numbers the fast path leaves to the exact one, CSV structure.
const CELLS: &[&str] = &[
    "nan",
    "NaN",
    "inf",
    "-inf",
    "infinity",
    "1e999",
    "-1e999",
    "1e-999",
    "-",
    "+",
    ".",
    "-.",
    "1.2.3",
    "0x10",
    "",
    " ",
    "\"1\"",
    "\"",
    "\"\"",
    "\"1,2\"",
    "\"1\n2\"",
    "1,2",
    ",",
    " 1",
    "1 ",
    "+1",
    "-0",
    "-0.0",
    "+.5",
    "5.",
    "1e",
    "1e+",
    "1E-3",
    "--1",
    "1_0",
    "١",
    "é",
    "\u{feff}1",
    "99999999999999999999",
    "99999999999999999999999999999999999999999",
    "18446744073709551616",
    "123456789012345678901234567890.5",
    "0.000000000000000000000000000000000000001",
    "1e308",
    "-1e308",
    "4.9e-324",
    "1e22",
    "1e23",
    "12345678.5",
    "1.12345678",
    "0.1234567",
    "\r",
    "\n",
    "\r\n",
    "#",
    "t",
    "ax",
];

/// Tokens for numbers in the manifest (segment times, site, axes).
const YAML_NUMBERS: &[&str] = &[
    ".nan",
    ".inf",
    "-.inf",
    "1e999",
    "-1",
    "0",
    "-0",
    "1e9",
    "0.25",
    "0.3",
    "0.5",
    "0.75",
    "1e-300",
    "\"0.1\"",
    "~",
    "[",
    "{",
    "x",
    "0x10",
    "99999999999999999999",
];

#[derive(Debug, Clone)]
enum Mutation {
    Truncate(Index),
    InsertByte(Index, u8),
    DeleteRange(Index, usize),
    DuplicateLine(Index),
    SwapLines(Index, Index),
    DeleteLine(Index),
    ReplaceCell(Index, usize),
    InsertCell(Index, usize),
    ReplaceYamlNumber(Index, usize),
    LongDigits(Index, usize, bool),
    Crlf,
    Bom,
    NonUtf8(Index),
    Cr(Index),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        any::<Index>().prop_map(Mutation::Truncate),
        (any::<Index>(), any::<u8>()).prop_map(|(i, b)| Mutation::InsertByte(i, b)),
        (any::<Index>(), 1usize..30).prop_map(|(i, n)| Mutation::DeleteRange(i, n)),
        any::<Index>().prop_map(Mutation::DuplicateLine),
        (any::<Index>(), any::<Index>()).prop_map(|(a, b)| Mutation::SwapLines(a, b)),
        any::<Index>().prop_map(Mutation::DeleteLine),
        (any::<Index>(), 0..CELLS.len()).prop_map(|(i, c)| Mutation::ReplaceCell(i, c)),
        (any::<Index>(), 0..CELLS.len()).prop_map(|(i, c)| Mutation::InsertCell(i, c)),
        (any::<Index>(), 0..YAML_NUMBERS.len())
            .prop_map(|(i, c)| Mutation::ReplaceYamlNumber(i, c)),
        (any::<Index>(), 1usize..400, any::<bool>())
            .prop_map(|(i, n, p)| Mutation::LongDigits(i, n, p)),
        Just(Mutation::Crlf),
        Just(Mutation::Bom),
        any::<Index>().prop_map(Mutation::NonUtf8),
        any::<Index>().prop_map(Mutation::Cr),
    ]
}

/// Byte ranges of the cells of a CSV text (split at `,` and line ends).
fn cells(b: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut s = 0;
    for (i, &c) in b.iter().enumerate() {
        if c == b',' || c == b'\n' {
            out.push((s, i));
            s = i + 1;
        }
    }
    if s < b.len() {
        out.push((s, b.len()));
    }
    out
}

/// Byte ranges of the numbers of a YAML text.
fn yaml_numbers(b: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let starts =
            b[i].is_ascii_digit() || (b[i] == b'-' && b.get(i + 1).is_some_and(u8::is_ascii_digit));
        if starts && (i == 0 || b" [,:".contains(&b[i - 1])) {
            let s = i;
            i += 1;
            while i < b.len() && (b[i].is_ascii_digit() || b".eE-+".contains(&b[i])) {
                i += 1;
            }
            out.push((s, i));
        } else {
            i += 1;
        }
    }
    out
}

fn lines(b: &[u8]) -> Vec<Vec<u8>> {
    b.split_inclusive(|&c| c == b'\n')
        .map(<[u8]>::to_vec)
        .collect()
}

fn apply(b: &mut Vec<u8>, m: &Mutation) {
    let at = |i: &Index, n: usize| if n == 0 { 0 } else { i.index(n) };
    let splice_at = |b: &mut Vec<u8>, spans: Vec<(usize, usize)>, i: &Index, with: &[u8]| {
        if !spans.is_empty() {
            let (s, e) = spans[i.index(spans.len())];
            b.splice(s..e, with.iter().copied());
        }
    };
    let mut ls = lines(b);
    match m {
        Mutation::Truncate(i) => b.truncate(at(i, b.len() + 1)),
        Mutation::InsertByte(i, c) => b.insert(at(i, b.len() + 1), *c),
        Mutation::DeleteRange(i, n) => {
            let s = at(i, b.len());
            let e = (s + n).min(b.len());
            b.drain(s..e);
        }
        Mutation::ReplaceCell(i, c) => splice_at(b, cells(b), i, CELLS[*c].as_bytes()),
        Mutation::InsertCell(i, c) => {
            let s = at(i, b.len() + 1);
            b.splice(s..s, CELLS[*c].bytes());
        }
        Mutation::ReplaceYamlNumber(i, c) => {
            splice_at(b, yaml_numbers(b), i, YAML_NUMBERS[*c].as_bytes())
        }
        Mutation::LongDigits(i, n, point) => {
            let mut d = "7".repeat(*n);
            if *point {
                d.insert(n / 2, '.');
            }
            splice_at(b, cells(b), i, d.as_bytes())
        }
        Mutation::Crlf => {
            let mut out = Vec::with_capacity(b.len() * 2);
            for &c in b.iter() {
                if c == b'\n' {
                    out.push(b'\r');
                }
                out.push(c);
            }
            *b = out;
        }
        Mutation::Bom => {
            b.splice(0..0, "\u{feff}".bytes());
        }
        Mutation::NonUtf8(i) => {
            let s = at(i, b.len() + 1);
            b.splice(s..s, [0xff, 0xfe, 0xc3]);
        }
        Mutation::Cr(i) => {
            let s = at(i, b.len() + 1);
            b.insert(s, b'\r');
        }
        _ if ls.is_empty() => {}
        Mutation::DuplicateLine(i) => {
            let k = i.index(ls.len());
            ls.insert(k, ls[k].clone());
            *b = ls.concat();
        }
        Mutation::SwapLines(x, y) => {
            let (x, y) = (x.index(ls.len()), y.index(ls.len()));
            ls.swap(x, y);
            *b = ls.concat();
        }
        Mutation::DeleteLine(i) => {
            ls.remove(i.index(ls.len()));
            *b = ls.concat();
        }
    }
}

/// A number written the ways other acquisition systems write numbers.
fn number_text() -> impl Strategy<Value = String> {
    prop_oneof![
        (-1_000_000i64..1_000_000).prop_map(|i| i.to_string()),
        (-1e6f64..1e6, 0usize..17).prop_map(|(x, d)| format!("{x:.d$}")),
        (-1e3f64..1e3).prop_map(|x| format!("{x}")),
        (-1e3f64..1e3).prop_map(|x| format!("{x:e}")),
        (-1e3f64..1e3).prop_map(|x| format!("{x:E}")),
        (0f64..1e3, 0usize..9).prop_map(|(x, d)| format!("+{x:.d$}")),
        (-300i32..300, 1u32..99).prop_map(|(e, m)| format!("{m}e{e}")),
        (1u32..99999, 0usize..8).prop_map(|(m, z)| format!("0.{}{m}", "0".repeat(z))),
        (1u64..u64::MAX).prop_map(|i| i.to_string()),
        Just("-0".to_string()),
        Just("-0.0".to_string()),
        Just("0".to_string()),
        Just(".5".to_string()),
        Just("5.".to_string()),
        Just("-.25".to_string()),
        Just("1.7976931348623157e308".to_string()),
        Just("2.2250738585072014e-308".to_string()),
        Just("5e-324".to_string()),
        Just("0.1000000000000000055511151231257827".to_string()),
    ]
}

/// Strictly increasing times, written exactly (shortest round trip, maybe `+` or `e`).
fn times(n: usize) -> impl Strategy<Value = Vec<String>> {
    (
        -1e4f64..1e4,
        proptest::collection::vec((1e-6f64..10.0, 0u8..4), n),
    )
        .prop_map(|(t0, steps)| {
            let mut t = t0;
            steps
                .into_iter()
                .map(|(d, style)| {
                    let s = match style {
                        0 => format!("{t}"),
                        1 => format!("{t:e}"),
                        2 if t >= 0.0 => format!("+{t}"),
                        _ => format!("{t:?}"),
                    };
                    t += d;
                    s
                })
                .collect()
        })
}

fn stream(header: &[&str], t: &[String], cells: &[String]) -> String {
    let w = header.len() - 1;
    let mut s = header.join(",") + "\n";
    for (i, t) in t.iter().enumerate() {
        s += t;
        for c in &cells[i * w..(i + 1) * w] {
            s += ",";
            s += c;
        }
        s += "\n";
    }
    s
}

/// One cell of a CSV text quoted (the fast path gives up on quotes).
fn quote_one(text: &str, pick: Index) -> String {
    let b = text.as_bytes();
    // Data cells only: the header stays as it is.
    let header_end = text.find('\n').unwrap() + 1;
    let spans: Vec<(usize, usize)> = cells(b)
        .into_iter()
        .filter(|&(s, e)| s >= header_end && e > s)
        .collect();
    let (s, e) = spans[pick.index(spans.len())];
    format!("{}\"{}\"{}", &text[..s], &text[s..e], &text[e..])
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

fn same_streams(a: &Recording, b: &Recording) -> bool {
    let cols = |r: &Recording| {
        let mut cols = vec![bits(&r.imu.t)];
        cols.extend(r.imu.accel.iter().chain(&r.imu.gyro).map(|c| bits(c)));
        cols.extend([
            bits(r.imu.temp.as_deref().unwrap_or(&[])),
            bits(&r.table.t),
            bits(&r.table.outer),
            bits(&r.table.inner),
            bits(&r.table.outer_rate),
            bits(&r.table.inner_rate),
            bits(r.table.ambient.as_deref().unwrap_or(&[])),
        ]);
        cols
    };
    cols(a) == cols(b)
}

fn manifest_covering(t0: &str, t1: &str) -> String {
    format!(
        "format: ratecal-recording/1\nstation:\n  site: {{ latitude_deg: 40, gravity_mps2: 9.8 }}\n  table: {{ outer_axis: [0, -1, 0], inner_axis: [1, 0, 0] }}\nsegments:\n  - {{ id: all, kind: static, t_start: {t0}, t_end: {t1} }}\n"
    )
}

/// A valid recording of odd but legal content: a few samples, constant or huge values,
/// a table that never moves, segments holding one sample.
fn odd_valid() -> impl Strategy<Value = [Vec<u8>; 3]> {
    let value = prop_oneof![
        Just(0.0f64),
        Just(1e300),
        Just(-1e300),
        Just(1e-300),
        Just(9.81),
        -1e3f64..1e3,
    ];
    let column = (value.clone(), 0u8..3, any::<u64>());
    (
        2usize..30,
        2usize..15,
        prop_oneof![Just(1e-9f64), Just(0.01), Just(1.0), 1e-4f64..10.0],
        proptest::collection::vec(column, 13),
        proptest::collection::vec((0u8..3, any::<Index>(), 0usize..3, -1e3f64..1e3), 0..5),
        any::<bool>(),
    )
        .prop_map(|(n_imu, n_tab, dt, cols, segs, temp)| {
            let t_imu: Vec<f64> = (0..n_imu).map(|i| i as f64 * dt).collect();
            let t_tab: Vec<f64> = (0..n_tab)
                .map(|i| i as f64 * dt * (n_imu - 1) as f64 / (n_tab - 1) as f64)
                .collect();
            // A column is constant, alternating or ragged.
            let cell = |c: &(f64, u8, u64), i: usize| match c.1 {
                0 => c.0,
                1 => c.0 * if i.is_multiple_of(2) { 1.0 } else { -1.0 },
                _ => c.0 + ((c.2.wrapping_mul(i as u64 + 1) >> 40) as f64) * 1e-3,
            };
            let mut imu = String::from("t,ax,ay,az,gx,gy,gz");
            imu += if temp { ",temp\n" } else { "\n" };
            for (i, t) in t_imu.iter().enumerate() {
                imu += &format!("{t:?}");
                for c in &cols[..if temp { 7 } else { 6 }] {
                    imu += &format!(",{:?}", cell(c, i));
                }
                imu += "\n";
            }
            let mut table = String::from("t,outer,inner,outer_rate,inner_rate\n");
            for (i, t) in t_tab.iter().enumerate() {
                table += &format!("{t:?}");
                for c in &cols[7..11] {
                    table += &format!(",{:?}", cell(c, i));
                }
                table += "\n";
            }
            let mut m = MANIFEST[..MANIFEST.find("  mount:").unwrap()].to_string() + "segments:\n";
            if segs.is_empty() {
                m += "  []\n";
            }
            let half = dt * 0.25;
            for (k, (kind, at, len, rate)) in segs.iter().enumerate() {
                let a = at.index(n_imu);
                let b = (a + len).min(n_imu - 1);
                let (t0, t1) = (t_imu[a] - half, t_imu[b] + half);
                let (t0, t1) = (t0.max(t_imu[0]), t1.min(t_imu[n_imu - 1]));
                let t1 = if t1 > t0 { t1 } else { t0 + half };
                let (t0, t1) = (format!("{t0:?}"), format!("{t1:?}"));
                let times = format!("t_start: {t0}, t_end: {t1}");
                m += &match kind {
                    0 => format!("  - {{ id: s{k}, kind: static, {times} }}\n"),
                    1 => format!(
                        "  - {{ id: r{k}, kind: rate, axis: outer, rate_dps: {rate:?}, {times} }}\n"
                    ),
                    _ => format!(
                        "  - {{ id: o{k}, kind: oscillation, axis: inner, amplitude_deg: {rate:?}, \
                         period_s: {:?}, center_deg: 0, {times} }}\n",
                        rate.abs()
                    ),
                };
            }
            [m.into_bytes(), imu.into_bytes(), table.into_bytes()]
        })
}

proptest! {
    // 256 cases; PROPTEST_CASES=N runs longer (proptest's default reads it).
    #![proptest_config(ProptestConfig {
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn random_bytes_never_panic(
        m in proptest::collection::vec(any::<u8>(), 0..200),
        i in proptest::collection::vec(any::<u8>(), 0..200),
        t in proptest::collection::vec(any::<u8>(), 0..200),
        keep_manifest in any::<bool>(),
    ) {
        let v = valid();
        let m = if keep_manifest { &v[0][..] } else { &m[..] };
        check(&[Some(m), Some(&i), Some(&t)]);
    }

    #[test]
    fn mutated_recordings_read_or_are_located(
        muts in proptest::collection::vec((0usize..3, mutation()), 1..5),
    ) {
        let mut files = valid();
        for (f, m) in &muts {
            apply(&mut files[*f], m);
        }
        check(&[Some(&files[0]), Some(&files[1]), Some(&files[2])]);
    }

    #[test]
    fn segment_times_anywhere(
        picks in proptest::collection::vec((any::<Index>(), 0..YAML_NUMBERS.len()), 1..4),
        swap in any::<bool>(),
    ) {
        let mut m = MANIFEST.to_string();
        if swap {
            m = m.replace("t_start: 0.3, t_end: 0.5", "t_start: 0.5, t_end: 0.3");
        }
        let mut b = m.into_bytes();
        for (at, tok) in &picks {
            // Only the segment block's numbers.
            let from = MANIFEST.find("segments:").unwrap();
            let spans: Vec<_> = yaml_numbers(&b).into_iter().filter(|s| s.0 > from).collect();
            let (s, e) = spans[at.index(spans.len())];
            b.splice(s..e, YAML_NUMBERS[*tok].bytes());
        }
        let v = valid();
        check(&[Some(&b), Some(&v[1]), Some(&v[2])]);
    }

    /// Valid numeric content reads the same through the fast path and, with one cell
    /// quoted, through the exact csv path.
    #[test]
    fn fast_and_exact_paths_agree(
        n in 2usize..12,
        t_imu in times(12),
        t_tab in times(12),
        imu_cells in proptest::collection::vec(number_text(), 7 * 12),
        tab_cells in proptest::collection::vec(number_text(), 5 * 12),
        pick_imu in any::<Index>(),
        pick_tab in any::<Index>(),
        crlf in any::<bool>(),
    ) {
        let imu = stream(&["t", "ax", "ay", "az", "gx", "gy", "gz", "temp"], &t_imu[..n], &imu_cells);
        let table = stream(&["t", "outer", "inner", "outer_rate", "inner_rate", "ambient"], &t_tab[..n], &tab_cells);
        // No segments: the property is about the streams.
        let m = manifest_covering("0", "1");
        let m = &m[..m.find("segments:").unwrap()];
        let plain = check(&[Some(m.as_bytes()), Some(imu.as_bytes()), Some(table.as_bytes())]);
        let mut qi = quote_one(&imu, pick_imu);
        let mut qt = quote_one(&table, pick_tab);
        if crlf {
            qi = qi.replace('\n', "\r\n");
            qt = qt.replace('\n', "\r\n");
        }
        let quoted = check(&[Some(m.as_bytes()), Some(qi.as_bytes()), Some(qt.as_bytes())]);
        // Two clocks with no time in common are refused (`sanity::clocks_overlap`) on
        // either path.
        let span = |t: &[String]| {
            let v = |s: &String| s.trim_start_matches('+').parse::<f64>().unwrap();
            (v(&t[0]), v(&t[n - 1]))
        };
        let (i, b) = (span(&t_imu), span(&t_tab));
        if i.0.max(b.0) >= i.1.min(b.1) {
            prop_assert!(plain.is_none() && quoted.is_none(), "{imu}\n{table}");
            return Ok(());
        }
        match (plain, quoted) {
            (Some(a), Some(b)) => prop_assert!(same_streams(&a, &b), "{imu}\n{table}"),
            (a, b) => prop_assert!(
                false,
                "valid streams refused (plain read: {}, quoted read: {}):\n{imu}\n{table}",
                a.is_some(),
                b.is_some()
            ),
        }
    }

    #[test]
    fn odd_valid_recordings_are_analysed(files in odd_valid()) {
        let rec = check(&[Some(&files[0]), Some(&files[1]), Some(&files[2])]);
        prop_assert!(
            rec.is_some(),
            "refused:\n{}",
            files.iter().map(|f| String::from_utf8_lossy(f)).collect::<Vec<_>>().join("\n")
        );
    }
}

#[test]
fn the_base_recording_reads_and_analyses() {
    let v = valid();
    let rec = check(&[Some(&v[0]), Some(&v[1]), Some(&v[2])]).expect("valid recording");
    assert_eq!(rec.imu.t.len(), 16);
    assert_eq!(rec.manifest.segments.len(), 3);
}

#[test]
fn a_missing_file_is_an_io_error() {
    let v = valid();
    for k in 0..3 {
        let mut files = [Some(&v[0][..]), Some(&v[1][..]), Some(&v[2][..])];
        files[k] = None;
        assert!(check(&files).is_none());
    }
}

#[test]
fn helpers_find_cells_and_numbers() {
    let b = b"t,a\n1.5,-2\n";
    let c: Vec<&[u8]> = cells(b).iter().map(|&(s, e)| &b[s..e]).collect();
    assert_eq!(c, [&b"t"[..], b"a", b"1.5", b"-2"]);
    let y = b"site: { latitude_deg: 55.7, g: -9.8 }\n  - [0, -1, 1e-3]";
    let n: Vec<&[u8]> = yaml_numbers(y).iter().map(|&(s, e)| &y[s..e]).collect();
    assert_eq!(n, [&b"55.7"[..], b"-9.8", b"0", b"-1", b"1e-3"]);
    assert!(names_line_and_column("  ╭─[/x/imu.csv:3:7]", "/x/imu.csv"));
    assert!(!names_line_and_column(
        "/x/imu.csv: no samples",
        "/x/imu.csv"
    ));
}

// Regressions: inputs the properties above found, as plain tests.

fn read_files(
    manifest: &str,
    imu: &[u8],
    table: &str,
) -> (tempfile::TempDir, Result<Recording, RecordingError>) {
    let tmp = tempfile::tempdir().unwrap();
    for (name, b) in FILES
        .iter()
        .zip([manifest.as_bytes(), imu, table.as_bytes()])
    {
        std::fs::write(tmp.path().join(name), b).unwrap();
    }
    let r = recording::read(tmp.path());
    (tmp, r)
}

/// A cell of more than 19 digits overflowed the fast converter's mantissa (a panic in
/// debug builds); the exact fallback converts it.
#[test]
fn a_cell_of_many_digits_reads() {
    // 2^64: the nineteenth digit's mantissa times ten plus 6 overflows.
    let imu = imu_text().replacen(",-0.02,", ",-18446744073709551616,", 1);
    let (_tmp, r) = read_files(MANIFEST, imu.as_bytes(), &table_text());
    assert_eq!(r.unwrap().imu.accel[1][0], -18446744073709551616.0);
}

/// In a CRLF file the exact reader named the line before the bad cell.
#[test]
fn errors_in_crlf_files_name_their_line() {
    let imu = imu_text()
        .replacen("0.05,0.01,", "0.05,x0.01,", 1)
        .replace('\n', "\r\n");
    let (tmp, r) = read_files(MANIFEST, imu.as_bytes(), &table_text());
    let shown = render(&r.unwrap_err());
    let at = format!("{}:3:6", tmp.path().join("imu.csv").display());
    assert!(shown.contains(&format!("{at}: `x0.01`")), "{shown}");
    assert!(shown.contains(&format!("[{at}]")), "{shown}");

    // A time step back, and a bare CR ending a line (a record end for the csv crate).
    let table = table_text()
        .replace('\n', "\r\n")
        .replacen("\r\n0.3,", "\r0.3,", 1)
        .replacen("0.5,5.00", "0.2,5.00", 1);
    let (tmp, r) = read_files(MANIFEST, imu_text().as_bytes(), &table);
    let shown = render(&r.unwrap_err());
    let at = format!("{}:7:1", tmp.path().join("table.csv").display());
    assert!(
        shown.contains(&format!("{at}: time goes backwards")),
        "{shown}"
    );
    assert!(shown.contains(&format!("[{at}]")), "{shown}");
}

/// A stream of one sample was refused naming no line.
#[test]
fn a_stream_of_one_sample_is_located() {
    let table: String = table_text()
        .lines()
        .take(2)
        .map(|l| format!("{l}\n"))
        .collect();
    let (tmp, r) = read_files(MANIFEST, imu_text().as_bytes(), &table);
    let shown = render(&r.unwrap_err());
    let at = format!("{}:2:20", tmp.path().join("table.csv").display());
    assert!(shown.contains(&format!("{at}: no samples")), "{shown}");
    let (tmp, r) = read_files(MANIFEST, imu_text().as_bytes(), "");
    let shown = render(&r.unwrap_err());
    let at = format!("{}:1:1", tmp.path().join("table.csv").display());
    assert!(shown.contains(&format!("{at}: no samples")), "{shown}");
}

/// At a YAML scanner error the parser gives no byte offset: the snippet showed line 1.
#[test]
fn manifest_syntax_errors_show_their_line() {
    let m = MANIFEST.replacen("imu: {", "  - id: c\nimu: {", 1);
    let (tmp, r) = read_files(&m, imu_text().as_bytes(), &table_text());
    let shown = render(&r.unwrap_err());
    let at = format!("{}:7:", tmp.path().join("manifest.yaml").display());
    assert!(shown.contains(&format!("[{at}")), "{shown}");
}

/// A segment may end half a feedback step after the table stream; its samples past the
/// last feedback sample indexed past the table (a panic in the analysis).
#[test]
fn a_segment_past_the_last_feedback_sample_is_analysed() {
    let m = MANIFEST[..MANIFEST.find("segments:").unwrap()].to_string()
        + "segments:\n  - { id: end, kind: static, t_start: 0.12, t_end: 0.14 }\n";
    let imu = "t,ax,ay,az,gx,gy,gz\n0,0,0,9.8,0,0,0\n0.1,0,0,9.8,0,0,0\n0.14,0,0,9.8,0,0,0\n";
    let table = "t,outer,inner,outer_rate,inner_rate\n0,0,0,0,0\n0.1,0,0,0,0\n";
    let (_tmp, r) = read_files(&m, imu.as_bytes(), table);
    let rec = r.expect("the segment is within half a step of the table stream");
    let _ = ratecal_analysis::fit::analyze(&rec, None);
}

/// CR CR LF line endings (found by the property above): the message and the snippet name
/// the same line, and the column of the bad cell.
#[test]
fn cr_cr_lf_rows_are_located_on_their_line() {
    let [manifest, imu, table] = valid();
    let text = String::from_utf8(imu).unwrap();
    let mut rows: Vec<String> = text.lines().map(String::from).collect();
    let mut cells: Vec<&str> = rows[10].split(',').collect();
    cells[3] = "0x10";
    rows[10] = cells.join(",");
    let imu = rows.join("\r\r\n").into_bytes();
    assert!(check(&[Some(&manifest), Some(&imu), Some(&table)]).is_none());
    let tmp = tempfile::tempdir().unwrap();
    for (name, bytes) in FILES.iter().zip([&manifest, &imu, &table]) {
        std::fs::write(tmp.path().join(name), bytes).unwrap();
    }
    let e = recording::read(tmp.path()).unwrap_err();
    // Ten CR CR LF endings before the row: each a lone CR and a CRLF, twenty breaks.
    let shown = render(&e);
    assert!(shown.contains("imu.csv:21:17"), "{shown}");
}
