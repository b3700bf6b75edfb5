//! Reading by time span: a span read equals that slice of a whole read, whatever the line
//! ends, and a bad cell in a span is located where a whole read locates it.

use crate::shared;
use miette::{GraphicalReportHandler, GraphicalTheme};
use ratecal_recording::{self as recording, ImuStream, Recording, RecordingError, TableStream};
use std::path::Path;

/// A recording of `n` IMU rows at 100 Hz (a few blocks of the index), the table at 50 Hz
/// with the time column last.
fn synthetic(n: usize) -> [String; 3] {
    let mut imu = String::from("t,ax,ay,az,gx,gy,gz,temp\n");
    for i in 0..n {
        let t = i as f64 * 0.01;
        let w = (i * 7919 % 1000) as f64 * 1e-6;
        imu += &format!("{t:.2},{w:.6},-0.02,9.81,{:.7},0.2,-0.3,22.5\n", -w);
    }
    let mut table = String::from("outer,inner,outer_rate,inner_rate,t\n");
    for i in 0..n / 2 {
        table += &format!("{:.3},0,0,0,{:.2}\n", i as f64 * 1e-3, i as f64 * 0.02);
    }
    let end = (n / 2 - 1) as f64 * 0.02;
    let manifest = format!(
        "format: ratecal-recording/1
station:
  site: {{ latitude_deg: 55.7, gravity_mps2: 9.8156 }}
  table: {{ outer_axis: [0, -1, 0], inner_axis: [1, 0, 0] }}
segments:
  - {{ id: a, kind: static, t_start: 1.0, t_end: 11.0 }}
  - {{ id: b, kind: rate, axis: outer, rate_dps: 10.0, t_start: 50.005, t_end: {end} }}
"
    );
    [manifest, imu, table]
}

fn write(dir: &Path, files: &[String; 3]) {
    for (name, text) in ["manifest.yaml", "imu.csv", "table.csv"].iter().zip(files) {
        std::fs::write(dir.join(name), text).unwrap();
    }
}

/// The example or synthetic files, their CSV line ends rewritten by `ends`.
fn variant(files: &[String; 3], ends: &str) -> tempfile::TempDir {
    let tmp = tempfile::tempdir().unwrap();
    let [m, imu, table] = files;
    write(
        tmp.path(),
        &[
            m.clone(),
            imu.replace('\n', ends),
            table.replace('\n', ends),
        ],
    );
    tmp
}

fn read_files(dir: &Path) -> [String; 3] {
    ["manifest.yaml", "imu.csv", "table.csv"].map(|f| std::fs::read_to_string(dir.join(f)).unwrap())
}

/// The values of the rows with `t0 <= t <= t1`.
fn cut(v: &[f64], t: &[f64], t0: f64, t1: f64) -> Vec<f64> {
    let inside = t.iter().map(|&x| t0 <= x && x <= t1);
    v.iter().zip(inside).filter(|p| p.1).map(|p| *p.0).collect()
}

fn slice_imu(s: &ImuStream, t0: f64, t1: f64) -> ImuStream {
    let c = |v: &[f64]| cut(v, &s.t, t0, t1);
    ImuStream {
        t: c(&s.t),
        accel: s.accel.each_ref().map(|v| c(v)),
        gyro: s.gyro.each_ref().map(|v| c(v)),
        temp: s.temp.as_deref().map(c),
    }
}

fn slice_table(s: &TableStream, t0: f64, t1: f64) -> TableStream {
    let c = |v: &[f64]| cut(v, &s.t, t0, t1);
    TableStream {
        t: c(&s.t),
        outer: c(&s.outer),
        inner: c(&s.inner),
        outer_rate: c(&s.outer_rate),
        inner_rate: c(&s.inner_rate),
        ambient: s.ambient.as_deref().map(c),
    }
}

/// Every segment, spans across the whole recording (block edges among them), spans
/// outside it and an upside-down one.
fn spans(rec: &Recording) -> Vec<(f64, f64)> {
    let (first, last) = (rec.imu.t[0], rec.imu.t[rec.imu.t.len() - 1]);
    let mut v: Vec<_> = rec
        .manifest
        .segments
        .iter()
        .map(|s| (s.t_start, s.t_end))
        .collect();
    let step = (last - first) / 23.0;
    for k in 0..24 {
        let t0 = first + k as f64 * step;
        v.extend([
            (t0, t0 + 0.3 * step),
            (t0 - 1e-9, t0 + 2.1 * step),
            (t0, t0),
        ]);
    }
    let t5 = rec.imu.t[5];
    v.extend([
        (first - 10.0, last + 10.0),
        (t5, t5),
        (last + 1.0, last + 2.0),
        (5.0, 1.0),
    ]);
    v.extend([
        (f64::NEG_INFINITY, first),
        (last, f64::INFINITY),
        (f64::NAN, 1.0),
    ]);
    v
}

fn span_reads_are_slices(dir: &Path) {
    let rec = recording::read(dir).unwrap();
    let open = Recording::open(dir).unwrap();
    assert_eq!(open.manifest(), &rec.manifest);
    for (t0, t1) in spans(&rec) {
        let got = open.read_span(t0, t1).unwrap();
        let (imu, table) = (slice_imu(&rec.imu, t0, t1), slice_table(&rec.table, t0, t1));
        assert!(got.imu == imu, "imu {t0} .. {t1} in {}", dir.display());
        assert!(
            got.table == table,
            "table {t0} .. {t1} in {}",
            dir.display()
        );
    }
}

#[test]
fn spans_of_the_example_are_slices_of_a_whole_read() {
    let Some(dir) = shared::shared_example("standard-with-lever-arm") else {
        return;
    };
    span_reads_are_slices(&dir);
    let files = read_files(&dir);
    for ends in ["\r\n", "\r\r\n"] {
        span_reads_are_slices(variant(&files, ends).path());
    }
}

#[test]
fn spans_are_slices_whatever_the_line_ends() {
    let files = synthetic(40_000);
    for ends in ["\n", "\r\n", "\r\r\n"] {
        span_reads_are_slices(variant(&files, ends).path());
    }
    // A quoted cell: the exact reader indexes the whole file.
    let [m, imu, table] = &files;
    let quoted = imu.replacen("\n200.00,", "\n\"200.00\",", 1);
    let tmp = tempfile::tempdir().unwrap();
    write(tmp.path(), &[m.clone(), quoted, table.clone()]);
    span_reads_are_slices(tmp.path());
}

fn render(e: &RecordingError) -> String {
    let mut out = String::new();
    GraphicalReportHandler::new_themed(GraphicalTheme::unicode_nocolor())
        .with_width(120)
        .render_report(&mut out, e)
        .unwrap();
    out
}

/// One bad cell deep in imu.csv: the span holding it is refused exactly as a whole read
/// refuses the file (message, file:line:column and snippet); spans that read none of its
/// block read.
#[test]
fn a_bad_cell_in_a_span_is_located_as_a_whole_read_locates_it() {
    let [m, imu, table] = synthetic(40_000);
    // Row 30000, line 30002: its `ax` cell becomes `0.0x10.000000`.
    let bad = imu.replacen("\n300.00,", "\n300.00,0.0x1", 1);
    for (ends, at) in [
        ("\n", ":30002:8"),
        ("\r\n", ":30002:8"),
        ("\r\r\n", ":60003:8"),
    ] {
        let good = variant(&[m.clone(), imu.clone(), table.clone()], ends);
        let tmp = variant(&[m.clone(), bad.clone(), table.clone()], ends);
        let whole = render(&recording::read(tmp.path()).unwrap_err());
        let open = Recording::open(tmp.path()).unwrap();
        let span = render(&open.read_span(299.0, 301.0).unwrap_err());
        assert_eq!(span, whole, "{ends:?}");
        let file = tmp.path().join("imu.csv").display().to_string();
        let message = format!("{file}{at}: `0.0x10.000000` in column `ax` is not a number");
        assert!(whole.contains(&message), "{ends:?}: {whole}");
        let good = Recording::open(good.path()).unwrap();
        // Blocks hold about 40 s here: these spans read none of the bad row's.
        for (t0, t1) in [(0.0, 200.0), (360.0, 399.0)] {
            assert_eq!(
                open.read_span(t0, t1).unwrap(),
                good.read_span(t0, t1).unwrap()
            );
        }
    }
}

/// What opening checks, it refuses as a whole read does.
#[test]
fn opening_refuses_what_a_whole_read_refuses() {
    let [m, imu, table] = synthetic(600);
    let cases = [
        [
            m.clone(),
            imu.replacen("\n3.00,", "\n2.00,", 1),
            table.clone(),
        ],
        [m.clone(), imu.replacen("\n3.00,", "\nx,", 1), table.clone()],
        [m.clone(), imu.replace(",gz,", ",gq,"), table.clone()],
        [
            m.clone(),
            imu.clone(),
            table.replacen("\n", "\n0,0,0,0,5\n", 1),
        ],
        [
            m.clone(),
            imu.clone(),
            table.lines().take(2).collect::<Vec<_>>().join("\n"),
        ],
        [
            m.replace("t_start: 1.0", "t_start: -9.0"),
            imu.clone(),
            table.clone(),
        ],
        [
            m.replace("1.0, t_end: 11.0", "1.001, t_end: 1.002"),
            imu.clone(),
            table.clone(),
        ],
        [
            m.replace("format: ratecal-recording/1", "format: x"),
            imu.clone(),
            table.clone(),
        ],
        [
            m.clone(),
            imu.replacen("\n3.00,", "\n\"3.00\",\"", 1),
            table.clone(),
        ],
    ];
    for files in cases {
        let tmp = tempfile::tempdir().unwrap();
        write(tmp.path(), &files);
        let whole = render(&recording::read(tmp.path()).unwrap_err());
        let open = render(&Recording::open(tmp.path()).unwrap_err());
        assert_eq!(open, whole);
    }
    let tmp = tempfile::tempdir().unwrap();
    assert!(matches!(
        Recording::open(tmp.path()),
        Err(RecordingError::Io { .. })
    ));
}

/// A file of several blocks is indexed by two threads, each parsing every other batch of
/// blocks: a bad or backward stamp in either thread's part (rows 100, 30,000 and 39,990 of
/// 40,000; the second thread's begins near row 23,000) is refused as a whole read refuses
/// it, and a sound file opens with every row.
#[test]
fn a_refusal_in_either_thread_of_the_index_is_a_whole_reads() {
    let [m, imu, table] = synthetic(40_000);
    let open = |imu: String| {
        let tmp = tempfile::tempdir().unwrap();
        write(tmp.path(), &[m.clone(), imu, table.clone()]);
        let whole = recording::read(tmp.path()).map_err(|e| render(&e));
        let open = Recording::open(tmp.path()).map_err(|e| render(&e));
        (whole, open)
    };
    let (whole, opened) = open(imu.clone());
    assert_eq!(whole.unwrap().imu.t.len(), 40_000);
    assert_eq!(opened.unwrap().imu_rows(), 40_000);
    for row in ["1.00", "300.00", "399.90"] {
        let before = format!("{:.2}", row.parse::<f64>().unwrap() - 1.0);
        for bad in ["x", before.as_str()] {
            let (whole, opened) = open(imu.replacen(&format!("\n{row},"), &format!("\n{bad},"), 1));
            let (whole, opened) = (whole.unwrap_err(), opened.unwrap_err());
            assert_eq!(opened, whole, "row {row} as {bad}");
        }
    }
}

/// `imu` (a synthetic stream) with a temperature that varies: row i reads
/// 20 + (i mod 1000) / 100.
fn warming(imu: &str) -> String {
    let mut warm = String::from("t,ax,ay,az,gx,gy,gz,temp\n");
    for (i, line) in imu.lines().skip(1).enumerate() {
        let cut = line.rfind(',').unwrap();
        warm += &format!("{},{:.2}\n", &line[..cut], 20.0 + (i % 1000) as f64 / 100.0);
    }
    warm
}

/// The temperature read from the `t` and `temp` cells alone: the mean is the whole read's
/// (over a large enough file that the two halves it is read in both hold rows), every n-th
/// row is the whole read's rows (every line ending); `None` without the column; a bad
/// `temp` cell refused as a whole read refuses it (the exact reader takes over and names it).
#[test]
fn the_temperature_from_its_cells_alone() {
    let [m, imu, table] = synthetic(40_000);
    let warm = warming(&imu);
    for ends in ["\n", "\r\n"] {
        let tmp = variant(&[m.clone(), warm.clone(), table.clone()], ends);
        let whole = recording::read(tmp.path()).unwrap();
        let temps = whole.imu.temp.as_ref().unwrap();
        let want = temps.iter().sum::<f64>() / temps.len() as f64;
        let open = Recording::open(tmp.path()).unwrap();
        let got = open.imu_mean_temp().unwrap().unwrap();
        assert!((got - want).abs() < 1e-9, "{ends:?}: {got} vs {want}");
        for every in [1, 7, 20, 39_999, 40_000, 100_000] {
            let want: Vec<(f64, f64)> = (0..temps.len())
                .step_by(every)
                .map(|i| (whole.imu.t[i], temps[i]))
                .collect();
            let got = open.imu_temp_every(every).unwrap().unwrap();
            assert_eq!(got, want, "{ends:?}, every {every}");
        }
    }
    let no_temp = imu.replace(",temp\n", "\n").replace(",22.5\n", "\n");
    let tmp = variant(&[m.clone(), no_temp, table.clone()], "\n");
    let open = Recording::open(tmp.path()).unwrap();
    assert_eq!(open.imu_mean_temp().unwrap(), None);
    assert_eq!(open.imu_temp_every(10).unwrap(), None);
    let bad = warm.replacen(",20.50\n", ",2O.50\n", 1);
    let tmp = variant(&[m, bad, table], "\n");
    let whole = render(&recording::read(tmp.path()).unwrap_err());
    let open = Recording::open(tmp.path()).unwrap();
    assert_eq!(render(&open.imu_mean_temp().unwrap_err()), whole);
    // Every row kept: the bad cell is read, and named as the whole read names it (the
    // rows between kept ones are passed over unread: the analysis reads them).
    assert_eq!(render(&open.imu_temp_every(1).unwrap_err()), whole);
}
