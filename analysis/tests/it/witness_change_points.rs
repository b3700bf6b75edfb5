//! Change points anywhere in time, on recordings written by `ratecal-witness` (closed
//! forms, not our simulator): a gyro bias that jumps by tens of deg/h in the middle of the
//! long static block, and an accelerometer bias that jumps inside a static attitude, are
//! found at their instant within 3u with their size within 3u (issue 35, item 4). Before,
//! steps were tried only between segments and the gyro jump gave "nothing found".
//!
//! And the false-finding rate over nulls with Gauss-Markov bias instability (item 6):
//! `cargo test --release -p ratecal-analysis --test it witness_change_points:: -- --ignored`.

use ratecal_analysis::explain::{self, Explanation, NominalModel, Options, Parameter};
use ratecal_recording as recording;
use ratecal_witness::{GaussMarkov, Hidden, Scenario, write};
use serde_json::json;

fn explain_witness(s: &Scenario) -> Explanation {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), s).unwrap();
    let rec = recording::read(dir.path()).unwrap();
    explain::explain(&rec, &NominalModel::seed(), &Options::default())
}

fn estimate(p: Option<&Parameter>) -> (f64, f64) {
    match p {
        Some(Parameter::Estimate { value, u, .. }) => (*value, *u),
        other => panic!("not estimated: {other:?}"),
    }
}

/// The step found on `channel`: (instant, u), (size, u) in the finding's unit.
fn step_on(x: &Explanation, channel: &str) -> ((f64, f64), (f64, f64)) {
    let f = x
        .findings
        .iter()
        .find(|f| f.discovered && f.effect.starts_with(&format!("discovered_{channel}_step")))
        .unwrap_or_else(|| {
            let ids: Vec<&str> = x.findings.iter().map(|f| f.effect.as_str()).collect();
            panic!(
                "no step on {channel}: {ids:?}; unexplained {:?}",
                x.unexplained
            )
        });
    (
        estimate(f.parameters.get("at_s")),
        estimate(f.parameters.get(&format!("k_{channel}"))),
    )
}

fn within(what: &str, (v, u): (f64, f64), truth: f64) {
    eprintln!("{what}: {v:.3} ± {u:.3} (truth {truth})");
    assert!(
        (v - truth).abs() <= 3.0 * u,
        "{what}: {v} ± {u}, truth {truth}"
    );
}

/// A gyro bias jump of `jump_dph` on z at table time `at_s` (the witness's own closed form).
fn gyro_jump(at_s: f64, jump_dph: f64) -> Hidden {
    Hidden::Custom {
        name: "gyro_bias_step".into(),
        truth: json!({ "at_s": at_s, "z_dph": jump_dph }),
        f: Box::new(move |i| {
            let on = if i.t >= at_s { jump_dph / 3600.0 } else { 0.0 };
            ([0.0; 3], [0.0, 0.0, on])
        }),
    }
}

#[test]
fn a_gyro_bias_jump_inside_the_long_static_block_is_located() {
    // The standard shape's gyro-bias block runs from about 80 s to 380 s.
    let (at, jump) = (231.3, 40.0);
    let s = Scenario::standard("gyro-jump", 7).with(gyro_jump(at, jump));
    let x = explain_witness(&s);
    let (t, k) = step_on(&x, "gz");
    within("instant", t, at);
    within("jump", k, jump);
}

#[test]
fn an_accel_bias_jump_inside_a_static_attitude_is_located() {
    let at = 300.0;
    let step = [0.0, 0.004, 0.0];
    let s = Scenario::standard("accel-jump", 3).with(Hidden::AccelBiasStep {
        at_s: at,
        step_mps2: step,
    });
    let x = explain_witness(&s);
    let (t, k) = step_on(&x, "ay");
    within("instant", t, at);
    let g = s.station.gravity_mps2;
    within("jump", k, step[1] / (1e-6 * g));
}

/// Nulls with bias instability: a tactical IMU whose gyro and accelerometer biases wander
/// as Gauss-Markov processes (about 1 deg/h and 5 ug, correlation time 200 s).
fn gm_null(seed: u64) -> Scenario {
    let mut s = Scenario::standard("gm-null", seed);
    s.imu.gyro_bias_gm = Some(GaussMarkov {
        sigma: 3e-4,
        tau_s: 200.0,
    });
    s.imu.accel_bias_gm = Some(GaussMarkov {
        sigma: 5e-5,
        tau_s: 200.0,
    });
    s
}

/// Whether explain found anything in a null: an effect other than the Earth's rate (every
/// recording holds it), or a discovered term.
fn false_findings(x: &Explanation) -> Vec<String> {
    x.findings
        .iter()
        .filter(|f| f.effect != "earth_rate")
        .map(|f| f.effect.clone())
        .collect()
}

#[test]
fn gauss_markov_nulls_find_nothing() {
    for seed in [201, 202] {
        let x = explain_witness(&gm_null(seed));
        let f = false_findings(&x);
        assert!(f.is_empty(), "seed {seed}: {f:?}");
    }
}

#[test]
#[ignore]
fn fifty_gauss_markov_nulls_at_most_one_with_a_finding() {
    let mut with = 0;
    for seed in 300..350 {
        let f = false_findings(&explain_witness(&gm_null(seed)));
        if !f.is_empty() {
            eprintln!("seed {seed}: {f:?}");
            with += 1;
        }
    }
    eprintln!("Gauss-Markov nulls with a finding: {with}/50");
    assert!(with <= 1, "{with}/50");
}

/// One Gauss-Markov null, its seed from `GM_SEED` (309 by default, a seed the scan once
/// failed): a failing seed of the sweep rerun alone, with `RATECAL_EXPLAIN_DEBUG=1`.
#[test]
#[ignore]
fn one_gauss_markov_null_finds_nothing() {
    let seed = std::env::var("GM_SEED").map_or(309, |s| s.parse().unwrap());
    let f = false_findings(&explain_witness(&gm_null(seed)));
    assert!(f.is_empty(), "seed {seed}: {f:?}");
}
