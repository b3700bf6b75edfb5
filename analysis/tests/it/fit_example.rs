//! The analysis on the independent example recording, against its truth.json.

use crate::shared;
use ratecal_analysis::fit;
use ratecal_recording as recording;

#[test]
fn example_matches_truth_where_the_standard_model_applies() {
    let Some(dir) = shared::shared_example("standard-with-lever-arm") else {
        return;
    };
    let rec = recording::read(&dir).unwrap();
    let t0 = std::time::Instant::now();
    let res = fit::analyze(&rec, None);
    eprintln!("analysed in {:?}", t0.elapsed());
    let truth: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("truth.json")).unwrap()).unwrap();
    let nominal = &truth["nominal"];
    let mut report = Vec::new();
    let check = |name: &str, want: f64, k: f64, report: &mut Vec<String>| {
        let (v, u) = res.value(name).unwrap_or_else(|| panic!("{name} missing"));
        let z = (v - want) / u;
        report.push(format!(
            "{name}: {v:.6} +- {u:.2e} (truth {want}) z = {z:.2}"
        ));
        assert!(z.abs() <= k, "{name}: {v} +- {u}, truth {want}, z = {z}");
    };
    for (i, ax) in ["x", "y", "z"].iter().enumerate() {
        check(
            &format!("accel.bias.{ax}"),
            nominal["accel_bias"][i].as_f64().unwrap(),
            3.0,
            &mut report,
        );
        check(
            &format!("accel.scale.{ax}"),
            nominal["accel_scale_ppm"][i].as_f64().unwrap(),
            3.0,
            &mut report,
        );
        check(
            &format!("gyro.bias.{ax}"),
            nominal["gyro_bias_dps"][i].as_f64().unwrap(),
            3.0,
            &mut report,
        );
    }
    for (i, ax) in ["x", "y"].iter().enumerate() {
        check(
            &format!("gyro.scale.{ax}"),
            nominal["gyro_scale_ppm"][i].as_f64().unwrap(),
            3.0,
            &mut report,
        );
    }
    eprintln!("{}", report.join("\n"));
    // The standard turns the IMU about X and Y only: Z's scale needs a rotation about Z.
    assert_eq!(
        res.parameters["gyro.scale.z"],
        ratecal_analysis::results::Parameter::needs("rotate about Z")
    );
}
