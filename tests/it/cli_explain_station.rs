//! A station-side error found by explain: the table's encoders are eccentric
//! (`drivers/stations/eccentric-table.yaml`), the IMU is clean. Explain names
//! `table_encoder_eccentricity` with the station's values, marks it as the table's error,
//! and credits nothing to the IMU.

use crate::support;
use std::path::Path;
use support::{code, ratecal, text};

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

#[test]
fn an_eccentric_encoder_is_reported_as_a_station_error() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let station = Path::new(ROOT).join("drivers/stations/eccentric-table.yaml");
    let procedure = Path::new(ROOT).join("procedures/imu-2d-standard");
    let o = ratecal(
        &[
            "run",
            procedure.to_str().unwrap(),
            "--dry-run",
            "--station",
            station.to_str().unwrap(),
            "--out",
            "ecc",
        ],
        dir,
    );
    assert!(matches!(code(&o), 0 | 3), "{}", text(&o));
    let o = ratecal(&["explain", "ecc", "--format", "json"], dir);
    assert_eq!(code(&o), 1, "{}", text(&o));
    let x: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let ids: Vec<&str> = x["findings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["effect"].as_str().unwrap())
        .collect();
    assert_eq!(ids, ["earth_rate", "table_encoder_eccentricity"], "{x}");
    let f = &x["findings"][1];
    assert_eq!(f["station_side"], true);
    // The station file's components, arcsec.
    for (p, truth) in [
        ("outer_sin_arcsec", 60.0),
        ("outer_cos_arcsec", -40.0),
        ("inner_sin_arcsec", 30.0),
        ("inner_cos_arcsec", 50.0),
    ] {
        let v = f["parameters"][p]["value"].as_f64().unwrap();
        let u = f["parameters"][p]["u"].as_f64().unwrap();
        assert!((v - truth).abs() < (3.0 * u).max(0.5), "{p} = {v} ± {u}");
    }
    assert!(x["unexplained"].as_array().unwrap().is_empty(), "{x}");
    let o = ratecal(&["explain", "ecc"], dir);
    assert!(text(&o).contains("(a station error: the table, not the IMU)"));
}
