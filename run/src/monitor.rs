//! Abort rules on live data, sample by sample, with their persistence: a rule fires when
//! its condition has held continuously for `persistence_s` of stream time.

use super::live::{ImuRow, Source, TableRow, channels};
use ratecal_plan::{AbortAction, AbortCondition, AbortRule, Signal};

/// A rule that fired.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Fire {
    pub rule: String,
    pub action: AbortAction,
    pub t: f64,
    pub values: String,
}

#[derive(Debug)]
struct RuleState {
    rule: AbortRule,
    since: Option<f64>,
    warned: bool,
    baseline: Option<Vec<f64>>,
    prev: Option<[f64; 6]>,
}

impl RuleState {
    fn new(rule: &AbortRule) -> Self {
        RuleState {
            rule: rule.clone(),
            since: None,
            warned: false,
            baseline: None,
            prev: None,
        }
    }

    fn source(&self) -> Source {
        match &self.rule.condition {
            AbortCondition::Above { signal, .. }
            | AbortCondition::Outside { signal, .. }
            | AbortCondition::Drifts { signal, .. } => channels(*signal).0,
            AbortCondition::ImuAbnormal => Source::Imu,
        }
    }

    /// Whether the condition holds on this sample; `v` is the sample's full signal row.
    fn holds(&mut self, v: &[f64], ranges: (f64, f64)) -> bool {
        match &self.rule.condition {
            AbortCondition::Above { signal, limit } => {
                let abs = matches!(signal, Signal::Accel | Signal::Gyro);
                v[channels(*signal).1]
                    .iter()
                    .any(|&x| if abs { x.abs() > *limit } else { x > *limit })
            }
            AbortCondition::Outside { signal, lo, hi } => {
                v[channels(*signal).1].iter().any(|&x| x < *lo || x > *hi)
            }
            AbortCondition::Drifts { signal, limit } => {
                let now = &v[channels(*signal).1];
                if now.iter().any(|x| x.is_nan()) {
                    return false;
                }
                let base = self.baseline.get_or_insert_with(|| now.to_vec());
                now.iter()
                    .zip(base.iter())
                    .any(|(x, b)| (x - b).abs() > *limit)
            }
            AbortCondition::ImuAbnormal => {
                let six: [f64; 6] = [v[0], v[1], v[2], v[3], v[4], v[5]];
                let stuck = self.prev == Some(six);
                self.prev = Some(six);
                let (ar, gr) = ranges;
                stuck
                    || six.iter().any(|x| !x.is_finite())
                    || (ar > 0.0 && six[..3].iter().any(|x| x.abs() > ar))
                    || (gr > 0.0 && six[3..].iter().any(|x| x.abs() > gr))
            }
        }
    }

    /// A signal's name with the unit the rule's limit was written in, and its values
    /// converted to that unit (to five significant digits, as a limit is written).
    fn shown(&self, signal: Signal, values: &[f64]) -> String {
        let (name, internal) = signal_parts(signal);
        let (unit, conv): (&str, Vec<f64>) = match self.rule.in_written_unit(1.0) {
            Some((k, unit)) => (unit, values.iter().map(|x| x * k).collect()),
            None => (internal, values.to_vec()),
        };
        let list: Vec<String> = conv.iter().map(|x| significant(*x, 5)).collect();
        format!("{name} ({unit}) = [{}]", list.join(", "))
    }

    fn describe(&self, v: &[f64]) -> String {
        match &self.rule.condition {
            AbortCondition::Above { signal, .. } | AbortCondition::Outside { signal, .. } => {
                self.shown(*signal, &v[channels(*signal).1])
            }
            AbortCondition::Drifts { signal, .. } => {
                let base = self.baseline.as_deref().unwrap_or(&[]);
                let at_start = self.shown(*signal, base);
                let at_start = at_start.split_once(" = ").map_or("", |x| x.1);
                format!(
                    "{}, at scope start {at_start}",
                    self.shown(*signal, &v[channels(*signal).1])
                )
            }
            AbortCondition::ImuAbnormal => {
                format!("accel = {:?} m/s^2, gyro = {:?} deg/s", &v[0..3], &v[3..6])
            }
        }
    }

    fn step(&mut self, t: f64, v: &[f64], ranges: (f64, f64), out: &mut Vec<Fire>) {
        if !self.holds(v, ranges) {
            self.since = None;
            self.warned = false;
            return;
        }
        let since = *self.since.get_or_insert(t);
        if t - since + 1e-9 >= self.rule.persistence_s && !self.warned {
            out.push(Fire {
                rule: self.rule.text.clone(),
                action: self.rule.action,
                t,
                values: format!(
                    "{} (held {:.3} s from t = {since:.3} s)",
                    self.describe(v),
                    t - since
                ),
            });
            self.warned = true;
        }
    }
}

/// Name of a signal and its internal unit, for messages.
fn signal_parts(s: Signal) -> (&'static str, &'static str) {
    match s {
        Signal::Accel => ("imu.accel", "m/s^2"),
        Signal::Gyro => ("imu.gyro", "deg/s"),
        Signal::AttitudeError => ("table.attitude_error", "deg"),
        Signal::RateError => ("table.rate_error", "deg/s"),
        Signal::AmbientTemperature => ("ambient.temperature", "degC"),
        Signal::AmbientDrift => ("ambient.drift", "degC/h"),
        Signal::ImuTemperature => ("imu.temperature", "degC"),
    }
}

/// `x` to `digits` significant digits (`307851.6` -> `307850`, `0.000123456` -> `0.00012346`).
fn significant(x: f64, digits: i32) -> String {
    if !x.is_finite() || x == 0.0 {
        return format!("{x}");
    }
    let magnitude = x.abs().log10().floor() as i32;
    let decimals = (digits - 1 - magnitude).clamp(0, 12) as usize;
    let scale = 10f64.powi(magnitude + 1 - digits);
    let rounded = if decimals == 0 {
        (x / scale).round() * scale
    } else {
        x
    };
    format!("{rounded:.decimals$}")
}

/// The rules in force: the run's, and the current step's.
#[derive(Debug)]
pub(crate) struct Monitor {
    global: Vec<RuleState>,
    step: Vec<RuleState>,
    ranges: (f64, f64),
}

impl Monitor {
    /// Rules of the whole run; `ranges` = (accel range m/s^2, gyro range deg/s), 0 = unknown.
    pub fn new(rules: &[AbortRule], ranges: (f64, f64)) -> Self {
        Monitor {
            global: rules.iter().map(RuleState::new).collect(),
            step: Vec::new(),
            ranges,
        }
    }

    /// A step starts: its rules come into force (drift baselines taken from now on).
    pub fn enter_step(&mut self, rules: &[AbortRule]) {
        self.step = rules.iter().map(RuleState::new).collect();
    }

    /// The step ended.
    pub fn leave_step(&mut self) {
        self.step.clear();
    }

    /// Checks the rules watching the IMU stream.
    pub fn on_imu(&mut self, row: &ImuRow, out: &mut Vec<Fire>) {
        let ranges = self.ranges;
        for r in self.global.iter_mut().chain(self.step.iter_mut()) {
            if r.source() == Source::Imu {
                r.step(row.t, &row.v, ranges, out);
            }
        }
    }

    /// Checks the rules watching the table stream; attitude and rate errors count only
    /// when `armed` (the table is meant to be on its command, not travelling to it).
    pub fn on_table(&mut self, row: &TableRow, armed: bool, out: &mut Vec<Fire>) {
        let ranges = self.ranges;
        let mut v = row.v;
        if !armed {
            v[0] = f64::NAN;
            v[1] = f64::NAN;
        }
        for r in self.global.iter_mut().chain(self.step.iter_mut()) {
            if r.source() == Source::Table {
                r.step(row.t, &v, ranges, out);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rule(condition: AbortCondition, persistence_s: f64) -> AbortRule {
        AbortRule {
            text: "r".into(),
            condition,
            persistence_s,
            action: AbortAction::Abort,
            unit: String::new(),
        }
    }

    fn table_row(t: f64, att: f64) -> TableRow {
        TableRow {
            t,
            v: [att, 0.0, 20.0, f64::NAN],
            reached: true,
        }
    }

    #[test]
    fn persistence_must_hold_continuously() {
        let limit = 5.0 / 3600.0;
        let mut m = Monitor::new(
            &[rule(
                AbortCondition::Above {
                    signal: Signal::AttitudeError,
                    limit,
                },
                1.0,
            )],
            (0.0, 0.0),
        );
        let mut out = Vec::new();
        // Above the limit for 0.9 s, a dip, then above again: fires 1 s after the dip only.
        for k in 0..=200 {
            let t = k as f64 * 0.02;
            let att = if (0.9..0.95).contains(&t) {
                0.0
            } else {
                2.0 * limit
            };
            m.on_table(&table_row(t, att), true, &mut out);
        }
        assert_eq!(out.len(), 1);
        assert!((out[0].t - 1.96).abs() < 1e-9, "{}", out[0].t);
    }

    #[test]
    fn values_are_stated_in_the_unit_of_the_limit() {
        let mut r = rule(
            AbortCondition::Above {
                signal: Signal::AttitudeError,
                limit: 5.0 / 3600.0,
            },
            0.0,
        );
        r.unit = "arcsec".into();
        let mut m = Monitor::new(&[r], (0.0, 0.0));
        let mut out = Vec::new();
        m.on_table(&table_row(11.0, 85.51434352570847), true, &mut out);
        assert_eq!(out.len(), 1);
        assert!(
            out[0]
                .values
                .starts_with("table.attitude_error (arcsec) = [307850]"),
            "{}",
            out[0].values
        );
        // A limit in the internal unit keeps it, rounded as a limit is written.
        let mut m = Monitor::new(
            &[rule(
                AbortCondition::Above {
                    signal: Signal::AttitudeError,
                    limit: 1.0,
                },
                0.0,
            )],
            (0.0, 0.0),
        );
        let mut out = Vec::new();
        m.on_table(&table_row(11.0, 85.51434352570847), true, &mut out);
        assert!(
            out[0]
                .values
                .starts_with("table.attitude_error (deg) = [85.514]"),
            "{}",
            out[0].values
        );
    }

    #[test]
    fn unarmed_errors_do_not_fire() {
        let mut m = Monitor::new(
            &[rule(
                AbortCondition::Above {
                    signal: Signal::AttitudeError,
                    limit: 0.001,
                },
                0.0,
            )],
            (0.0, 0.0),
        );
        let mut out = Vec::new();
        m.on_table(&table_row(0.0, 10.0), false, &mut out);
        assert!(out.is_empty());
        m.on_table(&table_row(0.1, 10.0), true, &mut out);
        assert_eq!(out.len(), 1);
    }

    #[test]
    fn stuck_imu_fires() {
        let mut m = Monitor::new(&[rule(AbortCondition::ImuAbnormal, 0.5)], (160.0, 400.0));
        let mut out = Vec::new();
        for k in 0..100 {
            let t = k as f64 * 0.01;
            m.on_imu(
                &ImuRow {
                    t,
                    v: [0.0, 0.0, 9.8, 0.1, 0.2, 0.3, f64::NAN],
                },
                &mut out,
            );
        }
        // Stuck from the second sample (t = 0.01): fires at t = 0.51.
        assert_eq!(out.len(), 1);
        assert!((out[0].t - 0.51).abs() < 1e-9);
    }
}
