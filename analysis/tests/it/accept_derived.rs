//! Acceptance checks on calibrated parameters and derived quantities (`abs`, `norm`,
//! `within +-`), evaluated on the independent example recording: each value and
//! uncertainty recomputed here by hand from results.json (GUM law of propagation with the
//! fit's correlations), and the bias vector's length against truth.json.

use crate::shared;
use ratecal_analysis::fit;
use ratecal_analysis::results::{Acceptance, Results, Verdict};
use ratecal_check::{CheckOptions, NoImports, check_text};
use ratecal_recording as recording;

const G: f64 = 9.80665;

const CHECKS: &str = "
  accept norm(accel.bias) <= 50 mg
  accept accel.bias.y within +-20 mg
  accept accel.bias.x within ±1 mg guarded
  accept abs(accel.bias.z) <= 0.5 mg
  accept norm(gyro.bias) <= 1 deg/s
}
";

fn procedure() -> String {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../procedures/imu-2d-standard/1.0.0.rcal"
    );
    let text = std::fs::read_to_string(path).unwrap();
    let end = text.rfind('}').unwrap();
    format!("{}{CHECKS}", &text[..end])
}

/// Value and standard uncertainty (results units) of a parameter.
fn param(res: &Results, name: &str) -> (f64, f64) {
    res.value(name).unwrap_or_else(|| panic!("{name} missing"))
}

/// The correlation of two parameters in the fit that gave both.
fn corr(res: &Results, a: &str, b: &str) -> f64 {
    for f in res.fits.values() {
        let i = f.parameters.iter().position(|p| p == a);
        let j = f.parameters.iter().position(|p| p == b);
        if let (Some(i), Some(j)) = (i, j) {
            return f.correlation[i][j];
        }
    }
    0.0
}

/// |v| and its standard uncertainty, by hand: u^2 = sum_ij (v_i/|v|)(v_j/|v|) u_i u_j r_ij.
fn norm_by_hand(res: &Results, names: &[String]) -> (f64, f64) {
    let vu: Vec<(f64, f64)> = names.iter().map(|n| param(res, n)).collect();
    let len = vu.iter().map(|(v, _)| v * v).sum::<f64>().sqrt();
    let mut var = 0.0;
    for (i, a) in names.iter().enumerate() {
        for (j, b) in names.iter().enumerate() {
            let r = if i == j { 1.0 } else { corr(res, a, b) };
            var += vu[i].0 / len * vu[j].0 / len * vu[i].1 * vu[j].1 * r;
        }
    }
    (len, var.sqrt())
}

fn by<'a>(res: &'a Results, start: &str) -> &'a Acceptance {
    res.acceptance
        .iter()
        .find(|a| a.name.starts_with(start))
        .unwrap_or_else(|| panic!("{start}: {:#?}", res.acceptance))
}

#[test]
fn derived_checks_on_the_independent_example() {
    let Some(dir) = shared::shared_example("standard-with-lever-arm") else {
        return;
    };
    let checked = check_text("p.rcal", &procedure(), &NoImports, &CheckOptions::default())
        .unwrap_or_else(|d| panic!("{:?}", d.iter().map(|d| d.render()).collect::<Vec<_>>()));
    let rec = recording::read(&dir).unwrap();
    let res = fit::analyze(&rec, Some(&checked.plan));
    let truth: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("truth.json")).unwrap()).unwrap();
    let tb: Vec<f64> = (0..3)
        .map(|i| truth["nominal"]["accel_bias"][i].as_f64().unwrap())
        .collect();

    // norm(accel.bias): in mg, with u through the accelerometer fit's correlations.
    assert_eq!(res.parameters["accel.bias.x"].unit(), Some("m/s^2"));
    let names: Vec<String> = ["x", "y", "z"]
        .iter()
        .map(|a| format!("accel.bias.{a}"))
        .collect();
    let (len, u) = norm_by_hand(&res, &names);
    let a = by(&res, "norm(accel.bias) <= 50 mg");
    assert_eq!(a.unit, "mg");
    let v = a.value.unwrap();
    assert!((v - len / G * 1e3).abs() < 1e-9, "{v} vs {}", len / G * 1e3);
    assert!((a.expanded_u.unwrap() - 2.0 * u / G * 1e3).abs() < 1e-9);
    assert_eq!(a.verdict, Verdict::Pass);
    // The truth's bias length (about 3.5 mg) lies within 3 standard uncertainties.
    let truth_len = tb.iter().map(|b| b * b).sum::<f64>().sqrt();
    assert!(
        (len - truth_len).abs() <= 3.0 * u,
        "|b| = {len} +- {u}, truth {truth_len}"
    );

    // within +-20 mg: the signed value is reported, the margin is to the nearer side.
    let (by_v, by_u) = param(&res, "accel.bias.y");
    let w = by(&res, "accel.bias.y within +-20 mg");
    assert_eq!(w.op, "within");
    assert!((w.value.unwrap() - by_v / G * 1e3).abs() < 1e-9);
    assert!((w.margin.unwrap() - (20.0 - (by_v / G * 1e3).abs())).abs() < 1e-9);
    assert!((w.expanded_u.unwrap() - 2.0 * by_u / G * 1e3).abs() < 1e-9);
    assert_eq!(w.verdict, Verdict::Pass);

    // accel.bias.x is about -1.22 mg (truth -0.012 m/s^2): outside +-1 mg by more than U,
    // so even guarded it fails, from the negative side.
    let (bx, _) = param(&res, "accel.bias.x");
    assert!(bx < 0.0);
    let x = by(&res, "accel.bias.x within +-1 mg");
    assert!(x.value.unwrap() < 0.0);
    assert_eq!(x.verdict, Verdict::Fail, "{x:?}");

    // abs(accel.bias.z): about 1.9 mg against 0.5 mg.
    let z = by(&res, "abs(accel.bias.z) <= 0.5 mg");
    assert!((z.value.unwrap() - param(&res, "accel.bias.z").0.abs() / G * 1e3).abs() < 1e-9);
    assert_eq!(z.verdict, Verdict::Fail);

    // norm(gyro.bias) in deg/s, through the gyro fit's correlations.
    let gnames: Vec<String> = ["x", "y", "z"]
        .iter()
        .map(|a| format!("gyro.bias.{a}"))
        .collect();
    let (glen, gu) = norm_by_hand(&res, &gnames);
    let g = by(&res, "norm(gyro.bias)");
    assert!((g.value.unwrap() - glen).abs() < 1e-12);
    assert!((g.expanded_u.unwrap() - 2.0 * gu).abs() < 1e-12);
}
