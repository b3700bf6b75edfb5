//! Any bytes as a source file under three maps (a header CSV with declared segments, a
//! header-less whitespace file in counts with detection, a time column): an imported
//! recording that reads back, or a diagnostic naming its file (and, for a cell, the line
//! and column) with a help line, and nothing written; never a panic.
//! Run with `cargo fuzz run -s none import_source`.
#![no_main]

use libfuzzer_sys::fuzz_target;
use ratecal_import::{ErrorKind, import, load_map};

const MAPS: [&str; 3] = [
    "source: { format: csv }
imu:
  time: { rate_hz: 10 }
  columns: { ax: a, ay: b, az: c, gx: d, gy: e, gz: f }
  units: { accel: g, gyro: deg/s }
segments:
  - { id: s, kind: static, samples: [1, 4], up: +z }
site: { latitude_deg: 1, gravity_mps2: 9.8 }
",
    "source: { format: csv, header: none, delimiter: whitespace }
imu:
  time: { rate_hz: 100 }
  columns: { ax: 0, ay: 1, az: 2, gx: 3, gy: 4, gz: 5 }
  units: { accel: 0.001 g/count, gyro: 131 count/deg/s }
  zero: { accel: 1000, gyro: 0 }
segments: { detect: { static_min: 0.02 s, window: 0.01 s } }
site: { latitude_deg: 1, gravity_mps2: 9.8 }
",
    "source: { format: csv, skip_lines: 1, encoding: latin-1 }
imu:
  time: { column: t, unit: ms }
  columns: { ax: a, ay: b, az: c, gx: d, gy: e, gz: f }
  units: { accel: m/s^2, gyro: rad/s }
site: { latitude_deg: 1, gravity_mps2: 9.8 }
",
];

fuzz_target!(|data: &[u8]| {
    let Some((&which, body)) = data.split_first() else {
        return;
    };
    let map = load_map(MAPS[which as usize % 3], "map.yaml").expect("the maps load");
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("src.csv");
    std::fs::write(&src, body).unwrap();
    let out = dir.path().join("run");
    match import(std::slice::from_ref(&src), &map, &out) {
        Ok(s) => {
            let rec = ratecal_recording::read(&s.out).expect("an import reads back");
            assert_eq!(rec.imu.t.len() as u64, s.samples);
        }
        Err(e) => {
            assert!(!e.help.is_empty() && e.message.starts_with(&e.file), "{e:?}");
            if e.kind == ErrorKind::Cell && e.line.is_some() {
                assert!(e.column.is_some() && e.span.is_some(), "{e:?}");
            }
            assert!(!out.exists(), "nothing written on refusal");
        }
    }
});
