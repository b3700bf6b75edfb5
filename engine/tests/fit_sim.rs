//! The analysis on simulated recordings with known parameters: estimates within their
//! stated uncertainty, and uncertainties that are honest over many seeds.

mod fit_support;

use fit_support::{SimSpec, standard_windows, truth_params, write};
use ratecal_engine::results::Parameter;
use ratecal_engine::{fit, recording};

fn run(spec: &SimSpec) -> (ratecal_engine::results::Results, Vec<(String, f64)>) {
    let tmp = tempfile::tempdir().unwrap();
    let truth = write(tmp.path(), spec, &standard_windows(spec.block_s));
    let rec = recording::read(tmp.path()).expect("simulated recording reads");
    (fit::analyze(&rec, None), truth_params(&truth))
}

#[test]
fn one_seed_every_estimate_within_its_uncertainty() {
    let (res, truth) = run(&SimSpec::tactical(7));
    for (name, want) in truth {
        match &res.parameters[&name] {
            Parameter::Estimate { value, u, .. } => {
                let z = (value - want) / u;
                assert!(
                    z.abs() < 3.0,
                    "{name}: {value} +- {u} vs {want} (z = {z:.2})"
                );
            }
            Parameter::Unobservable { .. } => {
                assert_eq!(name, "gyro.scale.z", "{name} should be observable")
            }
        }
    }
    // The standard plan never rotates about Z.
    assert_eq!(res.parameters["gyro.scale.z"], Parameter::unobservable());
    assert!(res.observability["gyro.scale.z"].contains("rate point"));
}

#[test]
fn uncertainties_are_honest_over_many_seeds() {
    let (mut inside, mut total) = (0usize, 0usize);
    let mut per: std::collections::BTreeMap<String, (usize, usize)> = Default::default();
    for seed in 0..40 {
        let (res, truth) = run(&SimSpec::tactical(1000 + seed));
        for (name, want) in truth {
            if let Some((v, u)) = res.value(&name) {
                let ok = (v - want).abs() <= 2.0 * u;
                inside += usize::from(ok);
                total += 1;
                let e = per.entry(name).or_default();
                e.0 += usize::from(ok);
                e.1 += 1;
            }
        }
    }
    let frac = inside as f64 / total as f64;
    eprintln!("{inside}/{total} = {frac:.3} within 2u; per parameter: {per:?}");
    assert!((0.88..=0.995).contains(&frac), "{frac}");
}
