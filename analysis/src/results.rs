//! The results model: what `fit` produces from a recording and what every renderer
//! (text, JSON, Markdown, HTML) consumes. Serializes to `results.json`; the keys are a
//! stable interface documented in `docs/results.md`.

use crate::recording::{EnvironmentRecord, ProcedureRef};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// The format tag written in every results file.
pub const FORMAT: &str = "ratecal-results/1";

/// Everything the analysis found about one recording (or several, for repeatability).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Results {
    /// `ratecal-results/1`.
    pub format: String,
    /// The run's verdict over every check it can decide (`pass`, `fail`, `incomplete`,
    /// `aborted`, `not_judged`); an older results file without one reads as `incomplete`.
    #[serde(default)]
    pub verdict: RunVerdict,
    /// Why the verdict is what it is, when the checks alone do not say it: the failed
    /// sanity checks (`incomplete`: not fit for judgment) or why nothing was judged
    /// (`not_judged`). The terminal and the report print this sentence.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub verdict_reason: Option<String>,
    /// The sanity checks (what physics guarantees of any recording), one entry per check,
    /// always all of them; a failed one makes the verdict `incomplete`.
    #[serde(default)]
    pub sanity: Vec<SanityCheck>,
    /// Parameters by dotted name (`accel.bias.x`, `gyro.scale.z`, `accel.misalignment.xy`...).
    pub parameters: BTreeMap<String, Parameter>,
    /// Every acceptance threshold of the procedure, evaluated (or not evaluated, with why).
    pub acceptance: Vec<Acceptance>,
    /// Why each unobservable parameter is unobservable, by parameter name.
    #[serde(default)]
    pub observability: BTreeMap<String, String>,
    /// Which recording was analysed.
    pub recording: RecordingInfo,
    /// The model and fits that were applied.
    pub model: ModelInfo,
    /// Segments and what each was used for.
    #[serde(default)]
    pub segments: Vec<SegmentUse>,
    /// Synchronisation of the table feedback to the IMU stamps.
    pub sync: SyncReport,
    /// Residuals per segment and channel.
    #[serde(default)]
    pub residuals: Vec<ResidualStats>,
    /// Allan deviation of the long static block (plot-ready).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub allan: Option<AllanCurve>,
    /// Accuracy verification at points not used in the fit.
    #[serde(default)]
    pub verification: Vec<VerificationPoint>,
    /// Repeatability across runs (`analyze RUN1 RUN2 RUN3`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub repeatability: Option<Repeatability>,
    /// Lab conditions (manifest `environment` block and `ambient` column).
    pub environment: EnvironmentInfo,
    /// Everything the analysis could not do as asked, in plain words.
    #[serde(default)]
    pub warnings: Vec<String>,
    /// Joint fits with effects: their parameter keys in order and correlation matrix.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub fits: BTreeMap<String, JointFit>,
    /// The swaying segments' velocity drifts behind the `size_effect.*` parameters.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub size_effect: Option<SizeEffectDrifts>,
    /// A calibration without a table (poses of `nominal` or `unknown` attitude): its method,
    /// what the poses determine and how well the calibrated poses read gravity.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub manual: Option<ManualFit>,
    /// The GUM budget of every reported parameter (Type A from the fit, Type B from the
    /// station's stated figures), when the analysis was given the station's figures: the
    /// verdict, the report and the certificate state these `U` and `k`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub budgets: Vec<crate::budget::Budget>,
    /// Set when the run's procedure was a draft (`run --draft`): the manifest's
    /// `DRAFT PROCEDURE: ...` sentence, repeated for every reader of the results.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub draft_procedure: Option<String>,
}

/// How a recording without a table was calibrated (docs/results.md, `manual`).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ManualFit {
    /// `six_face` (nominal faces, Ferraris) or `multi_pose` (unknown attitudes, Tedaldi).
    pub method: String,
    /// The parameters the poses and turns determine (results.json keys).
    pub determined: Vec<String>,
    /// The convention that fixes what the poses cannot tell apart, when one applies.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub convention: Option<String>,
    /// The site's gravity the poses were fitted to, m/s^2.
    pub gravity_mps2: f64,
    /// Each pose's |specific force| before and after the calibration, m/s^2.
    pub poses: Vec<PoseGravity>,
    /// RMS of |specific force| - g over the poses, raw, m/s^2.
    pub gravity_rms_raw_mps2: f64,
    /// The same through the calibration, m/s^2.
    pub gravity_rms_calibrated_mps2: f64,
    /// Each turn between two poses: how far gravity's direction, carried through the turn
    /// by the gyros, lands from the direction measured after it (deg).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub turns: Vec<TurnMiss>,
    /// RMS of those angles with the nominal gyro model (scale 1, no cross-axis), deg.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub turn_rms_nominal_deg: Option<f64>,
    /// RMS of those angles with the calibrated gyros, deg.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub turn_rms_calibrated_deg: Option<f64>,
}

/// One pose's gravity reading.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PoseGravity {
    /// Segment id.
    pub segment: String,
    /// |mean specific force| as recorded, m/s^2.
    pub raw_mps2: f64,
    /// The same through the calibration, m/s^2.
    pub calibrated_mps2: f64,
}

/// One turn's miss of gravity's direction (deg), nominal and calibrated gyros.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TurnMiss {
    /// Segment id.
    pub segment: String,
    /// With the nominal gyro model, deg.
    pub nominal_deg: f64,
    /// With the calibrated gyros, deg.
    pub calibrated_deg: f64,
}

/// A joint fit's parameters (results.json keys, in order) and their correlation matrix.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct JointFit {
    /// The effects in the model.
    pub effects: Vec<String>,
    /// Parameter keys, in the matrix's order.
    pub parameters: Vec<String>,
    /// Correlation coefficients, square, in that order.
    pub correlation: Vec<Vec<f64>>,
}

/// The size-effect fit's evidence: each oscillation segment's fitted drift rates and its
/// navigation velocity (plot-ready).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct SizeEffectDrifts {
    /// One entry per oscillation segment used.
    pub segments: Vec<SegmentDriftReport>,
    /// One entry per cycle (navigation run): how well its periods cancelled the
    /// instrumental terms.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub cycles: Vec<SizeEffectCycle>,
    /// The segments the size effect could not use, and why.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub left_out: Vec<SegmentLeftOut>,
}

/// A segment of a `fit size_effect` left out of it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SegmentLeftOut {
    /// Segment id.
    pub segment: String,
    /// Why it was left out.
    pub reason: String,
}

/// One swaying cycle: its segments, the axis it held up, and the instrumental terms its
/// periods cancelled.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SizeEffectCycle {
    /// The static segment it aligned on.
    pub align: String,
    /// Its oscillation segments, in time order.
    pub segments: Vec<String>,
    /// The body axis nearest the sway axis (`x`, `y`, `z`) and its angle from it, deg.
    pub up_axis: String,
    /// Angle of the up axis from the sway axis, deg.
    pub up_axis_off_deg: f64,
    /// The shortest and longest period, s.
    pub periods_s: [f64; 2],
    /// East and North drift (mean acceleration error) at the shortest period less that at
    /// the longest, m/s^2: size effect, plus whatever the periods did not cancel.
    pub difference_mps2: [f64; 2],
    /// The part of that difference the size-effect coordinates explain, m/s^2.
    pub size_effect_mps2: [f64; 2],
    /// The part due to the tilt error growing between the two spans (measured at rest),
    /// m/s^2; subtracted before the coordinates.
    pub tilt_change_mps2: [f64; 2],
    /// What remains, m/s^2: against `u` it says how well the periods cancelled.
    pub residual_mps2: [f64; 2],
    /// Standard uncertainty of the difference, m/s^2.
    pub u_mps2: [f64; 2],
    /// The period-independent instrumental term while swaying, East and North, m/s^2,
    /// `[value, u]` each; absent when the cycle swayed at one period (then not cancelled).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub instrumental_mps2: Option<[[f64; 2]; 2]>,
    /// Growth of the tilt error times g while swaying, East and North, m/s^3.
    pub tilt_growth_mps3: [f64; 2],
    /// How many stretches at rest measured the tilt.
    pub rests: usize,
}

/// One oscillation segment of the size-effect fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SegmentDriftReport {
    /// Segment id.
    pub segment: String,
    /// Swaying period, s.
    pub period_s: f64,
    /// East velocity drift (mean acceleration error), m/s^2, and its u.
    pub east_mps2: [f64; 2],
    /// North velocity drift, m/s^2, and its u.
    pub north_mps2: [f64; 2],
    /// Navigation velocity at about 1 Hz: `[t s, East m/s, North m/s]`.
    pub velocity: Vec<[f64; 3]>,
    /// The cycle it belongs to (index into `cycles`).
    #[serde(default)]
    pub cycle: usize,
    /// The body axis nearest the sway axis: `x`, `y` or `z`.
    #[serde(default)]
    pub up_axis: String,
    /// Angle of the sway axis from the vertical, deg.
    #[serde(default)]
    pub sway_axis_tilt_deg: f64,
    /// Change of the East and North acceleration error over the span, m/s^3, `[value, u]`.
    #[serde(default)]
    pub trend_mps3: [[f64; 2]; 2],
    /// The instrumental part of its drift (constant and tilt), East and North, m/s^2.
    #[serde(default)]
    pub instrumental_mps2: [f64; 2],
    /// The size-effect part of its drift, East and North, m/s^2.
    #[serde(default)]
    pub size_effect_mps2: [f64; 2],
}

/// A parameter estimate, or the statement that the motion did not determine it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Parameter {
    /// A value with its standard uncertainty, in `unit`.
    Estimate {
        /// Value.
        value: f64,
        /// Standard uncertainty (k = 1).
        u: f64,
        /// Unit (`m/s^2`, `ppm`, `deg/s`, `mrad`...).
        unit: String,
    },
    /// `{ "upper_bound": 26.9, "unit": "deg/h", "why": "..." }`: the data bound the value from
    /// above and determine it no further (no value, no uncertainty is printed for it).
    UpperBound {
        /// The bound.
        upper_bound: f64,
        /// Unit.
        unit: String,
        /// Why only a bound.
        why: String,
    },
    /// `{ "observable": false, "needs": "..." }`.
    Unobservable {
        /// Always `false`.
        observable: bool,
        /// The motion that would determine it, when known.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        needs: Option<String>,
    },
}

impl Parameter {
    /// An estimate.
    pub fn estimate(value: f64, u: f64, unit: &str) -> Self {
        Parameter::Estimate {
            value,
            u,
            unit: unit.to_string(),
        }
    }

    /// `{ "observable": false }`.
    pub fn unobservable() -> Self {
        Parameter::Unobservable {
            observable: false,
            needs: None,
        }
    }

    /// `{ "observable": false, "needs": "..." }`.
    pub fn needs(motion: &str) -> Self {
        Parameter::Unobservable {
            observable: false,
            needs: Some(motion.to_string()),
        }
    }

    /// `(value, u)` of an estimate.
    pub fn value_u(&self) -> Option<(f64, f64)> {
        match self {
            Parameter::Estimate { value, u, .. } => Some((*value, *u)),
            Parameter::UpperBound { .. } | Parameter::Unobservable { .. } => None,
        }
    }

    /// Unit of an estimate.
    pub fn unit(&self) -> Option<&str> {
        match self {
            Parameter::Estimate { unit, .. } | Parameter::UpperBound { unit, .. } => Some(unit),
            Parameter::Unobservable { .. } => None,
        }
    }
}

/// Outcome of one acceptance check.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// Meets the limit (under the decision rule).
    Pass,
    /// Misses the limit.
    Fail,
    /// Guard band: the expanded uncertainty straddles the limit.
    Indeterminate,
    /// Could not be evaluated (see `reason`).
    NotEvaluated,
    /// Declared over several runs: decided by `ratecal analyze RUN1 RUN2 ...`, not by one run.
    Deferred,
}

impl Verdict {
    /// How the terminal shows it (a failure in capitals).
    pub fn label(self) -> &'static str {
        match self {
            Verdict::Pass => "pass",
            Verdict::Fail => "FAIL",
            Verdict::Indeterminate => "indeterminate",
            Verdict::NotEvaluated => "not evaluated",
            Verdict::Deferred => "deferred",
        }
    }
}

/// One sanity check: what physics guarantees of any recording (gravity at rest, the gyro
/// following the table, one clock, plausible fitted values), checked before the numbers
/// become a verdict. Names are stable (docs/results.md).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SanityCheck {
    /// The check's name (`gravity_magnitude_at_rest`, ...).
    pub check: String,
    /// Outcome.
    pub status: SanityStatus,
    /// What was found, where, against what tolerance, in plain words.
    pub detail: String,
}

impl SanityCheck {
    /// An entry.
    pub fn new(check: &str, status: SanityStatus, detail: impl Into<String>) -> Self {
        SanityCheck {
            check: check.to_string(),
            status,
            detail: detail.into(),
        }
    }
}

/// Outcome of a sanity check.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SanityStatus {
    /// Holds.
    Pass,
    /// Does not hold: the recording is not fit for judgment.
    Fail,
    /// The recording holds nothing to check it on (e.g. no rate segment).
    NotEvaluated,
}

impl SanityStatus {
    /// How the terminal shows it (a failure in capitals).
    pub fn label(self) -> &'static str {
        match self {
            SanityStatus::Pass => "pass",
            SanityStatus::Fail => "FAIL",
            SanityStatus::NotEvaluated => "not evaluated",
        }
    }
}

/// The verdict of a whole run (or of several runs analysed together).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RunVerdict {
    /// Every check this run can decide was evaluated and passed.
    Pass,
    /// A check failed.
    Fail,
    /// A check could not be evaluated or decided (missing data, guard band straddled).
    #[default]
    Incomplete,
    /// The run was aborted (or otherwise did not complete).
    Aborted,
    /// No acceptance check was evaluated (no procedure, a procedure without `accept`, or
    /// only checks decided over several runs): nothing to judge, never a pass.
    NotJudged,
}

impl RunVerdict {
    /// The word results.json holds (`pass`, `fail`, `incomplete`, `aborted`).
    pub fn as_str(self) -> &'static str {
        match self {
            RunVerdict::Pass => "pass",
            RunVerdict::Fail => "fail",
            RunVerdict::Incomplete => "incomplete",
            RunVerdict::Aborted => "aborted",
            RunVerdict::NotJudged => "not_judged",
        }
    }

    /// How the terminal shows it (`PASS`, `NOT JUDGED`, ...).
    pub fn label(self) -> String {
        self.as_str().replace('_', " ").to_uppercase()
    }
}

/// One evaluated acceptance threshold; `value`, `limit`, `margin` and `expanded_u` are in
/// `unit`, the unit the procedure wrote the limit in.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Acceptance {
    /// Human name (`accel.residual.std <= 0.002 g`).
    pub name: String,
    /// Quantity checked, dotted (`accel.residual.std`).
    pub quantity: String,
    /// Step that declared it, if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub step: Option<String>,
    /// Measured value (absent when not evaluated).
    pub value: Option<f64>,
    /// Comparison as written (`<=`, `<`, `>=`, `>`), or `within` for `within +-limit`.
    pub op: String,
    /// Limit.
    pub limit: f64,
    /// Unit as the procedure wrote it.
    pub unit: String,
    /// Distance to the limit, positive on the passing side.
    pub margin: Option<f64>,
    /// Expanded uncertainty of the value: `k` times its standard uncertainty (the full
    /// budget's for a calibrated parameter when the station states Type B figures).
    #[serde(rename = "U")]
    pub expanded_u: Option<f64>,
    /// The coverage factor of `U` (2 for the run's Type A uncertainty alone; Student's t
    /// of the budget's effective degrees of freedom otherwise).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub k: Option<f64>,
    /// `simple` or `guard_banded`.
    pub rule: String,
    /// Verdict.
    pub verdict: Verdict,
    /// Why it was not evaluated, or what the value means (e.g. std instead of CV).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
}

/// Identity of the analysed recording.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct RecordingInfo {
    /// Folders as given on the command line (several for repeatability).
    pub paths: Vec<String>,
    /// IMU description from the manifest.
    pub imu: BTreeMap<String, String>,
    /// Procedure that produced the recording (manifest block), if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub procedure: Option<ProcedureRef>,
    /// Run id (ratecal recordings only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub run_id: Option<String>,
    /// Station site latitude, deg.
    pub latitude_deg: f64,
    /// Station gravity, m/s^2.
    pub gravity_mps2: f64,
    /// IMU rows.
    pub imu_rows: usize,
    /// Table rows.
    pub table_rows: usize,
    /// IMU sample rate (median), Hz.
    pub imu_rate_hz: f64,
    /// Table feedback rate (median), Hz.
    pub table_rate_hz: f64,
    /// Time span of the IMU stream, s.
    pub duration_s: f64,
}

/// What model was fitted and from which procedure.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ModelInfo {
    /// Procedure used for the analysis (`--procedure` or the recording's), if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub procedure: Option<ProcedureRef>,
    /// `procedure` (fit statements) or `by_kind` (segment kinds, standard model).
    pub selection: String,
    /// Fits applied, e.g. `accel_bias_scale from accel_static/*`.
    pub fits: Vec<String>,
}

/// One segment and what the analysis did with it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SegmentUse {
    /// Segment id.
    pub id: String,
    /// `static`, `rate`, `oscillation`.
    pub kind: String,
    /// Start, s.
    pub t_start: f64,
    /// End, s.
    pub t_end: f64,
    /// IMU samples in the window.
    pub imu_samples: usize,
    /// Samples removed as outliers (any channel).
    pub outliers_removed: usize,
    /// Uses: `accel`, `gyro_bias`, `gyro_scale`, `gyro_full`, `allan`, `temperature`,
    /// `verification`; empty when unused.
    pub used_for: Vec<String>,
}

/// Synchronisation of the table feedback onto the IMU time stamps (linear interpolation).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct SyncReport {
    /// `linear_interpolation`.
    pub method: String,
    /// Median table feedback step, s.
    pub table_step_s: f64,
    /// Largest gap between the two table samples that bracket an IMU sample used, s.
    pub max_gap_s: f64,
    /// Largest distance from an IMU stamp to its nearest table sample, s: the time
    /// uncertainty of the interpolated reference.
    pub max_sync_error_s: f64,
    /// Largest interpolation error of the feedback angle, deg, bounded by
    /// `gap^2 / 8 * |angular acceleration|` (estimated from the feedback rates).
    pub max_angle_error_deg: f64,
}

impl SyncReport {
    /// Widens the largest gap and errors to cover `other`'s too.
    pub(crate) fn widen(&mut self, other: &SyncReport) {
        self.max_gap_s = self.max_gap_s.max(other.max_gap_s);
        self.max_sync_error_s = self.max_sync_error_s.max(other.max_sync_error_s);
        self.max_angle_error_deg = self.max_angle_error_deg.max(other.max_angle_error_deg);
    }
}

/// Residual statistics of one channel over one segment (observed minus model).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ResidualStats {
    /// Segment id.
    pub segment: String,
    /// `accel` or `gyro`.
    pub sensor: String,
    /// `x`, `y`, `z`.
    pub channel: String,
    /// Samples.
    pub n: usize,
    /// Mean, sensor unit.
    pub mean: f64,
    /// Standard deviation, sensor unit.
    pub std: f64,
    /// Linear trend, sensor unit per second.
    pub slope_per_s: f64,
    /// Sensor unit (`m/s^2`, `deg/s`).
    pub unit: String,
}

/// Overlapping Allan deviation of the gyros over the long static block.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AllanCurve {
    /// Segment analysed.
    pub segment: String,
    /// Averaging times, s (octaves).
    pub tau_s: Vec<f64>,
    /// Allan deviation per axis (x, y, z), deg/s, one entry per tau.
    pub adev_dps: [Vec<f64>; 3],
}

/// Accuracy at one point not used in the fit: compensated output vs reference.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct VerificationPoint {
    /// Segment id.
    pub segment: String,
    /// `accel` or `gyro`.
    pub sensor: String,
    /// Largest per-axis error of the segment-mean compensated output, sensor unit.
    pub max_error: f64,
    /// Per-axis errors (x, y, z), sensor unit.
    pub error: [f64; 3],
    /// Standard uncertainty of the largest error, sensor unit.
    pub u: f64,
    /// Sensor unit.
    pub unit: String,
}

/// Repeatability across complete runs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Repeatability {
    /// Number of runs.
    pub runs: usize,
    /// Per parameter.
    pub parameters: Vec<RepeatParameter>,
}

/// Spread of one parameter across runs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RepeatParameter {
    /// Parameter name.
    pub name: String,
    /// Value in each run.
    pub values: Vec<f64>,
    /// Mean.
    pub mean: f64,
    /// Sample standard deviation.
    pub std: f64,
    /// Coefficient of variation std/|mean| (absent where meaningless).
    pub cv: Option<f64>,
    /// `cv`, or `std` for a near-zero parameter (a bias), where the CV is meaningless.
    pub measure: String,
    /// Parameter unit.
    pub unit: String,
}

/// Lab conditions during the recording.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct EnvironmentInfo {
    /// The manifest's `environment` block.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub recorded: Option<EnvironmentRecord>,
    /// Statistics of the `ambient` column, if present.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ambient: Option<AmbientStats>,
    /// IMU internal temperature range (not the lab's), degC.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub imu_temp_range_c: Option<[f64; 2]>,
}

/// Lab air temperature over the recording.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AmbientStats {
    /// Mean, degC.
    pub mean_c: f64,
    /// Minimum, degC.
    pub min_c: f64,
    /// Maximum, degC.
    pub max_c: f64,
    /// Linear drift, degC/h.
    pub drift_c_per_h: f64,
}

impl Results {
    /// Whether any acceptance check failed.
    pub fn has_failure(&self) -> bool {
        self.acceptance.iter().any(|a| a.verdict == Verdict::Fail)
    }

    /// The sanity checks that failed.
    pub fn sanity_failures(&self) -> impl Iterator<Item = &SanityCheck> {
        self.sanity
            .iter()
            .filter(|c| c.status == SanityStatus::Fail)
    }

    /// Sets `verdict` from the checks: `aborted` when the run did not complete, else
    /// `incomplete` on a failed sanity check (the recording is not fit for judgment), else
    /// `fail` on a failed acceptance check, `incomplete` on one not evaluated or undecided,
    /// `not_judged` when none was evaluated (none declared, or all deferred), else `pass`.
    pub fn decide(&mut self, aborted: bool) {
        let any = |v: Verdict| self.acceptance.iter().any(|a| a.verdict == v);
        self.verdict = if aborted {
            RunVerdict::Aborted
        } else if self.sanity_failures().next().is_some() {
            RunVerdict::Incomplete
        } else if any(Verdict::Fail) {
            RunVerdict::Fail
        } else if any(Verdict::NotEvaluated) || any(Verdict::Indeterminate) {
            RunVerdict::Incomplete
        } else if !any(Verdict::Pass) {
            RunVerdict::NotJudged
        } else {
            RunVerdict::Pass
        };
        self.verdict_reason = self.reason();
    }

    /// The sentence `verdict_reason` holds for the verdict decided.
    fn reason(&self) -> Option<String> {
        let failed: Vec<&str> = self.sanity_failures().map(|c| c.check.as_str()).collect();
        match self.verdict {
            RunVerdict::Incomplete if !failed.is_empty() => Some(format!(
                "the recording is not fit for judgment: sanity check{} {} failed",
                if failed.len() == 1 { "" } else { "s" },
                failed.join(", ")
            )),
            RunVerdict::NotJudged => Some(match &self.model.procedure {
                Some(p) if self.acceptance.is_empty() => format!(
                    "procedure {} {} declares no acceptance check: the results are measurements, not judged against any standard",
                    p.name, p.version
                ),
                Some(p) => format!(
                    "the checks of procedure {} {} are decided over several runs, none on this one: the results are measurements, not judged",
                    p.name, p.version
                ),
                None => "analysed without a procedure: no acceptance check applies; the results are measurements, not judged against any standard".into(),
            }),
            _ => None,
        }
    }

    /// An estimate by name: `(value, u)`.
    pub fn value(&self, name: &str) -> Option<(f64, f64)> {
        self.parameters.get(name).and_then(Parameter::value_u)
    }

    /// Pretty JSON text of `results.json`.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("results serialize")
    }

    /// Parses a `results.json` text.
    pub fn from_json(text: &str) -> Result<Self, serde_json::Error> {
        serde_json::from_str(text)
    }
}

/// Whether a recording's run ended other than `completed` (aborted, failed, or never
/// ended); a recording from another system, with no `run` block, counts as complete.
pub fn ended_early(manifest: &crate::recording::Manifest) -> bool {
    manifest
        .run
        .as_ref()
        .is_some_and(|r| r.status != "completed")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(verdict: Verdict) -> Acceptance {
        Acceptance {
            name: "q".into(),
            quantity: "q".into(),
            step: None,
            value: None,
            op: "<=".into(),
            limit: 1.0,
            unit: String::new(),
            margin: None,
            expanded_u: None,
            k: None,
            rule: "simple".into(),
            verdict,
            reason: None,
        }
    }

    #[test]
    fn run_verdict_follows_the_worst_check() {
        let mut r: Results = serde_json::from_value(serde_json::json!({
            "format": FORMAT, "parameters": {}, "acceptance": [], "recording": {
                "paths": [], "imu": {}, "latitude_deg": 0.0, "gravity_mps2": 9.8,
                "imu_rows": 0, "table_rows": 0, "imu_rate_hz": 0.0, "table_rate_hz": 0.0,
                "duration_s": 0.0 },
            "model": { "selection": "by_kind", "fits": [] }, "sync": {
                "method": "", "table_step_s": 0.0, "max_gap_s": 0.0, "max_sync_error_s": 0.0,
                "max_angle_error_deg": 0.0 },
            "environment": {}
        }))
        .unwrap();
        assert_eq!(
            r.verdict,
            RunVerdict::Incomplete,
            "no verdict recorded is no pass"
        );
        let cases = [
            (
                vec![Verdict::Pass, Verdict::Deferred],
                false,
                RunVerdict::Pass,
            ),
            (
                vec![Verdict::Pass, Verdict::NotEvaluated],
                false,
                RunVerdict::Incomplete,
            ),
            (vec![Verdict::Indeterminate], false, RunVerdict::Incomplete),
            (
                vec![Verdict::NotEvaluated, Verdict::Fail],
                false,
                RunVerdict::Fail,
            ),
            (vec![], false, RunVerdict::NotJudged),
            (vec![Verdict::Deferred], false, RunVerdict::NotJudged),
            (vec![Verdict::Pass], true, RunVerdict::Aborted),
        ];
        for (checks, aborted, want) in cases {
            r.acceptance = checks.iter().copied().map(check).collect();
            r.decide(aborted);
            assert_eq!(r.verdict, want, "{checks:?} aborted={aborted}");
        }
        assert!(r.to_json().contains("\"verdict\": \"aborted\""));
        // A failed sanity check is never a pass, whatever the acceptance says.
        r.acceptance = vec![check(Verdict::Pass)];
        r.sanity = vec![SanityCheck::new(
            "gravity_magnitude_at_rest",
            SanityStatus::Fail,
            "1.0 m/s^2",
        )];
        r.decide(false);
        assert_eq!(r.verdict, RunVerdict::Incomplete);
        assert!(r.to_json().contains("\"status\": \"fail\""));
    }

    #[test]
    fn parameter_shapes() {
        let p = Parameter::estimate(0.021, 2e-5, "m/s^2");
        assert_eq!(
            serde_json::to_string(&p).unwrap(),
            r#"{"value":0.021,"u":0.00002,"unit":"m/s^2"}"#
        );
        let q = Parameter::unobservable();
        assert_eq!(
            serde_json::to_string(&q).unwrap(),
            r#"{"observable":false}"#
        );
        let back: Parameter = serde_json::from_str(r#"{"observable":false}"#).unwrap();
        assert_eq!(back, q);
    }
}
