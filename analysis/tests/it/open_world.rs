//! Explain on recordings written by an independent implementation of the spec, each with
//! physics no registry holds (`../shared/examples/open-*`, with their truth.json): the
//! right answer names only the Earth's rate, and says what remains unexplained, on the
//! right sensor, with the right form, never crediting a registry effect with it.

use crate::shared;
use ratecal_analysis::explain::{self, Explanation, NominalModel, Options, Parameter};
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
    let Parameter::Estimate { value, u, .. } = &f.parameters["latitude_deg"] else {
        panic!("latitude not reported");
    };
    assert_eq!((*value, *u), (latitude, 0.0));
    let Parameter::Estimate { value, .. } = &f.parameters["north_dph"] else {
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
    let Parameter::Estimate { value, u, .. } = &f.parameters["heading_deg"] else {
        panic!("heading not fitted");
    };
    assert!(value.abs() < 3.0 * u && *u < 5.0, "heading {value} ± {u}");
}

/// The discovered term on `channel` whose expression starts with `form`: (value, u).
fn term(x: &Explanation, channel: &str, form: &str) -> (f64, f64) {
    x.findings
        .iter()
        .filter(|f| f.discovered)
        .flat_map(|f| &f.terms)
        .find(|t| t.channel == channel && t.expression.contains(form))
        .map(|t| (t.value, t.u))
        .unwrap_or_else(|| panic!("no {form} on {channel}: {:?}", found(x)))
}

#[test]
fn gyro_g2_is_discovered_on_the_gyros_with_its_form_and_values() {
    let Some(x) = explain_example("open-gyro-g2") else {
        return;
    };
    // Before: g_sensitivity and a latitude of 46.6 deg. Now the Earth's rate, held, and the
    // form itself, discovered; no registry effect takes its credit.
    assert_eq!(found(&x)[0], "earth_rate", "refused {:?}", x.refused);
    assert!(
        x.findings[1..].iter().all(|f| f.discovered),
        "{:?}",
        found(&x)
    );
    earth_held(&x, 40.0);
    assert!(x.unexplained.is_empty(), "{:?}", x.unexplained);
    // Its own axis squared, on each of the three axes (truth.json: 0.006, -0.004, 0.005
    // deg/s/g^2, i.e. 21.6, -14.4, 18 deg/h/g^2).
    for (c, form, truth) in [
        ("gx", "f_b.x^2 / g^2", 21.6),
        ("gy", "f_b.y^2 / g^2", -14.4),
        ("gz", "f_b.z^2 / g^2", 18.0),
    ] {
        let (v, u) = term(&x, c, form);
        assert!(
            (v - truth).abs() <= 3.0 * u,
            "{c}: {v} +- {u}, truth {truth}"
        );
    }
}

#[test]
fn accel_bias_step_is_discovered_on_the_accelerometers_at_its_instant() {
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
    assert!(x.unexplained.is_empty(), "{:?}", x.unexplained);
    let step = x
        .findings
        .iter()
        .find(|f| f.discovered)
        .expect("a discovered step");
    let channels: Vec<&str> = step.terms.iter().map(|t| t.channel.as_str()).collect();
    assert_eq!(channels, ["ax", "ay"], "az has no step");
    // truth.json: 0.004 and -0.003 m/s^2 at t = 1500 s; g = 9.80160 m/s^2 in the manifest.
    for (c, truth) in [("ax", 0.004), ("ay", -0.003)] {
        let (v, u) = term(&x, c, "sign(t_s - ");
        let truth = truth / (1e-6 * 9.80160);
        assert!(
            (v - truth).abs() <= 3.0 * u,
            "{c}: {v} +- {u} ug, truth {truth}"
        );
    }
    let Parameter::Estimate { value, .. } = &step.parameters["at_s"] else {
        panic!("no instant")
    };
    assert!((value - 1500.0).abs() < 20.0, "step at {value}");
}
