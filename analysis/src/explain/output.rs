//! What explain reports: the `ratecal-explain/1` JSON (docs/explain.md), and its text form.

use crate::results::Parameter;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// The format tag.
pub const FORMAT: &str = "ratecal-explain/1";

/// Residual RMS per sensor over every sample inside the segments considered.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Rms {
    /// Accelerometers, m/s^2.
    pub accel_mps2: f64,
    /// Gyros, deg/s.
    pub gyro_dps: f64,
}

/// The nominal model's figures.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Nominal {
    /// Which model: `seed` (the standard's) or the procedure's name and version.
    pub model: String,
    /// Its terms.
    pub terms: Vec<String>,
    /// RMS over every segment of the recording.
    pub rms: Rms,
    /// RMS over the segments held out of the selection's fits.
    pub holdout_rms: Rms,
}

/// Where an effect shows.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Located {
    /// Segment id.
    pub segment: String,
    /// Channel, `ax` ... `gz`.
    pub channel: String,
    /// Time span of the segment, s.
    pub t_start: f64,
    /// End of the span, s.
    pub t_end: f64,
    /// Residual RMS there before the effect was modelled.
    pub rms_before: f64,
    /// After.
    pub rms_after: f64,
    /// What the residual follows there.
    pub correlates_with: String,
    /// Whether the segment was held out of the fit.
    pub held_out: bool,
}

/// Residual RMS of one segment and channel before and after a finding: the data of its
/// before/after figure, for every segment, not only where the finding shows.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SegmentRms {
    /// Segment id.
    pub segment: String,
    /// Channel, `ax` ... `gz`.
    pub channel: String,
    /// Residual RMS before the effect was modelled (m/s^2 or deg/s).
    pub rms_before: f64,
    /// After.
    pub rms_after: f64,
    /// Whether the segment was held out of the fit.
    pub held_out: bool,
}

/// Why explain believes a finding.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Evidence {
    /// Wald statistic of the effect's parameters (honest covariance).
    pub chi2: f64,
    /// Its degrees of freedom.
    pub dof: usize,
    /// Probability of a statistic this large without the effect.
    pub p_value: f64,
    /// The selection's threshold on `p_value` at that step.
    pub alpha: f64,
    /// Held-out residual RMS before and after adding the effect.
    pub holdout_rms_before: Rms,
    /// After.
    pub holdout_rms_after: Rms,
    /// Candidates the data cannot tell apart from this one (collinear parameters).
    pub not_separable_from: Vec<String>,
}

/// One effect the nominal model left out.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Finding {
    /// Canonical id.
    pub effect: String,
    /// In an engineer's words.
    pub explanation: String,
    /// Where it shows.
    pub located: Vec<Located>,
    /// Its parameters; an unobservable one always says what motion it needs.
    pub parameters: BTreeMap<String, Parameter>,
    /// The statistics.
    pub evidence: Evidence,
    /// RMS over every segment once this effect (and those before it) is modelled.
    pub rms_after: Rms,
    /// The file of a user effect (docs/user-effects.md); absent for the registry's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub defined_in: Option<String>,
    /// Residual RMS before and after, every segment and channel, in recording order.
    #[serde(default)]
    pub residuals: Vec<SegmentRms>,
    /// Effects that explain this recording as well (a tie by the selection criterion):
    /// the data cannot say which it is.
    #[serde(default)]
    pub alternatives: Vec<String>,
    /// With alternatives: the motion that would separate them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub separate_by: Option<String>,
    /// An error of the station (the table's encoders), not of the IMU.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub station_side: bool,
    /// Whether the form was discovered in the probe library rather than taken from the
    /// registry or an effect file.
    #[serde(default)]
    pub discovered: bool,
    /// A discovered finding's terms, one per channel, in the user-effect language.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub terms: Vec<Term>,
    /// Each alternative's own fit in this finding's place (the same model otherwise), so
    /// that an engineer sees both answers; an alternative whose fit lies outside its
    /// plausible range is in `refused` instead.
    #[serde(default)]
    pub alternative_fits: Vec<AlternativeFit>,
}

/// An alternative's own fit: its parameters as a finding's.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AlternativeFit {
    /// Its id.
    pub effect: String,
    /// Its parameters.
    pub parameters: BTreeMap<String, Parameter>,
}

/// A candidate this recording cannot determine, so explain did not fit it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NotObservable {
    /// The registry or user effect's id (`effect.parameter` when only some of its
    /// parameters fail), or a library form (`form_accel_fy_fz`, `.ax` for one channel).
    pub candidate: String,
    /// Why, in words.
    pub reason: String,
    /// The motion that would determine it.
    pub observed_by: String,
}

/// One term of a discovered finding: `channel += value * expression`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Term {
    /// Output channel (`ax` .. `gz`).
    pub channel: String,
    /// The regressor, in the user-effect expression language (docs/user-effects.md).
    pub expression: String,
    /// The coefficient.
    pub value: f64,
    /// Its standard uncertainty.
    pub u: f64,
    /// Its unit.
    pub unit: String,
    /// The motion that excites it.
    pub needs: String,
    /// Its plausible range for the IMU's grade (`|value| <= max_abs`, docs/effects.md).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_abs: Option<f64>,
}

/// One form a leftover follows.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Signature {
    /// The form, in the user-effect expression language (docs/user-effects.md).
    pub expression: String,
    /// Fraction of the channel's leftover it explains (0..1).
    pub share: f64,
    /// The channel it was measured on.
    pub channel: String,
    /// What a term of this form usually is, in an engineer's words.
    pub reading: String,
    /// Whether the form is a function of time (a drift, decay or step).
    pub in_time: bool,
}

/// A residual the final model leaves that is larger than the noise allows.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Unexplained {
    /// `accel` or `gyro`.
    pub sensor: String,
    /// The channels, `ax` ... `gz`.
    pub channels: Vec<String>,
    /// Where it shows most (segment ids).
    pub segments: Vec<String>,
    /// The smallest p-value of its tests, corrected for the multiplicity (Bonferroni over
    /// every test of the library, docs/explain.md).
    pub p_value: f64,
    /// Its size: the largest test statistic, in standard errors.
    pub standard_errors: f64,
    /// The forms it follows, best first.
    pub signature: Vec<Signature>,
    /// What it means, when explain knows more than the signature says.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

/// A candidate that was significant but not reported as a finding, and why.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RefusedOut {
    /// Its id.
    pub effect: String,
    /// Why.
    pub reason: String,
}

/// A user effect explain tried, and its file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct UserEffectOut {
    /// Its id.
    pub effect: String,
    /// The file that defines it.
    pub file: String,
}

/// The model with every finding.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Final {
    /// Terms.
    pub terms: Vec<String>,
    /// RMS over every segment.
    pub rms: Rms,
    /// RMS over the held-out segments.
    pub holdout_rms: Rms,
    /// Noise floor per sensor (white noise of the residuals), for comparison.
    pub noise_floor: Rms,
}

/// Everything explain says about a recording.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Explanation {
    /// `ratecal-explain/1`.
    pub format: String,
    /// The recording's folder.
    pub recording: String,
    /// The nominal model.
    pub nominal: Nominal,
    /// Segments the models were fitted to (those with samples and a known attitude or
    /// motion): none, and nothing was compared with a model (every figure is empty).
    #[serde(default)]
    pub segments_used: usize,
    /// Effects found, in the order they were selected.
    pub findings: Vec<Finding>,
    /// The final model.
    #[serde(rename = "final")]
    pub final_: Final,
    /// Segments held out of every fit.
    pub held_out: Vec<String>,
    /// Candidates tried and not reported, with their last p-value.
    pub rejected: BTreeMap<String, f64>,
    /// Candidates this recording cannot determine: not fitted (always present).
    #[serde(default)]
    pub not_observable: Vec<NotObservable>,
    /// Significant candidates not reported: outside the plausible range, or a form
    /// outside the registry explains their residual better.
    #[serde(default)]
    pub refused: Vec<RefusedOut>,
    /// What the final model leaves unexplained (empty when the recording is explained to
    /// its noise).
    #[serde(default)]
    pub unexplained: Vec<Unexplained>,
    /// How to adopt the findings: the registry effects to add to the procedure's fits.
    pub adopt: Option<String>,
    /// Registry effects found that the run's own procedure already holds (a run folder
    /// explained against the seed model): nothing to add for them.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub already_held: Vec<String>,
    /// With a procedure: the unified diff that adds them to its fit statements.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub adopt_diff: Option<String>,
    /// User effects tried besides the registry's.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub user_effects: Vec<UserEffectOut>,
    /// Draft effect files of the discovered findings (`effect`, `file`), once written.
    #[serde(default)]
    pub draft_effects: Vec<UserEffectOut>,
    /// What could not be done as asked.
    pub warnings: Vec<String>,
    /// With [`super::Options::profile`]: every candidate fitted beside the final model,
    /// what explain over several recordings pools (docs/explain.md, "Across recordings").
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub profile: Vec<super::profile::Fitted>,
}
