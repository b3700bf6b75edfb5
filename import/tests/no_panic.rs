//! User input never panics the importer, and every refusal is located: any text as a map,
//! any bytes as a source under several maps. (The fuzz targets `import_map` and
//! `import_source` in fuzz/ run the same properties for longer.)

use proptest::prelude::*;
use ratecal_import::{ErrorKind, ImportError, import, load_map};

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
  time: { column: 0, unit: ms }
  columns: { ax: 1, ay: 2, az: 3, gx: 4, gy: 5, gz: 6 }
  units: { accel: 0.001 g/count, gyro: 131 count/deg/s }
  zero: { accel: 1000, gyro: [1, 2, 3] }
  axes: [y, -x, z]
segments: { detect: { static_min: 0.1 s, window: 0.05 s } }
site: { latitude_deg: 1, gravity_mps2: 9.8 }
",
    "source: { format: csv, skip_lines: 1, encoding: latin-1 }
imu:
  time: { column: t, unit: s }
  columns: { ax: a, ay: b, az: c, gx: d, gy: e, gz: f }
  units: { accel: m/s^2, gyro: rad/s }
segments:
  - { id: r, kind: rate, time: [0.1, 0.5], axis: -y, rate_dps: 10 }
site: { latitude_deg: 1, gravity_mps2: 9.8 }
",
];

fn rendered(e: &ImportError) -> String {
    let mut out = String::new();
    miette::GraphicalReportHandler::new_themed(miette::GraphicalTheme::unicode_nocolor())
        .render_report(&mut out, e)
        .expect("renders");
    out
}

/// Located: a map or cell error names its file, line and column; every error has a help.
fn located(e: &ImportError, file: &str) {
    assert!(!e.help.is_empty(), "{e:?}");
    assert!(e.message.starts_with(&e.file), "{e:?}");
    if matches!(e.kind, ErrorKind::Map) {
        assert_eq!(e.file, file);
    }
    if e.line.is_some() {
        assert!(e.column.is_some() && e.span.is_some(), "{e:?}");
    } else {
        // Whole-file problems (too short, ragged sources) name the file.
        assert!(
            matches!(e.kind, ErrorKind::Cell | ErrorKind::Io | ErrorKind::Format),
            "{e:?}"
        );
    }
    let _ = rendered(e);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn any_map_text_loads_or_is_refused_located(text in "\\PC{0,300}") {
        if let Err(e) = load_map(&text, "fuzz.yaml") {
            prop_assert!(e.line.is_some() && e.column.is_some(), "{e:?}");
            located(&e, "fuzz.yaml");
        }
    }

    #[test]
    fn a_mutated_map_loads_or_is_refused_located(
        which in 0usize..3, at in 0usize..600, junk in "[-:{}\\[\\], a-z0-9.#\"'\\n]{0,12}"
    ) {
        let base = MAPS[which];
        let mut at = at.min(base.len());
        while !base.is_char_boundary(at) {
            at -= 1;
        }
        let text = format!("{}{}{}", &base[..at], junk, &base[at..]);
        if let Err(e) = load_map(&text, "fuzz.yaml") {
            located(&e, "fuzz.yaml");
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

    #[test]
    fn any_source_bytes_import_or_are_refused_located(
        which in 0usize..3,
        body in proptest::collection::vec(
            prop_oneof![
                Just(b"a,b,c,d,e,f,t\n".to_vec()),
                Just(b"0,0,1,0,0,0,0.1\n".to_vec()),
                Just(b" 1 2 3000 4 5 6 7\r\n".to_vec()),
                Just(b"0.01,0.02,0.98,1e-3,NaN,0,0.2\n".to_vec()),
                proptest::collection::vec(any::<u8>(), 0..12),
            ],
            0..12,
        ),
    ) {
        let map = load_map(MAPS[which], "map.yaml").expect("the base maps load");
        let dir = tempfile::tempdir().unwrap();
        let src = dir.path().join("src.csv");
        std::fs::write(&src, body.concat()).unwrap();
        match import(std::slice::from_ref(&src), &map, &dir.path().join("run")) {
            Ok(s) => {
                let rec = ratecal_recording::read(&s.out).expect("an import reads back");
                prop_assert_eq!(rec.imu.t.len() as u64, s.samples);
            }
            Err(e) => {
                located(&e, "map.yaml");
                prop_assert!(!dir.path().join("run").exists(), "nothing written");
            }
        }
    }
}

/// The MATLAB fixtures (written by scipy.io.savemat), compressed and not.
fn mat_fixture(which: usize) -> Vec<u8> {
    let name = ["mpu6050_single_v6.mat", "mpu6050_int16.mat"][which];
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/fixtures/import_mat")
        .join(name);
    std::fs::read(p).unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn a_damaged_mat_file_reads_or_is_refused_naming_it(
        which in 0usize..2,
        cut in 0usize..100_000,
        edits in proptest::collection::vec((0usize..600, any::<u8>()), 0..6),
    ) {
        let mut bytes = mat_fixture(which);
        for (at, b) in edits {
            if let Some(x) = bytes.get_mut(at) {
                *x = b;
            }
        }
        bytes.truncate(cut.max(1));
        match ratecal_import::read_mat(&bytes, "src.mat", "cal_data") {
            Ok(m) => prop_assert_eq!(m.data.len(), m.rows * m.cols),
            Err(e) => prop_assert!(
                !e.help.is_empty() && e.message.starts_with("src.mat: "),
                "{:?}", e
            ),
        }
    }
}
