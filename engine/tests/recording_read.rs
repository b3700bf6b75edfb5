//! Reading recordings: the independent example folder, and located errors for bad ones.

use miette::{GraphicalReportHandler, GraphicalTheme};
use ratecal_engine::recording::{self, RecordingError, SegmentKind};
use std::path::{Path, PathBuf};

fn shared() -> Option<PathBuf> {
    // ../shared next to the repository (CI), or one level up (a worktree under wt/).
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let found = ["../../shared", "../../../shared"]
        .iter()
        .map(|r| root.join(r).join("examples/standard-with-lever-arm"))
        .find(|p| p.exists());
    if found.is_none() {
        println!("skipped: ../shared/examples/standard-with-lever-arm is absent");
    }
    found
}

#[test]
fn reads_the_independent_example_exactly() {
    let Some(dir) = shared() else { return };
    let t0 = std::time::Instant::now();
    let rec = recording::read(&dir).expect("example reads");
    eprintln!("read in {:?}", t0.elapsed());
    assert_eq!(rec.imu.t.len(), 88600);
    assert_eq!(rec.table.t.len(), 44300);
    assert_eq!(rec.imu.t[0], 0.00370);
    assert_eq!(rec.imu.accel[0], [-0.013975, 0.021913, 9.788327]);
    assert_eq!(rec.imu.gyro[0], [-0.0365109, 0.0623964, 0.0283184]);
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
    assert_eq!(rec.imu.gyro[5], [0.1, 0.2, 0.3]);
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
