//! Explain on recordings written by `ratecal-witness`, a second, deliberately simple
//! implementation of the spec (closed forms, no code shared with the physics crate or the
//! simulator), each hiding one effect at a realistic magnitude for a tactical-grade IMU.
//! Whatever explain says, it must not credit the wrong physics: a finding is the Earth's
//! rate, the registry term that is the hidden effect, or a discovered form; the unlisted
//! forms themselves are in tests/it/witness_discover.rs.

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

/// Every finding is the Earth's rate, one of `right`, or a discovered form (a registry
/// effect's leftover, e.g. a clock error's second order: tests/it/witness_discover.rs checks
/// the forms themselves).
fn not_mislabelled(x: &Explanation, right: &[&str], what: &str) {
    for f in x.findings.iter().filter(|f| !f.discovered) {
        let f = f.effect.as_str();
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
    let left = x.unexplained.iter().any(|u| u.sensor == sensor)
        || x.findings
            .iter()
            .any(|f| f.discovered && f.terms.iter().any(|t| t.channel.starts_with(&sensor[..1])));
    assert!(named || left, "{what}: missed: {:?}", found(x));
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
