//! Writes a corpus of witness recordings: each hidden kind at a realistic (tactical-grade)
//! magnitude, three seeds each, plus null recordings, each folder with its `truth.json`;
//! and `corpus.json` listing them.
//!
//! `cargo run -p ratecal-witness --example open_world -- OUT_DIR [--gyro-bias-s S] [--nulls N]`
//!
//! Then, e.g.: `for d in OUT_DIR/*/; do ratecal explain $d --format json > $d/explain.json; done`

use std::path::PathBuf;

use ratecal_witness::{Hidden, Plan, Scenario, write};

/// Each hidden kind at a magnitude a tactical IMU can have, large enough to be seen over
/// its noise on the standard plan.
fn kinds() -> Vec<(&'static str, Hidden)> {
    vec![
        (
            "accel-k2",
            Hidden::AccelSecondOrder {
                k2_ug_per_g2: [150.0, -120.0, 100.0],
            },
        ),
        (
            "accel-cross",
            Hidden::AccelCrossCoupling {
                ug_per_g2: [300.0, -250.0, 0.0],
            },
        ),
        (
            "gyro-g2",
            Hidden::GyroG2 {
                dps_per_g2: [0.006, -0.004, 0.005],
            },
        ),
        (
            "gyro-scale-asym",
            Hidden::GyroScaleAsymmetry {
                ppm: [400.0, -300.0, 0.0],
            },
        ),
        (
            "accel-scale-asym",
            Hidden::AccelScaleAsymmetry {
                ppm: [300.0, -250.0, 200.0],
            },
        ),
        ("clock-rate", Hidden::ClockRate { ppm: 60.0 }),
        (
            "accel-bias-step",
            Hidden::AccelBiasStep {
                at_s: 110.0,
                step_mps2: [0.004, -0.003, 0.0],
            },
        ),
        (
            "gyro-warm-up",
            Hidden::GyroWarmUp {
                amplitude_dps: [0.03, -0.02, 0.025],
                tau_s: 200.0,
            },
        ),
        (
            "g-sensitivity",
            Hidden::GSensitivity {
                dps_per_g: [[0.01, 0.0, -0.008], [0.0, 0.012, 0.006], [0.0; 3]],
            },
        ),
        (
            "lever-arm",
            Hidden::LeverArm {
                r_mm: [[-4.0, 9.0, -12.0], [3.0, 14.0, -8.0], [-6.0, 2.0, 25.0]],
            },
        ),
    ]
}

fn main() -> std::io::Result<()> {
    let mut args = std::env::args().skip(1);
    let mut out: Option<PathBuf> = None;
    let (mut gyro_bias_s, mut nulls) = (300.0, 6);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--gyro-bias-s" => gyro_bias_s = args.next().and_then(|v| v.parse().ok()).unwrap(),
            "--nulls" => nulls = args.next().and_then(|v| v.parse().ok()).unwrap(),
            _ => out = Some(a.into()),
        }
    }
    let Some(out) = out else {
        eprintln!("usage: open_world OUT_DIR [--gyro-bias-s S] [--nulls N]");
        std::process::exit(2);
    };
    let mut listed = Vec::new();
    let mut put = |name: String, seed: u64, hidden: Option<Hidden>| -> std::io::Result<()> {
        let mut s = Scenario::standard(&name, seed);
        s.plan = Plan::standard(gyro_bias_s);
        s.hidden.extend(hidden);
        let truth = write(&out.join(&name), &s)?;
        eprintln!("{name}: {:.0} s", truth.duration_s);
        listed.push(serde_json::json!({ "recording": name, "hidden": truth.hidden }));
        Ok(())
    };
    for seed in 1..=3 {
        for (name, hidden) in kinds() {
            put(format!("{name}-{seed}"), 1000 + seed, Some(hidden))?;
        }
    }
    for seed in 1..=nulls {
        put(format!("null-{seed}"), 2000 + seed, None)?;
    }
    let corpus = serde_json::to_string_pretty(&listed).map_err(std::io::Error::other)?;
    std::fs::write(out.join("corpus.json"), corpus + "\n")
}
