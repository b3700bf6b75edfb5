//! Writes a fleet of one model's units (issue 40's "done when"): every unit its own biases
//! and scales, sharing an accelerometer K2 too weak for any one recording; one unit recorded
//! three times, each with the same lever arm; another recorded three times, twice right
//! after power-on with a gyro warm-up; one unit whose K2 is five times the fleet's. With
//! `--null`, nothing is shared: each unit only its own biases and scales.
//!
//! `cargo run --release -p ratecal-witness --example fleet -- OUT_DIR [--units N] [--null]
//! [--seed S] [--gyro-bias-s S] [--k2 UG_PER_G2]`
//!
//! Then: `ratecal explain OUT_DIR/*/ --format json`.

use ratecal_witness::{Hidden, Scenario, write};
use std::path::PathBuf;

/// The options.
struct Args {
    out: PathBuf,
    units: u64,
    null: bool,
    seed: u64,
    gyro_bias_s: f64,
    k2: f64,
}

fn args() -> Args {
    let mut a = Args {
        out: PathBuf::new(),
        units: 20,
        null: false,
        seed: 1,
        gyro_bias_s: 60.0,
        k2: 16.0,
    };
    let mut it = std::env::args().skip(1);
    while let Some(s) = it.next() {
        let mut num = || {
            it.next()
                .and_then(|v| v.parse::<f64>().ok())
                .expect("a number")
        };
        match s.as_str() {
            "--units" => a.units = num() as u64,
            "--null" => a.null = true,
            "--seed" => a.seed = num() as u64,
            "--gyro-bias-s" => a.gyro_bias_s = num(),
            "--k2" => a.k2 = num(),
            _ => a.out = PathBuf::from(s),
        }
    }
    assert!(
        !a.out.as_os_str().is_empty(),
        "usage: fleet OUT_DIR [options]"
    );
    a
}

/// Unit `n` of the fleet ([`Scenario::fleet_unit`]), the noise from `seed`.
fn unit(n: u64, seed: u64, a: &Args) -> Scenario {
    Scenario::fleet_unit(&format!("SN{n:03}"), n, seed, a.gyro_bias_s)
}

fn k2(k: f64) -> Hidden {
    Hidden::AccelSecondOrder {
        k2_ug_per_g2: [k, k, k],
    }
}

fn main() -> std::io::Result<()> {
    let a = args();
    let mut fleet: Vec<Scenario> = Vec::new();
    let base = 1000 * a.seed;
    let shared = |s: Scenario, k: f64| if a.null { s } else { s.with(k2(k)) };
    for n in 1..=a.units {
        let seed = base + n;
        match n {
            // Recorded three times, each with the same lever arm.
            1 if !a.null => {
                for i in 0..3 {
                    let lever = [[30.0, 0.0, 0.0]; 3];
                    fleet.push(
                        shared(unit(n, seed + 100 * i, &a), a.k2)
                            .with(Hidden::LeverArm { r_mm: lever }),
                    );
                }
            }
            // Recorded three times, twice right after power-on (a gyro warm-up).
            2 if !a.null => {
                for i in 0..3 {
                    let s = shared(unit(n, seed + 100 * i, &a), a.k2);
                    fleet.push(match i {
                        0 | 1 => s.with(Hidden::GyroWarmUp {
                            amplitude_dps: [0.03, -0.02, 0.025],
                            tau_s: 100.0,
                        }),
                        _ => s,
                    });
                }
            }
            // Five times the fleet's K2.
            3 if !a.null => fleet.push(shared(unit(n, seed, &a), 5.0 * a.k2)),
            _ => fleet.push(shared(unit(n, seed, &a), a.k2)),
        }
    }
    for (i, s) in fleet.iter().enumerate() {
        let dir = a.out.join(format!("{i:02}-{}", s.name));
        write(&dir, s)?;
    }
    eprintln!("{} recordings in {}", fleet.len(), a.out.display());
    Ok(())
}
