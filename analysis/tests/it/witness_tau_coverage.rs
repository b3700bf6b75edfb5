//! Issue 35 item 5: a discovered warm-up's time constant and amplitudes carry an honest
//! uncertainty. Witness recordings (white noise and a wandering gyro bias) hide a gyro
//! warm-up `A exp(-t / tau)` with tau from 100 s to 900 s; over the seeds, the truth must
//! lie within 3u of the reported `tau_s` (and of each amplitude) in at least 95 % of them.
//!
//! `coverage_sweep` (ignored) is the full sweep of docs/validation.md:
//! `cargo test --release -p ratecal-analysis --test it witness_tau_coverage:: -- --ignored
//! --nocapture` (`TAU_SWEEP_SEEDS` seeds per case, 6 by default; `TAU_SWEEP_TAUS` and
//! `TAU_SWEEP_BLOCKS`, comma-separated, to run a part; `TAU_SWEEP_VERBOSE` prints each run, `TAU_SWEEP_DUMP=DIR` writes each explanation there).

use ratecal_analysis::explain::{self, Explanation, NominalModel, Options, Parameter};
use ratecal_recording as recording;
use ratecal_witness::{Hidden, Plan, Scenario, write};

/// A warm-up case: time constant, s; amplitude at power-on per gyro axis, deg/s.
type Case = (f64, [f64; 3]);

/// The standard plan's gyro-bias block, s: 300 (a recording of about 12 min) or longer.
type Block = f64;

/// What one seed's explanation reports against the truth, in units of its uncertainty.
#[derive(Debug, Default, Clone, Copy)]
struct Outcome {
    /// Whether a decay was discovered.
    found: bool,
    /// Whether it has a time constant (`tau_s`) with an uncertainty.
    refined: bool,
    /// |tau - truth| / u.
    tau_z: f64,
    /// The largest |amplitude - truth| / u over the kept channels.
    amp_z: f64,
    /// The reported tau_s and its u, s.
    tau: (f64, f64),
}

fn explain_case(seed: u64, (tau, a): Case, block: Block) -> Explanation {
    let mut s = Scenario::standard("warm-up", seed);
    s.plan = Plan::standard(block);
    let mut s = s.with(Hidden::GyroWarmUp {
        amplitude_dps: a,
        tau_s: tau,
    });
    s.thermal.rise_c = 0.0;
    let dir = tempfile::tempdir().unwrap();
    let path = match std::env::var_os("TAU_SWEEP_DUMP") {
        Some(d) => std::path::Path::new(&d).join(format!("tau{tau:.0}-a{:.3}-seed{seed}", a[0])),
        None => dir.path().to_path_buf(),
    };
    write(&path, &s).unwrap();
    let rec = recording::read(&path).unwrap();
    explain::explain(&rec, &NominalModel::seed(), &Options::default())
}

/// The decay's `t0` in an expression `exp(-(t_s - T0) / TAU) / 3600`.
fn t0_of(expression: &str) -> f64 {
    let rest = expression.split("(t_s - ").nth(1).expect("a decay");
    rest.split(')').next().unwrap().parse().unwrap()
}

fn outcome(x: &Explanation, (tau, a): Case) -> Outcome {
    let Some(f) = x
        .findings
        .iter()
        .find(|f| f.discovered && f.effect.contains("decay"))
    else {
        return Outcome::default();
    };
    let Some(Parameter::Estimate { value, u, .. }) = f.parameters.get("tau_s") else {
        return Outcome {
            found: true,
            ..Outcome::default()
        };
    };
    let amp_z = f
        .terms
        .iter()
        .map(|t| {
            let i = ["gx", "gy", "gz"].iter().position(|c| *c == t.channel);
            let truth = a[i.unwrap()] * 3600.0 * (-t0_of(&t.expression) / tau).exp();
            if std::env::var_os("TAU_SWEEP_VERBOSE").is_some() {
                eprintln!(
                    "    {}: amplitude {:.2} ± {:.2}, truth {truth:.2}",
                    t.channel, t.value, t.u
                );
            }
            (t.value - truth).abs() / t.u
        })
        .fold(0.0, f64::max);
    Outcome {
        found: true,
        refined: true,
        tau_z: (value - tau).abs() / u,
        amp_z,
        tau: (*value, *u),
    }
}

/// Amplitudes at power-on of a tactical gyro's warm-up, deg/s (about 20 to 150 deg/h).
const AMPLITUDES: [[f64; 3]; 3] = [
    [0.006, -0.004, 0.005],
    [0.015, -0.010, 0.012],
    [0.04, -0.025, 0.03],
];

/// Counts over seeds: decays found, with a time constant, tau within 3u, amplitudes
/// within 3u; the largest |tau - truth| / u.
#[derive(Debug, Default, Clone, Copy)]
struct Tally {
    found: usize,
    refined: usize,
    tau_in: usize,
    amp_in: usize,
    worst: f64,
}

impl Tally {
    fn add(&mut self, o: Outcome) {
        self.found += usize::from(o.found);
        self.refined += usize::from(o.refined);
        self.tau_in += usize::from(o.refined && o.tau_z <= 3.0);
        self.amp_in += usize::from(o.refined && o.amp_z <= 3.0);
        if o.refined {
            self.worst = self.worst.max(o.tau_z);
        }
    }

    fn join(&mut self, o: Tally) {
        self.found += o.found;
        self.refined += o.refined;
        self.tau_in += o.tau_in;
        self.amp_in += o.amp_in;
        self.worst = self.worst.max(o.worst);
    }
}

/// Runs seeds `seeds` of every case and prints a row per time constant.
fn sweep(
    block: Block,
    taus: &[f64],
    amplitudes: &[[f64; 3]],
    seeds: std::ops::Range<u64>,
) -> Tally {
    let mut all = Tally::default();
    for &tau in taus {
        let mut t = Tally::default();
        for amp in amplitudes {
            for seed in seeds.clone() {
                let x = explain_case(seed, (tau, *amp), block);
                let o = outcome(&x, (tau, *amp));
                if let Some(dir) = std::env::var_os("TAU_SWEEP_DUMP") {
                    let path = std::path::Path::new(&dir)
                        .join(format!("tau{tau:.0}-a{:.3}-seed{seed}.json", amp[0]));
                    std::fs::write(path, serde_json::to_string_pretty(&x).unwrap()).unwrap();
                }
                if std::env::var_os("TAU_SWEEP_VERBOSE").is_some() {
                    let names: Vec<&str> = x.findings.iter().map(|f| f.effect.as_str()).collect();
                    eprintln!(
                        "  findings: {names:?}; unexplained: {}",
                        x.unexplained.len()
                    );
                    eprintln!(
                        "  seed {seed} amplitude {:.3}: tau {:.1} ± {:.1} (z {:+.2}), amplitude z {:.2}",
                        amp[0],
                        o.tau.0,
                        o.tau.1,
                        (o.tau.0 - tau) / o.tau.1,
                        o.amp_z
                    );
                }
                t.add(o);
            }
        }
        let runs = amplitudes.len() * seeds.clone().count();
        eprintln!(
            "| {block:.0} | {tau:.0} | {runs} | {} | {} | {} | {} | {:.1} |",
            t.found, t.refined, t.tau_in, t.amp_in, t.worst
        );
        all.join(t);
    }
    eprintln!(
        "| {block:.0} | all | | {} | {} | {} | {} | {:.1} |",
        all.found, all.refined, all.tau_in, all.amp_in, all.worst
    );
    all
}

#[test]
#[ignore = "the full sweep of docs/validation.md: run with --release"]
fn coverage_sweep() {
    let seeds = std::env::var("TAU_SWEEP_SEEDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(6);
    eprintln!(
        "| gyro-bias block s | tau s | runs | decay found | with tau_s | tau within 3u \
         | amplitudes within 3u | worst tau z |"
    );
    let taus = list(
        "TAU_SWEEP_TAUS",
        &[100.0, 150.0, 200.0, 300.0, 450.0, 600.0, 900.0],
    );
    for block in list("TAU_SWEEP_BLOCKS", &[300.0, 1200.0]) {
        sweep(block, &taus, &AMPLITUDES, 1..seeds + 1);
    }
}

/// A comma-separated list of numbers from the environment variable `var`, else `default`.
fn list(var: &str, default: &[f64]) -> Vec<f64> {
    std::env::var(var)
        .ok()
        .map(|s| s.split(',').filter_map(|v| v.trim().parse().ok()).collect())
        .unwrap_or_else(|| default.to_vec())
}

/// A debug-build share of the sweep: the standard recording, time constants from 150 s to
/// 600 s (the longest beyond the library's grid), the middle amplitude, two seeds each.
#[test]
fn warm_up_time_constants_cover_the_truth_within_3u() {
    let t = sweep(300.0, &[150.0, 300.0, 600.0], &AMPLITUDES[1..2], 1..3);
    assert_eq!(t.found, 6, "every warm-up is discovered as a decay: {t:?}");
    assert_eq!(t.refined, 6, "every decay has tau_s: {t:?}");
    assert!(t.tau_in as f64 >= 0.95 * 6.0, "tau within 3u: {t:?}");
    // The amplitudes are not asserted: their u rests on the recording's estimate of the
    // wandering bias, which is too small in some seeds (docs/validation.md).
}
