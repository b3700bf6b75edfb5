//! The analysis on simulated recordings with known parameters: estimates within their
//! stated uncertainty, and uncertainties that are honest over many seeds.

use crate::fit_support;
use fit_support::{SimSpec, standard_windows, truth_params, write};
use ratecal_analysis::fit;
use ratecal_analysis::results::Parameter;
use ratecal_recording as recording;

fn run(spec: &SimSpec) -> (ratecal_analysis::results::Results, Vec<(String, f64)>) {
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
            Parameter::UpperBound { .. } => panic!("{name}: a calibration parameter as a bound"),
        }
    }
    // The standard plan never rotates about Z, and the result says what would determine it.
    assert_eq!(
        res.parameters["gyro.scale.z"],
        Parameter::needs("rotate about Z")
    );
    assert!(res.observability["gyro.scale.z"].contains("rotate about Z"));
}

/// Over 40 seeds, the fraction of each parameter's estimates within 2u of the truth, and
/// of all of them: about 95 % if the uncertainties are honest (a binomial 40 at 0.95 falls
/// below 33 with a probability of about 1e-3).
fn honesty(runs: impl Iterator<Item = (ratecal_analysis::results::Results, Vec<(String, f64)>)>) {
    let (mut inside, mut total) = (0usize, 0usize);
    let mut per: std::collections::BTreeMap<String, (usize, usize)> = Default::default();
    for (res, truth) in runs {
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
    assert!((0.9..=0.99).contains(&frac), "{frac}");
    for (name, (k, n)) in &per {
        assert!(*n == 40, "{name} estimated in {n} of 40 runs");
        assert!(*k >= 33, "{name}: {k} of {n} within 2u");
    }
}

#[test]
fn uncertainties_are_honest_over_many_seeds() {
    honesty((0..40).map(|seed| run(&SimSpec::tactical(1000 + seed))));
}

/// The same with effects present in the IMU and declared to the analysis (`--with`): a
/// lever arm (accelerometer sensing points a few centimetres off the table's centre) and
/// a g-sensitivity, each of whose observable parameters is honest too, the nominal ones
/// beside them.
#[test]
fn effect_uncertainties_are_honest_over_many_seeds() {
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};
    let g = fit_support::SITE.gravity_mps2;
    honesty((0..40).map(|seed| {
        let mut spec = SimSpec::tactical(2000 + seed);
        let mut rng = rand::rngs::ChaCha8Rng::seed_from_u64(seed);
        let n = Normal::new(0.0, 1.0).unwrap();
        for i in 0..3 {
            for j in 0..3 {
                spec.errors.lever_m[(i, j)] = 0.02 * n.sample(&mut rng);
                // 0.005 deg/s per g, as (deg/s) per (m/s^2).
                spec.errors.g_sens[(i, j)] = 0.005 / g * n.sample(&mut rng);
            }
        }
        let tmp = tempfile::tempdir().unwrap();
        let truth = write(tmp.path(), &spec, &standard_windows(spec.block_s));
        let rec = recording::read(tmp.path()).expect("simulated recording reads");
        let opts = fit::Options {
            with: vec!["lever_arm".into(), "g_sensitivity".into()],
            ..fit::Options::default()
        };
        let res = fit::analyze_with(&rec, None, &opts);
        let mut want = truth_params(&truth);
        let xyz = ["x", "y", "z"];
        for i in 0..3 {
            for j in 0..3 {
                let (a, b) = (xyz[i], xyz[j]);
                want.push((
                    format!("lever_arm.r{a}{b}_mm"),
                    spec.errors.lever_m[(i, j)] * 1e3,
                ));
                want.push((
                    format!("g_sensitivity.{a}{b}_dps_per_g"),
                    spec.errors.g_sens[(i, j)] * g,
                ));
            }
        }
        (res, want)
    }));
}
