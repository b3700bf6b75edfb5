//! Explain across recordings (docs/explain.md, "Across recordings"): every parameter of
//! every candidate each recording's profile holds ([`super::profile`]) is pooled over the
//! recordings with random effects ([`pool`]), and judged: physics of the model (every
//! unit shows it), of the unit (every recording of one serial), of the day (some
//! recordings), seen only in the pool, or nothing.

mod judge;
mod pool;
mod text;

pub use text::render_text;

use super::Explanation;
use serde::{Deserialize, Serialize};

/// A recording to pool: its run, its unit and its explanation (with a profile).
pub struct Member<'a> {
    /// The run (its folder, or the archive's run id).
    pub run: String,
    /// The manifest's `imu.serial`.
    pub serial: String,
    /// The explanation, computed with [`super::Options::profile`].
    pub explanation: &'a Explanation,
}

/// What explain says across recordings: the JSON key `across` (stable).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Across {
    /// The recordings pooled, in the order given.
    pub recordings: Vec<RecordingOut>,
    /// The pooled parameters worth naming: every verdict but `none`, and every parameter
    /// of an effect some recording reported.
    pub effects: Vec<PooledOut>,
    /// Serials whose value lies outside the fleet's spread.
    pub outliers: Vec<Outlier>,
}

/// One recording of the pool.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RecordingOut {
    /// The run.
    pub run: String,
    /// The manifest's `imu.serial`.
    pub serial: String,
    /// What explain reported in it (effect ids).
    pub findings: Vec<String>,
    /// How many entries its `unexplained` holds.
    pub unexplained: usize,
}

/// One parameter pooled over the recordings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PooledOut {
    /// The registry or user effect's id, or `form_<sensor>_<form>`.
    pub effect: String,
    /// The parameter (a form's channel).
    pub parameter: String,
    /// The pooled value (outliers left out for `model` and `pooled_only`).
    pub pooled: f64,
    /// Its standard uncertainty.
    pub u: f64,
    /// The spread between recordings beyond their own uncertainties (tau).
    pub spread: f64,
    /// Heterogeneity I^2 (0 to 1).
    pub i2: f64,
    /// `model`, `unit`, `occasional`, `pooled_only` or `none`.
    pub verdict: String,
    /// Each recording's value.
    pub per_recording: Vec<PerRecording>,
    /// The runs the pooled value leaves out (outliers' recordings).
    pub left_out: Vec<String>,
    /// The unit of the values (text output only).
    #[serde(skip)]
    pub unit: String,
}

/// One recording's value of a parameter.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PerRecording {
    /// The run.
    pub run: String,
    /// Its serial.
    pub serial: String,
    /// Value.
    pub value: f64,
    /// Standard uncertainty.
    pub u: f64,
}

/// A serial whose value of a parameter lies outside the fleet's spread.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Outlier {
    /// The serial.
    pub serial: String,
    /// The effect.
    pub effect: String,
    /// The parameter.
    pub parameter: String,
    /// The serial's value (its recordings' weighted mean).
    pub value: f64,
    /// Its standard uncertainty.
    pub u: f64,
}

impl PooledOut {
    /// Where a unit of the fleet is expected to lie about the pooled value: its standard
    /// uncertainty and the spread between units together, `sqrt(u^2 + spread^2)` (what the
    /// forest plot's wide band shows and the model's twin writes as u).
    pub fn fleet_u(&self) -> f64 {
        self.u.hypot(self.spread)
    }
}

impl Across {
    /// How many units (distinct serials) the pooled recordings are of.
    pub fn units(&self) -> usize {
        judge::distinct(self.recordings.iter().map(|r| r.serial.as_str())).len()
    }

    /// Whether the pool has a finding: any verdict but `none`.
    pub fn has_finding(&self) -> bool {
        self.effects.iter().any(|e| e.verdict != "none")
    }
}

/// Pools the members' profiles at family-wise (per recording) and false-discovery (over
/// the pool) level `alpha`.
pub fn pool(members: &[Member], alpha: f64) -> Across {
    let recordings = members
        .iter()
        .map(|m| RecordingOut {
            run: m.run.clone(),
            serial: m.serial.clone(),
            findings: m
                .explanation
                .findings
                .iter()
                .map(|f| f.effect.clone())
                .collect(),
            unexplained: m.explanation.unexplained.len(),
        })
        .collect();
    let (effects, outliers) = judge::judge(members, alpha);
    Across {
        recordings,
        effects,
        outliers,
    }
}
