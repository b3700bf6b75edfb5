//! What the twin's comparison reports: the `twin` key of explain's JSON (docs/explain.md).

use crate::explain::Rms;
use serde::{Deserialize, Serialize};

/// The twin against the recording: its prediction before and after the changes, the
/// changes, and (filled in by the CLI) the file written and its diff.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TwinReport {
    /// The station file compared, as given.
    pub station: String,
    /// The twin as it is.
    pub before: Prediction,
    /// The twin with every change made.
    pub after: Prediction,
    /// What the recording says the twin gets wrong or lacks (empty when it is right).
    pub changes: Vec<Change>,
    /// Parameters of the changed or added effects that the recording cannot determine
    /// (its motion does not excite them): kept at the twin's value, not changed.
    #[serde(default)]
    pub not_determined: Vec<Kept>,
    /// Whether the twin needs a change: a changed parameter, missing physics or a
    /// residual nothing explains.
    pub needs_change: bool,
    /// The corrected station file written (`--write-twin`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub written: Option<String>,
    /// The unified diff from the twin to the written file.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub diff: Option<String>,
    /// Time series of the segments where the twin disagrees most (a few per segment kind):
    /// what the twin's figures per kind draw.
    #[serde(default)]
    pub series: Vec<Series>,
}

/// One segment's channel in time: the recording's output and the twin's prediction as it is
/// and updated, each minus the ideal input (the IMU model's part of the output), in means
/// over one second or more.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Series {
    /// Segment id.
    pub segment: String,
    /// Its kind (`static`, `rate`, `oscillation`).
    pub kind: String,
    /// Channel, `ax` ... `gz`.
    pub channel: String,
    /// Mean stamp of each point, s since the segment's start.
    pub t_s: Vec<f64>,
    /// The recording (m/s^2 or deg/s).
    pub real: Vec<f64>,
    /// The twin as it is.
    pub before: Vec<f64>,
    /// The twin updated.
    pub after: Vec<f64>,
}

/// A twin's prediction of every sample of the recording's segments, against the samples.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Prediction {
    /// Residual RMS (recording - prediction) per sensor over every segment.
    pub rms: Rms,
    /// What the twin says the residual should be: its white noise and gyro bias wander.
    pub noise: Rms,
    /// Every segment and channel with data, in recording order.
    pub segments: Vec<SegmentResidual>,
    /// The segments and channels the twin gets wrong: residual RMS over 1.1 times the
    /// noise and its sum of squares five standard deviations above the noise's (largest
    /// ratio first, at most ten).
    pub disagree: Vec<SegmentResidual>,
}

/// The residual of one segment and channel.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SegmentResidual {
    /// Segment id.
    pub segment: String,
    /// Its kind (`static`, `rate`, `oscillation`, ...).
    pub kind: String,
    /// Channel, `ax` ... `gz`.
    pub channel: String,
    /// Residual RMS (m/s^2 or deg/s).
    pub rms: f64,
    /// Residual mean.
    pub mean: f64,
    /// Residual standard deviation about the mean: what is left once the segment's offset
    /// (a wandering gyro bias's, in a right twin) is set aside.
    pub sd: f64,
    /// The RMS the twin's noise figures allow there.
    pub noise_twin: f64,
    /// The recording's own white noise on the channel (explain's final model).
    pub noise_recording: f64,
    /// `rms` over the larger of the two noise figures (the recording's with the twin's
    /// bias wander): 1 at the noise floor.
    pub ratio: f64,
}

/// One parameter of the twin the recording contradicts, or of an effect it lacks.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Change {
    /// Registry id as docs/effects.md names it (`gyro_scale`, `lever_arm`), or a user
    /// effect's id.
    pub effect: String,
    /// Parameter name there (`x`, `rzz_mm`).
    pub parameter: String,
    /// The twin's value (0 for an effect it lacked).
    pub from: f64,
    /// What the recording says.
    pub to: f64,
    /// Standard uncertainty of `to`.
    pub u: f64,
    /// The parameter's unit as docs/effects.md writes it.
    pub unit: String,
    /// How many combined standard uncertainties (the fit's and the twin's stated noise)
    /// `to` lies from `from`.
    pub standard_errors: f64,
    /// Whether the twin lacked the effect.
    pub added: bool,
    /// The user effect's file, for a user effect.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub defined_in: Option<String>,
}

/// A parameter the recording cannot determine, kept as the twin has it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Kept {
    /// Registry or user effect id.
    pub effect: String,
    /// Parameter name.
    pub parameter: String,
    /// The twin's value, kept (0 for an effect it lacked).
    pub value: f64,
    /// Its unit.
    pub unit: String,
}
