//! Explain on recordings written by `ratecal-witness`, a second, deliberately simple
//! implementation of the spec (closed forms, no code shared with the physics crate or the
//! simulator), each hiding one effect at a realistic magnitude for a tactical-grade IMU.
//! Whatever explain says, it must not credit the wrong physics: a finding is the Earth's
//! rate or the registry term that is the hidden effect; anything else it cannot name shows
//! as `unexplained` on the right sensor.

use ratecal_analysis::explain::{self, Explanation, NominalModel, Options};
use ratecal_recording as recording;
use ratecal_witness::{Hidden, Scenario, write};

fn explain_witness(name: &str, seed: u64, hidden: Option<Hidden>) -> Explanation {
    let dir = tempfile::tempdir().unwrap();
    let mut s = Scenario::standard(name, seed);
    if let Some(h) = hidden {
        s = s.with(h);
    }
    write(dir.path(), &s).unwrap();
    let rec = recording::read(dir.path()).unwrap();
    explain::explain(&rec, &NominalModel::seed(), &Options::default())
}

fn found(x: &Explanation) -> Vec<&str> {
    x.findings.iter().map(|f| f.effect.as_str()).collect()
}

/// Every finding is the Earth's rate or one of `right`.
fn not_mislabelled(x: &Explanation, right: &[&str], what: &str) {
    for f in found(x) {
        assert!(
            f == "earth_rate" || right.contains(&f),
            "{what}: {f} named; refused {:?}; unexplained {:?}",
            x.refused,
            x.unexplained
        );
    }
}

/// Named as one of `right`, or unexplained on `sensor`.
fn seen_on(x: &Explanation, right: &[&str], sensor: &str, what: &str) {
    let named = found(x).iter().any(|f| right.contains(f));
    let left = x.unexplained.iter().any(|u| u.sensor == sensor);
    assert!(named || left, "{what}: missed: {:?}", found(x));
}

/// The forms of the `sensor`'s unexplained entries.
fn forms<'a>(x: &'a Explanation, sensor: &str) -> Vec<(&'a str, &'a str)> {
    x.unexplained
        .iter()
        .filter(|u| u.sensor == sensor)
        .flat_map(|u| &u.signature)
        .map(|s| (s.channel.as_str(), s.expression.as_str()))
        .collect()
}

#[test]
fn nulls_name_only_the_earth_rate() {
    for seed in [11, 12, 13] {
        let x = explain_witness("null", seed, None);
        assert_eq!(found(&x), ["earth_rate"], "seed {seed}: {:?}", x.refused);
        assert!(x.unexplained.is_empty(), "seed {seed}: {:?}", x.unexplained);
    }
}

#[test]
fn accelerometer_cross_coupling_is_unexplained_with_its_product() {
    let x = explain_witness(
        "cross",
        1,
        Some(Hidden::AccelCrossCoupling {
            ug_per_g2: [300.0, -250.0, 0.0],
        }),
    );
    not_mislabelled(&x, &[], "cross-coupling");
    seen_on(&x, &[], "accel", "cross-coupling");
    let f = forms(&x, "accel");
    assert!(f.contains(&("ax", "f_b.y * f_b.z / g")), "{f:?}");
}

#[test]
fn gyro_g2_is_unexplained_with_the_own_axis_square() {
    let x = explain_witness(
        "g2",
        1,
        Some(Hidden::GyroG2 {
            dps_per_g2: [0.006, -0.004, 0.005],
        }),
    );
    not_mislabelled(&x, &[], "gyro g^2");
    let f = forms(&x, "gyro");
    for (c, e) in [("gx", "f_b.x^2 / g^2"), ("gz", "f_b.z^2 / g^2")] {
        assert!(f.contains(&(c, e)), "{c} {e} not in {f:?}");
    }
}

#[test]
fn gyro_warm_up_is_unexplained_in_time() {
    let x = explain_witness(
        "warm-up",
        1,
        Some(Hidden::GyroWarmUp {
            amplitude_dps: [0.03, -0.02, 0.025],
            tau_s: 200.0,
        }),
    );
    not_mislabelled(&x, &[], "warm-up");
    seen_on(&x, &[], "gyro", "warm-up");
    let timed = x
        .unexplained
        .iter()
        .filter(|u| u.sensor == "gyro")
        .flat_map(|u| &u.signature)
        .any(|s| s.in_time);
    assert!(timed, "{:?}", x.unexplained);
}

#[test]
fn accelerometer_bias_step_is_unexplained_at_its_instant() {
    for seed in [1, 2] {
        let x = explain_witness(
            "step",
            seed,
            Some(Hidden::AccelBiasStep {
                at_s: 110.0,
                step_mps2: [0.004, -0.003, 0.0],
            }),
        );
        // Before: accel_misalignment, 0.055 mrad at 18 standard errors.
        not_mislabelled(&x, &[], "bias step");
        let u = x
            .unexplained
            .iter()
            .find(|u| u.sensor == "accel")
            .expect("unexplained on the accelerometers");
        assert!(u.channels.contains(&"ax".into()) && u.channels.contains(&"ay".into()));
        let s = &u.signature[0];
        assert!(
            s.in_time && s.expression.starts_with("(sign(t_s - "),
            "{s:?}"
        );
    }
}

#[test]
fn registry_terms_are_named_or_left_unexplained_never_mislabelled() {
    let cases: Vec<(&str, Hidden, &[&str], &str)> = vec![
        (
            "k2",
            Hidden::AccelSecondOrder {
                k2_ug_per_g2: [150.0, -120.0, 100.0],
            },
            &["accel_second_order"],
            "accel",
        ),
        (
            "gyro-asym",
            Hidden::GyroScaleAsymmetry {
                ppm: [400.0, -300.0, 0.0],
            },
            &["gyro_scale_asymmetry"],
            "gyro",
        ),
        (
            "accel-asym",
            Hidden::AccelScaleAsymmetry {
                ppm: [300.0, -250.0, 200.0],
            },
            &["accel_scale_asymmetry"],
            "accel",
        ),
        (
            "clock",
            Hidden::ClockRate { ppm: 60.0 },
            &["clock_rate"],
            "gyro",
        ),
        (
            "g-sens",
            Hidden::GSensitivity {
                dps_per_g: [[0.01, 0.0, -0.008], [0.0, 0.012, 0.006], [0.0; 3]],
            },
            &["g_sensitivity"],
            "gyro",
        ),
    ];
    for (name, hidden, right, sensor) in cases {
        let x = explain_witness(name, 1, Some(hidden));
        not_mislabelled(&x, right, name);
        seen_on(&x, right, sensor, name);
    }
}
