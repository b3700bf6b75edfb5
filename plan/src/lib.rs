//! The checked procedure: what `check` produces from the AST and what `run`, `fit`,
//! `render` and `diff` consume. Every quantity is resolved to the internal unit named in
//! its field (deg, deg/s, s, Hz, m/s^2, degC, ...); `Quantity` keeps the value as the
//! procedure wrote it, for reports and diffs.
//!
//! Loops over explicit lists (`for`) are expanded by the checker (it refuses a nest whose
//! expansion would exceed a limit); `repeat N` stays a node, so a large count costs
//! nothing to check.

pub mod derived;
pub mod versions;

use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

pub use ratecal_physics::units::Dim;

/// A value with its unit as written, and its value in the internal unit of its dimension.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Quantity {
    /// Value as written in the procedure.
    pub written: f64,
    /// Unit as written (`g`, `arcsec`, `deg/s`...), empty for a bare number.
    pub unit: String,
    /// Dimension.
    pub dim: Dim,
    /// Value in the internal unit of `dim`.
    pub value: f64,
}

/// The resolved procedure.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Plan {
    /// Procedure name (`imu-2d-standard`).
    pub name: String,
    /// Semantic version (`1.0.0`).
    pub version: String,
    /// Title.
    pub title: String,
    /// References (standards).
    pub references: Vec<String>,
    /// IMU class the procedure is meant for (`tactical`, `navigation`, `consumer`...).
    pub imu_class: Option<String>,
    /// Free metadata.
    pub meta: BTreeMap<String, String>,
    /// Station requirements, by name (`table.position_accuracy`, `imu.warm_up`...).
    pub requirements: Vec<Requirement>,
    /// Environment preconditions.
    pub environment: Vec<EnvCondition>,
    /// Abort rules that hold for the whole run.
    pub aborts: Vec<AbortRule>,
    /// Steps in order.
    pub steps: Vec<Step>,
    /// Fit statements, in procedure order (each names the step that declared it).
    pub fits: Vec<FitSpec>,
    /// Acceptance thresholds, in procedure order.
    pub accepts: Vec<Accept>,
    /// Verification points (attitudes or rates not used in the fit) and their limits.
    pub verifications: Vec<Verification>,
    /// Estimated duration of the whole procedure, s.
    pub estimated_duration_s: f64,
}

/// A station or IMU requirement (`position accuracy <= 10 arcsec`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Requirement {
    /// Dotted name: `table.position_accuracy`, `table.perpendicularity`,
    /// `table.rate_stability`, `imu.warm_up`...
    pub name: String,
    /// Comparison.
    pub op: Cmp,
    /// Limit.
    pub limit: Quantity,
}

/// An environment precondition.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EnvCondition {
    /// `temperature`, `temperature_drift`, `humidity`, `pressure`, `vibration`.
    pub name: String,
    /// Allowed band, inclusive; an open side is `None`.
    pub min: Option<Quantity>,
    /// Upper end of the band.
    pub max: Option<Quantity>,
}

/// Comparison operator of a threshold.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Cmp {
    /// `<=`
    Le,
    /// `<`
    Lt,
    /// `>=`
    Ge,
    /// `>`
    Gt,
}

/// Table axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Axis {
    /// The outer axis (pitch on the seed station).
    Outer,
    /// The inner axis (roll on the seed station).
    Inner,
}

/// A step of the procedure.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Step {
    /// Step name (unique).
    pub name: String,
    /// Human title.
    pub title: Option<String>,
    /// Abort rules scoped to this step.
    pub aborts: Vec<AbortRule>,
    /// Body.
    pub body: Vec<Node>,
    /// Estimated duration of the step, s.
    pub estimated_duration_s: f64,
}

/// A node of a step's body.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Node {
    /// One action.
    Do(Action),
    /// `repeat N`: the body `count` times; `var` (if named) is the 1-based index, usable as
    /// `{var}` in segment names.
    Repeat {
        /// Repetition count.
        count: u64,
        /// Index variable name.
        var: Option<String>,
        /// Body.
        body: Vec<Node>,
    },
}

/// A concrete action on the station.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Action {
    /// Move both axes to angles (pitch/roll are resolved to outer/inner by the checker:
    /// pitch = outer, roll = inner on the seed geometry).
    MoveTo {
        /// Outer angle, deg.
        outer_deg: f64,
        /// Inner angle, deg.
        inner_deg: f64,
    },
    /// Spin an axis at a constant rate (0 holds it still in rate mode).
    Spin {
        /// Axis.
        axis: Axis,
        /// Rate, deg/s.
        rate_dps: f64,
    },
    /// Stop an axis (or both) and hold position.
    Stop {
        /// Axis; `None` stops both.
        axis: Option<Axis>,
    },
    /// Sinusoidal oscillation `center + amplitude sin(2 pi t / period)`.
    Oscillate {
        /// Axis.
        axis: Axis,
        /// Amplitude, deg.
        amplitude_deg: f64,
        /// Period, s.
        period_s: f64,
        /// Centre angle, deg (`None`: the current angle).
        center_deg: Option<f64>,
        /// How long, s (the motion continues until the next motion command).
        duration_s: f64,
    },
    /// Hold (wait) for a time, recording continuously.
    Hold {
        /// Duration, s.
        duration_s: f64,
    },
    /// Wait until the settle conditions hold.
    Settle(Settle),
    /// Record a named segment.
    Acquire(Acquire),
    /// The operator remounts the IMU (mount rotation `C_PB`, row-major) and confirms.
    Remount {
        /// New `C_PB`, row-major.
        rotation: [[f64; 3]; 3],
        /// What the operator is told.
        message: String,
    },
    /// Manual station: the operator places the unit and keeps it still; the next settle
    /// waits for the IMU's rest and checks the pose.
    Place(Pose),
    /// Manual station: the operator turns the unit by hand; recorded as a `turn` segment
    /// from the end of the last pose to the rest the next settle finds.
    Turn(HandTurn),
}

/// A pose the operator is asked for.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Pose {
    /// The body axis brought up (`+x`, `-z`); `None`: a free, hand-held pose.
    pub up: Option<String>,
    /// How far gravity may be from that axis, deg (`None` for a free pose).
    pub tolerance_deg: Option<f64>,
    /// What the operator is told.
    pub message: String,
}

/// A hand turn the operator is asked for.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HandTurn {
    /// Segment id template of the turn.
    pub segment: String,
    /// The body axis turned about (`+x`); `None`: a free turn.
    pub axis: Option<String>,
    /// Nominal angle about `axis`, deg.
    pub angle_deg: Option<f64>,
    /// What the operator is told.
    pub message: String,
}

/// Settle conditions, all of which must hold at once.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Settle {
    /// Minimum time before the conditions are tested, s.
    pub min_time_s: f64,
    /// Signal stability conditions.
    pub stable: Vec<Stability>,
    /// Table attitude error limit (feedback vs command), deg.
    pub attitude_error_deg: Option<f64>,
    /// Table rate error limit, deg/s.
    pub rate_error_dps: Option<f64>,
    /// Give up after this long, s.
    pub timeout_s: Option<f64>,
    /// What happens on timeout.
    pub on_timeout: OnTimeout,
}

/// `accel fluctuation <= 0.001 g over 5 s`: peak-to-peak of a signal over a window.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Stability {
    /// Signal.
    pub signal: Signal,
    /// Largest allowed peak-to-peak (per channel), in the signal's internal unit.
    pub max_fluctuation: f64,
    /// Window, s.
    pub window_s: f64,
}

/// What a settle timeout does.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum OnTimeout {
    /// Abort the run (safe state, exit 4).
    Abort,
    /// Log a warning and go on.
    Warn,
    /// Go on silently (journal only).
    Continue,
}

/// A recorded segment.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Acquire {
    /// Segment id template; `{var}` names a `repeat` index.
    pub segment: String,
    /// Channels requested (`accel`, `gyro`, `table`, `temp`); streams are recorded whole anyway.
    pub channels: Vec<String>,
    /// Duration, s.
    pub duration_s: f64,
    /// Sample rate asked, Hz.
    pub rate_hz: f64,
}

/// Live signals that settle and abort rules watch.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Signal {
    /// Accelerometer outputs (m/s^2).
    Accel,
    /// Gyro outputs (deg/s).
    Gyro,
    /// Table attitude error, feedback vs command (deg).
    AttitudeError,
    /// Table rate error, feedback vs command (deg/s).
    RateError,
    /// Lab air temperature (degC).
    AmbientTemperature,
    /// Lab temperature drift (degC/h).
    AmbientDrift,
    /// IMU internal temperature (degC).
    ImuTemperature,
}

/// An abort rule: a condition on a live signal that persists.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AbortRule {
    /// The rule as the procedure wrote it (for journals, reports and diffs).
    pub text: String,
    /// Condition.
    pub condition: AbortCondition,
    /// How long the condition must hold before the rule fires, s.
    pub persistence_s: f64,
    /// What to do.
    pub action: AbortAction,
    /// The unit its limit was written in (`arcsec`): messages state the live value in it.
    /// Empty: the signal's internal unit.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub unit: String,
}

impl AbortRule {
    /// A live value of the rule's signal (internal unit) in the unit its limit was written
    /// in, and that unit; `None` when it was written in the internal unit or in one that
    /// is not a plain multiple of it (`K` against degC).
    pub fn in_written_unit(&self, internal: f64) -> Option<(f64, &str)> {
        if self.unit.is_empty() {
            return None;
        }
        let (_, one) = ratecal_physics::units::to_internal(1.0, &self.unit)?;
        let (_, zero) = ratecal_physics::units::to_internal(0.0, &self.unit)?;
        if zero != 0.0 || one == 0.0 || one == 1.0 {
            return None;
        }
        Some((internal / one, &self.unit))
    }
}

/// Conditions an abort rule can watch.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum AbortCondition {
    /// `signal > limit` (absolute value per channel for vector signals).
    Above {
        /// Signal.
        signal: Signal,
        /// Limit in the signal's internal unit.
        limit: f64,
    },
    /// `signal outside lo .. hi`.
    Outside {
        /// Signal.
        signal: Signal,
        /// Lower bound.
        lo: f64,
        /// Upper bound.
        hi: f64,
    },
    /// Signal drifts more than `limit` from its value when the scope started.
    Drifts {
        /// Signal.
        signal: Signal,
        /// Limit in the signal's internal unit.
        limit: f64,
    },
    /// IMU output out of its range (station), NaN, or stuck (identical samples).
    ImuAbnormal,
}

/// What an abort rule does when it fires.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AbortAction {
    /// Safe state, run marked aborted, exit 4.
    Abort,
    /// Journal a warning and go on.
    Warn,
}

/// Error model a fit statement asks for.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FitModel {
    /// Seed model, accelerometers: per axis `a = K (a_ref + b)`.
    AccelBiasScale,
    /// Full accelerometer model: 3x3 `K_a` and `b_a`.
    AccelFull,
    /// Gyro static bias (mean after outlier removal) and noise.
    GyroBias,
    /// Gyro scale per axis from rate points, bias fixed from another fit.
    GyroScale,
    /// Full gyro model: 3x3 `K_g` and `b_g`.
    GyroFull,
    /// Temperature compensation of biases across temperature points.
    TempCompensation,
    /// Allan deviation of a static block.
    Allan,
    /// Size effect (lever arms) from oscillation segments.
    SizeEffect,
}

/// Outlier rule.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Outliers {
    /// Remove samples beyond k standard deviations of the segment's mean.
    Sigma(f64),
    /// Grubbs' test at significance `alpha`.
    Grubbs(f64),
}

/// A fit statement.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FitSpec {
    /// Step that declared it.
    pub step: String,
    /// Model.
    pub model: FitModel,
    /// Body axes the fit declares (0 = x, 1 = y, 2 = z); all three unless the procedure says.
    pub axes: Vec<usize>,
    /// Segment patterns (`accel_static/*`): `*` matches any run of characters.
    pub segments: Vec<String>,
    /// Outlier rule.
    pub outliers: Option<Outliers>,
    /// Butterworth low-pass: (order, cutoff Hz).
    pub lowpass: Option<(u32, f64)>,
    /// `using gyro_bias`: segment (or fit step) whose result is held fixed.
    pub using: Option<String>,
    /// `with lever_arm, ...`: catalogue effects (registry ids) added to the model.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub effects: Vec<String>,
}

/// Decision rule of an acceptance check.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DecisionRule {
    /// Pass when the value meets the limit.
    Simple,
    /// Pass only when value plus expanded uncertainty meets the limit; fail when value
    /// minus it misses; indeterminate between.
    GuardBanded,
}

/// An acceptance threshold.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Accept {
    /// Step that declared it (`None` at procedure level).
    pub step: Option<String>,
    /// Quantity checked, dotted (`accel.residual.std`, `gyro.residual.std`,
    /// `repeatability.cv`, `accel.error`, `gyro.error`, `gyro.bias.std`, `accel.bias.x`...),
    /// or a derived quantity of the fitted parameters (`abs(gyro.scale.x)`,
    /// `norm(accel.bias)`, `norm(accel.misalignment.x)`).
    pub quantity: String,
    /// Comparison.
    pub op: Cmp,
    /// Limit.
    pub limit: Quantity,
    /// `over N runs` for repeatability.
    pub over_runs: Option<u32>,
    /// Decision rule.
    pub rule: DecisionRule,
    /// `within +-limit`: the value must lie between `-limit` and `+limit` (`op` is `Le`,
    /// on the value's magnitude).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub within: bool,
}

/// A verification point and its limits.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Verification {
    /// What the point is.
    pub point: VerifyPoint,
    /// Limits (`accel.error <= 0.01 g`).
    pub limits: Vec<Accept>,
    /// Segment patterns that record the point (`verify/attitude`), possibly empty.
    #[serde(default)]
    pub segments: Vec<String>,
}

/// A point not used in the fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum VerifyPoint {
    /// A static attitude (outer/inner, deg).
    Attitude {
        /// Outer angle, deg.
        outer_deg: f64,
        /// Inner angle, deg.
        inner_deg: f64,
    },
    /// A rate about an axis, deg/s.
    Rate {
        /// Axis.
        axis: Axis,
        /// Rate, deg/s.
        rate_dps: f64,
    },
}

impl Plan {
    /// Segment-id templates of every acquisition, in order.
    pub fn segment_templates(&self) -> Vec<&str> {
        fn walk<'a>(nodes: &'a [Node], out: &mut Vec<&'a str>) {
            for n in nodes {
                match n {
                    Node::Do(Action::Acquire(a)) => out.push(&a.segment),
                    Node::Do(_) => {}
                    Node::Repeat { body, .. } => walk(body, out),
                }
            }
        }
        let mut out = Vec::new();
        for s in &self.steps {
            walk(&s.body, &mut out);
        }
        out
    }
}

/// Whether a segment id matches a fit pattern (`*` matches any run of characters).
pub fn segment_matches(pattern: &str, id: &str) -> bool {
    fn go(p: &[u8], s: &[u8]) -> bool {
        match p.split_first() {
            None => s.is_empty(),
            Some((b'*', rest)) => (0..=s.len()).any(|k| go(rest, &s[k..])),
            Some((c, rest)) => s.first() == Some(c) && go(rest, &s[1..]),
        }
    }
    go(pattern.as_bytes(), id.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::segment_matches;

    #[test]
    fn patterns() {
        assert!(segment_matches("accel_static/*", "accel_static/4"));
        assert!(segment_matches("gyro_bias", "gyro_bias"));
        assert!(!segment_matches("gyro_bias", "gyro_bias/2"));
        assert!(segment_matches(
            "gyro_scale/*/+100",
            "gyro_scale/outer/+100"
        ));
        assert!(!segment_matches("accel_static/*", "gyro_scale/outer/+100"));
    }
}
