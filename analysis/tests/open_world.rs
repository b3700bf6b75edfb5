//! Explain on recordings written by an independent implementation of the spec, each with
//! physics no registry holds (`../shared/examples/open-*`, with their truth.json): the
//! right answer names only the Earth's rate, and says what remains unexplained, on the
//! right sensor, with the right form, never crediting a registry effect with it.

#[path = "../../tests/support/shared.rs"]
mod shared;

use ratecal_analysis::explain::{self, Explanation, NominalModel, Options, ParamOut};
use ratecal_recording as recording;

fn explain_example(name: &str) -> Option<Explanation> {
    let dir = shared::shared_example(name)?;
    let rec = recording::read(&dir).unwrap();
    Some(explain::explain(
        &rec,
        &NominalModel::seed(),
        &Options::default(),
    ))
}

fn found(x: &Explanation) -> Vec<&str> {
    x.findings.iter().map(|f| f.effect.as_str()).collect()
}

/// The Earth's rate is reported at the manifest's latitude, never fitted.
fn earth_held(x: &Explanation, latitude: f64) {
    let f = x
        .findings
        .iter()
        .find(|f| f.effect == "earth_rate")
        .expect("the Earth's rate is always in a real recording");
    let ParamOut::Estimate { value, u, .. } = &f.parameters["latitude_deg"] else {
        panic!("latitude not reported");
    };
    assert_eq!((*value, *u), (latitude, 0.0));
    let ParamOut::Estimate { value, .. } = &f.parameters["north_dph"] else {
        panic!("north not reported");
    };
    assert!((value - 15.041 * latitude.to_radians().cos()).abs() < 0.01);
}

#[test]
fn null_names_the_earth_rate_and_nothing_else() {
    let Some(x) = explain_example("open-null") else {
        return;
    };
    assert_eq!(found(&x), ["earth_rate"], "refused {:?}", x.refused);
    assert!(x.unexplained.is_empty(), "{:?}", x.unexplained);
    earth_held(&x, 40.0);
    // The table is aligned: the fitted heading is zero within 3u.
    let f = &x.findings[0];
    let ParamOut::Estimate { value, u, .. } = &f.parameters["heading_deg"] else {
        panic!("heading not fitted");
    };
    assert!(value.abs() < 3.0 * u && *u < 5.0, "heading {value} ± {u}");
}

#[test]
fn gyro_g2_is_unexplained_on_the_gyros_with_its_form() {
    let Some(x) = explain_example("open-gyro-g2") else {
        return;
    };
    // Before: g_sensitivity and a latitude of 46.6 deg. Only the Earth's rate is named.
    assert_eq!(found(&x), ["earth_rate"], "refused {:?}", x.refused);
    earth_held(&x, 40.0);
    let gyro: Vec<_> = x
        .unexplained
        .iter()
        .filter(|u| u.sensor == "gyro")
        .collect();
    assert!(!gyro.is_empty(), "{:?}", x.unexplained);
    assert!(x.unexplained.iter().all(|u| u.sensor == "gyro"));
    // Its own axis squared, on each of the three axes (truth: 0.006, -0.004, 0.005 deg/s/g^2).
    for (c, form) in [("gx", "f_b.x^2"), ("gy", "f_b.y^2"), ("gz", "f_b.z^2")] {
        let hit = gyro
            .iter()
            .flat_map(|u| &u.signature)
            .any(|s| s.channel == c && s.expression.starts_with(form) && s.share > 0.9);
        assert!(hit, "{c} does not follow {form}: {:?}", gyro);
    }
}

#[test]
fn accel_bias_step_is_unexplained_on_the_accelerometers_at_its_instant() {
    let Some(x) = explain_example("open-accel-bias-step") else {
        return;
    };
    assert_eq!(found(&x)[0], "earth_rate");
    // No registry effect that a step explains better is named for it.
    for id in [
        "accel_thermal_drift",
        "lever_arm",
        "time_offset",
        "accel_scale_thermal",
    ] {
        assert!(!found(&x).contains(&id), "{id} named: {:?}", found(&x));
    }
    let accel: Vec<_> = x
        .unexplained
        .iter()
        .filter(|u| u.sensor == "accel")
        .collect();
    assert_eq!(accel.len(), 1, "{:?}", x.unexplained);
    let u = accel[0];
    assert!(u.channels.contains(&"ax".to_string()) && u.channels.contains(&"ay".to_string()));
    assert!(
        !u.channels.contains(&"az".to_string()),
        "az has no step: {:?}",
        u.channels
    );
    // The strongest form is a step between the segments around t = 1500 s.
    let best = &u.signature[0];
    assert!(best.in_time, "{best:?}");
    let at: f64 = best
        .expression
        .trim_start_matches("(sign(t_s - ")
        .split(')')
        .next()
        .and_then(|v| v.parse().ok())
        .expect("a step's instant");
    assert!((at - 1500.0).abs() < 20.0, "step at {at}");
}
