//! The optional `t_host` column (host arrival times of hardware links): written only when
//! the recording asks for it, so other recordings stay byte for byte what they were, and
//! read like any extra column, by both readers.

use ratecal_recording::{self as recording, Columns, ImuSample, Manifest, RecordingWriter};
use ratecal_recording::{TableSample, parse_manifest};
use std::path::Path;

const MANIFEST: &str = "format: ratecal-recording/1
station:
  site: { latitude_deg: 55.7, gravity_mps2: 9.8156 }
  table: { outer_axis: [0, -1, 0], inner_axis: [1, 0, 0] }
segments:
  - { id: rest, kind: static, t_start: 0.0, t_end: 0.2 }
";

fn manifest() -> Manifest {
    parse_manifest("manifest.yaml", MANIFEST).unwrap()
}

/// `n` samples of each stream at 100 Hz, arriving `delay_s` after their stamp; one table
/// sample (the third) carries no arrival time.
fn samples(n: usize, delay_s: f64) -> (Vec<ImuSample>, Vec<TableSample>) {
    let imu = (0..n)
        .map(|i| {
            let t = i as f64 * 0.01;
            ImuSample {
                t,
                accel: [0.01 * i as f64, -0.02, 9.81],
                gyro: [0.1, 0.2 * i as f64, 0.3],
                temp_c: Some(21.5),
                t_host: Some(t + delay_s),
            }
        })
        .collect();
    let table = (0..n)
        .map(|i| {
            let t = i as f64 * 0.01 + 0.005;
            TableSample {
                t,
                outer_deg: i as f64,
                inner_deg: 0.5,
                outer_rate_dps: 10.0,
                inner_rate_dps: 0.0,
                ambient_c: Some(20.0),
                t_host: (i != 2).then_some(t + delay_s),
            }
        })
        .collect();
    (imu, table)
}

fn write(dir: &Path, columns: Columns, imu: &[ImuSample], table: &[TableSample]) {
    let mut w = RecordingWriter::create(dir, manifest(), columns).unwrap();
    w.write_imu(imu).unwrap();
    w.write_table(table).unwrap();
    w.finish().unwrap();
    assert_eq!(w.close(), 0, "no sample dropped");
}

fn text(dir: &Path, file: &str) -> String {
    std::fs::read_to_string(dir.join(file)).unwrap()
}

const BASE: Columns = Columns {
    imu_temp: true,
    ambient: true,
    imu_t_host: false,
    table_t_host: false,
};

#[test]
fn without_the_column_arrival_times_change_no_byte() {
    let (imu, table) = samples(50, 0.004);
    let strip = |v: &[ImuSample]| v.iter().map(|s| ImuSample { t_host: None, ..*s }).collect();
    let bare_imu: Vec<ImuSample> = strip(&imu);
    let bare_table: Vec<TableSample> = table
        .iter()
        .map(|s| TableSample { t_host: None, ..*s })
        .collect();
    let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    write(a.path(), BASE, &imu, &table);
    write(b.path(), BASE, &bare_imu, &bare_table);
    for f in ["imu.csv", "table.csv"] {
        assert_eq!(text(a.path(), f), text(b.path(), f), "{f}");
    }
    assert!(text(a.path(), "imu.csv").starts_with("t,ax,ay,az,gx,gy,gz,temp\n"));
    assert!(
        text(a.path(), "table.csv").starts_with("t,outer,inner,outer_rate,inner_rate,ambient\n")
    );
}

#[test]
fn the_column_holds_each_samples_arrival_and_reads_like_an_extra_column() {
    let (imu, table) = samples(50, 0.004);
    let (with, without) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let columns = Columns {
        imu_t_host: true,
        table_t_host: true,
        ..BASE
    };
    write(with.path(), columns, &imu, &table);
    write(without.path(), BASE, &imu, &table);

    let imu_csv = text(with.path(), "imu.csv");
    let mut lines = imu_csv.lines();
    assert_eq!(lines.next(), Some("t,ax,ay,az,gx,gy,gz,temp,t_host"));
    for (line, s) in lines.zip(&imu) {
        let cells: Vec<&str> = line.split(',').collect();
        let t_host: f64 = cells[8].parse().unwrap();
        assert!((t_host - s.t_host.unwrap()).abs() < 1e-6, "{line}");
    }
    let table_csv = text(with.path(), "table.csv");
    let rows: Vec<&str> = table_csv.lines().collect();
    assert_eq!(
        rows[0],
        "t,outer,inner,outer_rate,inner_rate,ambient,t_host"
    );
    // A sample without its arrival time: an empty cell, not a made-up number.
    assert!(rows[3].ends_with(','), "{}", rows[3]);
    assert!(rows[4].ends_with(",0.039000"), "{}", rows[4]);

    // Read whole, and stream by stream (as the replay driver reads): the same streams as
    // without the column.
    let a = recording::read(with.path()).unwrap();
    let b = recording::read(without.path()).unwrap();
    assert_eq!(a.imu, b.imu);
    assert_eq!(a.table, b.table);
    assert_eq!(a.imu.t.len(), 50);
    let exact_imu = recording::read_imu(&with.path().join("imu.csv")).unwrap();
    let exact_table = recording::read_table(&with.path().join("table.csv")).unwrap();
    assert_eq!(exact_imu, b.imu);
    assert_eq!(exact_table, b.table);
}

#[test]
fn a_continued_recording_keeps_its_arrival_column() {
    let (imu, table) = samples(40, 0.002);
    let tmp = tempfile::tempdir().unwrap();
    let columns = Columns {
        imu_t_host: true,
        table_t_host: false,
        ..BASE
    };
    let mut w = RecordingWriter::create(tmp.path(), manifest(), columns).unwrap();
    w.write_imu(&imu[..20]).unwrap();
    w.write_table(&table[..20]).unwrap();
    w.finish().unwrap();
    w.close();
    let (mut w, last) = RecordingWriter::append(tmp.path(), false).unwrap();
    assert_eq!(w.columns(), columns);
    assert_eq!(last, Some(table[19].t));
    w.write_imu(&imu[20..]).unwrap();
    w.write_table(&table[20..]).unwrap();
    w.finish().unwrap();
    w.close();
    let imu_csv = text(tmp.path(), "imu.csv");
    assert!(imu_csv.lines().skip(1).all(|l| l.split(',').count() == 9));
    assert_eq!(imu_csv.lines().count(), 41);
}
