//! Fixtures shared by the render tests: a full dry run (manifest with run block, plan,
//! results with every optional section, IMU and ambient temperatures) and a foreign
//! recording (no run, no procedure, no plan, minimal results).

#![allow(dead_code)]

use ratecal_plan::Plan;
use ratecal_render::{ReportInput, TemperatureSeries};
use std::path::PathBuf;

pub fn fixture(name: &str) -> String {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/report")
        .join(name);
    std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

fn yaml(name: &str) -> serde_json::Value {
    serde_saphyr::from_str(&fixture(name)).expect("fixture manifest parses")
}

/// A smooth warm-up curve sampled every 10 s over 15 min (no randomness: stable snapshots).
pub fn temperatures() -> TemperatureSeries {
    let imu = (0..=90).map(|k| {
        let t = 40.0 + 10.0 * k as f64;
        (t, 22.0 + 3.0 * (1.0 - (-(t - 40.0) / 300.0).exp()))
    });
    let ambient = (0..=90).map(|k| {
        let t = 40.0 + 10.0 * k as f64;
        (t, 20.4 + 0.1 * ((t - 40.0) / 900.0))
    });
    TemperatureSeries {
        imu: imu.collect(),
        ambient: ambient.collect(),
    }
}

/// Every section present: a dry run of the standard procedure.
pub fn full() -> ReportInput {
    let plan: Plan = serde_json::from_str(&fixture("plan.json")).expect("fixture plan parses");
    ReportInput {
        results: serde_json::from_str(&fixture("results.json")).unwrap(),
        manifest: Some(yaml("manifest.yaml")),
        plan: Some(plan),
        temperature: temperatures(),
        ratecal_version: "0.1.0".into(),
        explain: None,
        archive_trend: None,
    }
}

/// A recording from another acquisition system (the shared example), analysed by `fit`
/// without a procedure: no run block, no procedure block, no plan.
pub fn foreign() -> ReportInput {
    ReportInput {
        results: serde_json::from_str(&fixture("results-external.json")).unwrap(),
        manifest: Some(yaml("manifest-external.yaml")),
        plan: None,
        temperature: TemperatureSeries::default(),
        ratecal_version: "0.1.0".into(),
        explain: None,
        archive_trend: None,
    }
}

/// Only the keys results.json must have; no manifest at all.
pub fn minimal() -> ReportInput {
    ReportInput {
        results: serde_json::from_str(&fixture("results-minimal.json")).unwrap(),
        manifest: None,
        plan: None,
        temperature: TemperatureSeries::default(),
        ratecal_version: "0.1.0".into(),
        explain: None,
        archive_trend: None,
    }
}
