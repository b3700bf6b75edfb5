//! Reading recordings: the independent example folder, and located errors for bad ones.

use crate::shared;
use miette::{GraphicalReportHandler, GraphicalTheme};
use ratecal_recording::{self as recording, RecordingError, SegmentKind};
use std::path::Path;

#[test]
fn reads_the_independent_example_exactly() {
    let Some(dir) = shared::shared_example("standard-with-lever-arm") else {
        return;
    };
    let t0 = std::time::Instant::now();
    let rec = recording::read(&dir).expect("example reads");
    eprintln!("read in {:?}", t0.elapsed());
    assert_eq!(rec.imu.t.len(), 88600);
    assert_eq!(rec.table.t.len(), 44300);
    assert_eq!(rec.imu.t[0], 0.00370);
    let row = |c: &[Vec<f64>; 3], i: usize| [c[0][i], c[1][i], c[2][i]];
    assert_eq!(row(&rec.imu.accel, 0), [-0.013975, 0.021913, 9.788327]);
    assert_eq!(row(&rec.imu.gyro, 0), [-0.0365109, 0.0623964, 0.0283184]);
    assert_eq!(rec.imu.temp.as_ref().unwrap()[1], 21.979);
    assert_eq!(rec.table.outer_rate[2], 0.00268);
    assert!(rec.table.ambient.is_none());
    let m = &rec.manifest;
    assert_eq!(m.station.site.latitude_deg, 40.0);
    assert_eq!(m.station.site.gravity_mps2, 9.80180);
    assert_eq!(m.station.table.outer_axis, [0.0, -1.0, 0.0]);
    assert_eq!(m.segments.len(), 17);
    assert_eq!(m.segments[6].id, "gyro_bias");
    assert_eq!(m.segments[7].kind, SegmentKind::Rate);
    assert_eq!(m.segments[7].rate_dps, Some(-100.0));
    assert_eq!(m.segments[7].axis.as_deref(), Some("outer"));
    assert!(m.procedure.is_none() && m.environment.is_none());
}

const MANIFEST: &str = "format: ratecal-recording/1
station:
  site: { latitude_deg: 55.7, gravity_mps2: 9.8156 }
  table: { outer_axis: [0, -1, 0], inner_axis: [1, 0, 0] }
segments:
  - { id: a, kind: static, t_start: 0.0, t_end: 0.25 }
  - { id: b, kind: rate, axis: outer, rate_dps: 10.0, t_start: 0.3, t_end: 0.5 }
";

fn small(dir: &Path, manifest: &str, imu: &str, table: &str) {
    std::fs::write(dir.join("manifest.yaml"), manifest).unwrap();
    std::fs::write(dir.join("imu.csv"), imu).unwrap();
    std::fs::write(dir.join("table.csv"), table).unwrap();
}

fn imu_text() -> String {
    let mut s = String::from("t,ax,ay,az,gx,gy,gz,extra\n");
    for i in 0..6 {
        s += &format!("{:.2},0.01,0.02,9.81,0.1,0.2,0.3,x{i}\n", i as f64 * 0.1);
    }
    s
}

fn table_text() -> String {
    let mut s = String::from("t,outer,inner,outer_rate,inner_rate\n");
    for i in 0..6 {
        s += &format!("{:.2},0,0,0,0\n", i as f64 * 0.1);
    }
    s
}

fn render(dir: &Path, e: &RecordingError) -> String {
    let mut out = String::new();
    GraphicalReportHandler::new_themed(GraphicalTheme::unicode_nocolor())
        .with_width(100)
        .render_report(&mut out, e)
        .unwrap();
    out.replace(&dir.display().to_string(), "RUN")
}

fn err(manifest: &str, imu: &str, table: &str) -> String {
    let tmp = tempfile::tempdir().unwrap();
    small(tmp.path(), manifest, imu, table);
    let e = recording::read(tmp.path()).expect_err("must be refused");
    render(tmp.path(), &e)
}

#[test]
fn small_valid_recording_with_extra_column() {
    let tmp = tempfile::tempdir().unwrap();
    small(tmp.path(), MANIFEST, &imu_text(), &table_text());
    let rec = recording::read(tmp.path()).unwrap();
    assert_eq!(rec.imu.t.len(), 6);
    assert_eq!(
        [rec.imu.gyro[0][5], rec.imu.gyro[1][5], rec.imu.gyro[2][5]],
        [0.1, 0.2, 0.3]
    );
}

/// The fast path gives up on quotes, CRLF-free oddities and blank lines are its own; the
/// exact reader must then give the same streams as the fast path gives for plain text.
#[test]
fn quoted_cells_and_blank_lines_read_like_plain_ones() {
    let plain = tempfile::tempdir().unwrap();
    small(plain.path(), MANIFEST, &imu_text(), &table_text());
    let quoted = tempfile::tempdir().unwrap();
    let imu = imu_text()
        .replace(",0.02,", ",\"0.02\",")
        .replace("\n0.30", "\n\n  \r\n0.30");
    let table = table_text().replace("\n", "\r\n");
    small(quoted.path(), MANIFEST, &imu, &table);
    let a = recording::read(plain.path()).unwrap();
    let b = recording::read(quoted.path()).unwrap();
    assert_eq!(a.imu, b.imu);
    assert_eq!(a.table, b.table);
}

/// A file bigger than the reader's buffer, split over its two threads, reads row for row
/// like the text says, and a time step backwards deep inside it is located on its line.
#[test]
fn large_streams_split_across_threads_read_exactly() {
    let tmp = tempfile::tempdir().unwrap();
    let n = 40_000;
    let mut imu = String::from("t,ax,ay,az,gx,gy,gz,temp\n");
    for i in 0..n {
        let t = i as f64 * 0.01;
        imu += &format!(
            "{t:.2},{:.6},-0.5,9.8,{:.7},0,0,22.5\n",
            i as f64 * 1e-6,
            -(i as f64) * 1e-7
        );
    }
    let mut table = String::from("t,outer,inner,outer_rate,inner_rate\n");
    for i in 0..n / 2 {
        table += &format!("{:.2},0,0,0,0\n", i as f64 * 0.02);
    }
    let manifest = MANIFEST.replace("t_end: 0.5", "t_end: 300.0");
    small(tmp.path(), &manifest, &imu, &table);
    let rec = recording::read(tmp.path()).unwrap();
    assert_eq!(rec.imu.t.len(), n);
    for i in [0, 1, n / 2 - 1, n / 2, n / 2 + 1, n - 1] {
        assert_eq!(
            rec.imu.t[i],
            format!("{:.2}", i as f64 * 0.01).parse::<f64>().unwrap()
        );
        assert_eq!(
            rec.imu.accel[0][i],
            format!("{:.6}", i as f64 * 1e-6).parse::<f64>().unwrap()
        );
        assert_eq!(
            rec.imu.gyro[0][i],
            format!("{:.7}", -(i as f64) * 1e-7).parse::<f64>().unwrap()
        );
    }
    assert_eq!(rec.imu.temp.as_ref().unwrap().len(), n);
    assert_eq!(rec.table.t.len(), n / 2);
    // Row 30000 is on line 30002; make its time go back.
    let bad = imu.replacen("\n300.00,", "\n299.00,", 1);
    std::fs::write(tmp.path().join("imu.csv"), bad).unwrap();
    let e = recording::read(tmp.path()).expect_err("time goes back");
    assert!(
        render(tmp.path(), &e).contains("imu.csv:30002:1"),
        "{}",
        render(tmp.path(), &e)
    );
}

#[test]
fn err_missing_column() {
    let imu = imu_text().replace("t,ax,ay,az,gx,gy,gz", "t,ax,ay,az,gx,gyy,gz");
    insta::assert_snapshot!(err(MANIFEST, &imu, &table_text()));
}

#[test]
fn err_non_numeric_cell() {
    let imu = imu_text().replace("0.30,0.01,0.02", "0.30,0.01,O.02");
    insta::assert_snapshot!(err(MANIFEST, &imu, &table_text()));
}

#[test]
fn err_time_backwards() {
    let table = table_text().replace("0.30,0,0", "0.10,0,0");
    insta::assert_snapshot!(err(MANIFEST, &imu_text(), &table));
}

#[test]
fn err_empty_segment() {
    let m = MANIFEST.replace("t_start: 0.3, t_end: 0.5", "t_start: 0.31, t_end: 0.39");
    insta::assert_snapshot!(err(&m, &imu_text(), &table_text()));
}

#[test]
fn err_segment_outside_streams() {
    let m = MANIFEST.replace("t_start: 0.3, t_end: 0.5", "t_start: 0.3, t_end: 7.5");
    insta::assert_snapshot!(err(&m, &imu_text(), &table_text()));
}

#[test]
fn err_bad_manifest_yaml() {
    let m = MANIFEST.replace("gravity_mps2: 9.8156", "gravity_mps2: heavy");
    insta::assert_snapshot!(err(&m, &imu_text(), &table_text()));
}

#[test]
fn err_unknown_format() {
    let m = MANIFEST.replace("ratecal-recording/1", "ratecal-recording/9");
    insta::assert_snapshot!(err(&m, &imu_text(), &table_text()));
}

#[test]
fn err_gravity_not_the_earths() {
    let m = MANIFEST.replace("gravity_mps2: 9.8156", "gravity_mps2: .nan");
    insta::assert_snapshot!(err(&m, &imu_text(), &table_text()));
}

#[test]
fn err_axis_not_a_unit_vector() {
    let m = MANIFEST.replace("inner_axis: [1, 0, 0]", "inner_axis: [1, 0, 1]");
    insta::assert_snapshot!(err(&m, &imu_text(), &table_text()));
}

#[test]
fn err_segment_mount_is_a_reflection() {
    let m = MANIFEST.replace(
        "rate_dps: 10.0,",
        "rate_dps: 10.0, mount: { rotation: [[1, 0, 0], [0, 1, 0], [0, 0, -1]] },",
    );
    insta::assert_snapshot!(err(&m, &imu_text(), &table_text()));
}

#[test]
fn err_segment_rate_not_finite() {
    let m = MANIFEST.replace("rate_dps: 10.0", "rate_dps: .inf");
    insta::assert_snapshot!(err(&m, &imu_text(), &table_text()));
}

/// A spreadsheet program's byte-order mark before the header reads like no mark, on the
/// fast path and on the exact one (a quoted cell).
#[test]
fn a_byte_order_mark_before_the_header_is_no_column() {
    let plain = tempfile::tempdir().unwrap();
    small(plain.path(), MANIFEST, &imu_text(), &table_text());
    let want = recording::read(plain.path()).unwrap();
    for imu in [
        format!("\u{feff}{}", imu_text()),
        format!("\u{feff}{}", imu_text().replace(",0.02,", ",\"0.02\",")),
    ] {
        let tmp = tempfile::tempdir().unwrap();
        small(
            tmp.path(),
            MANIFEST,
            &imu,
            &format!("\u{feff}{}", table_text()),
        );
        let rec = recording::read(tmp.path()).unwrap();
        assert_eq!(rec.imu, want.imu);
        assert_eq!(rec.table, want.table);
    }
}

/// A table stamped on another clock (here 1000 s later) shares no time with the IMU: the
/// sanity check `clocks_overlap` refuses it, located at the table's first stamp, whether
/// the folder is read whole or opened span by span.
#[test]
fn err_clocks_disjoint() {
    let mut table = String::from("t,outer,inner,outer_rate,inner_rate\n");
    for i in 0..6 {
        table += &format!("{:.2},0,0,0,0\n", 1000.0 + i as f64 * 0.1);
    }
    let tmp = tempfile::tempdir().unwrap();
    small(tmp.path(), MANIFEST, &imu_text(), &table);
    let whole = recording::read(tmp.path()).expect_err("must be refused");
    let opened = recording::Recording::open(tmp.path()).expect_err("must be refused");
    assert_eq!(render(tmp.path(), &whole), render(tmp.path(), &opened));
    insta::assert_snapshot!(render(tmp.path(), &whole));
}
