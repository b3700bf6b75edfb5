//! The probe library: candidate forms that no registry effect or effect file holds, used to
//! say what a leftover residual follows (docs/explain.md, "unexplained"), and to keep a
//! registry effect from taking the credit for physics a probe explains better.
//!
//! A probe is one form per sensor axis (`f_b.x * f_b.z / g` on each accelerometer), written
//! in the user-effect expression language so that an engineer can paste it into an effect
//! file. Two kinds:
//! - *sampled* probes are effects of the layout, accumulated with the registry's columns
//!   (specific-force and rate forms, a linear drift, decays since the recording began);
//! - *steps* (a bias that jumps between two segments) are derived after accumulation: a
//!   segment's factor already holds the bias column, and a step is that column on the
//!   segments after the instant and zero before it, so every gap between segments is a
//!   candidate instant without a second pass over the samples ([`add_steps`]).

use crate::fit::joint::{Layout, SegAcc};
use ratecal_physics::effects::{Effect, Param, Partials, Sensor, Signals};

/// What a probe's regressor is, per axis `i` of its sensor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Form {
    /// `s_i^2` of the specific force (accel: `/ g`; gyro: `/ g^2`).
    ForceSquare,
    /// `f_j f_k` (the same pair on every axis).
    ForceProduct(usize, usize),
    /// `|f_i|` (accel: m/s^2; gyro: per g).
    ForceAbs,
    /// `|w_ib,i|`, deg/s.
    RateAbs,
    /// `w_ib,i^2` (deg/s)^2: even in the rate.
    RateSquare,
    /// `f_i |w_b|^2` (accel, (rad/s)^2): the specific force scaled by the rate squared,
    /// what a timing error leaves at second order (`-tau^2 w^2 f / 2`) or a scale that
    /// changes with the rate.
    ForceRateSquare,
    /// `(t - t0) / 3600`: a linear drift per hour.
    Drift { t0: f64 },
    /// `exp(-(t - t0) / tau)`: a decay since the recording began.
    Decay { t0: f64, tau: f64 },
    /// `1` after the instant, `0` before: a step (derived, never sampled).
    Step { at: f64 },
}

/// A probe: one form on each axis of one sensor.
#[derive(Debug)]
pub(crate) struct Probe {
    id: &'static str,
    pub(crate) sensor: Sensor,
    pub(crate) form: Form,
    params: &'static [Param],
}

const AXES: [&str; 3] = ["x", "y", "z"];

impl Probe {
    fn new(sensor: Sensor, form: Form) -> &'static Probe {
        let id: &'static str = Box::leak(
            format!(
                "probe:{}:{}",
                sensor.name(),
                Probe::expression_of(sensor, form, 0)
            )
            .into_boxed_str(),
        );
        let params: Vec<Param> = (0..3)
            .map(|i| Param {
                name: AXES[i],
                unit: "1",
                channel: Some((sensor, i)),
                needs: "",
                // A probe is a form, not physics: no range.
                max_abs: f64::INFINITY,
            })
            .collect();
        Box::leak(Box::new(Probe {
            id,
            sensor,
            form,
            params: Box::leak(params.into_boxed_slice()),
        }))
    }

    /// The form on axis `i`, in the user-effect expression language (docs/user-effects.md).
    pub(crate) fn expression(&self, i: usize) -> String {
        Probe::expression_of(self.sensor, self.form, i)
    }

    fn expression_of(sensor: Sensor, form: Form, i: usize) -> String {
        let a = AXES[i];
        let gyro = sensor == Sensor::Gyro;
        match form {
            Form::ForceSquare if gyro => format!("f_b.{a}^2 / g^2"),
            Form::ForceSquare => format!("f_b.{a}^2 / g"),
            Form::ForceProduct(j, k) if gyro => format!("f_b.{} * f_b.{} / g^2", AXES[j], AXES[k]),
            Form::ForceProduct(j, k) => format!("f_b.{} * f_b.{} / g", AXES[j], AXES[k]),
            Form::ForceAbs if gyro => format!("abs(f_b.{a}) / g"),
            Form::ForceAbs => format!("abs(f_b.{a})"),
            Form::RateAbs => format!("abs(w_ib.{a} / deg)"),
            Form::RateSquare => format!("(w_ib.{a} / deg)^2"),
            Form::ForceRateSquare => {
                format!("f_b.{a} * (w_b.x^2 + w_b.y^2 + w_b.z^2)")
            }
            Form::Drift { t0 } => format!("(t_s - {t0}) / 3600"),
            Form::Decay { t0, tau } => format!("exp(-(t_s - {t0}) / {tau})"),
            Form::Step { at } => format!("(sign(t_s - {at:.1}) + 1) / 2"),
        }
    }

    /// The regressor on axis `i`.
    fn value(&self, s: &Signals, i: usize) -> f64 {
        let gyro = self.sensor == Sensor::Gyro;
        let f = s.f_b;
        let w = s.w_ib_dps();
        let g = s.g;
        match self.form {
            Form::ForceSquare => f[i] * f[i] / if gyro { g * g } else { g },
            Form::ForceProduct(j, k) => f[j] * f[k] / if gyro { g * g } else { g },
            Form::ForceAbs => f[i].abs() / if gyro { g } else { 1.0 },
            Form::RateAbs => w[i].abs(),
            Form::RateSquare => w[i] * w[i],
            Form::ForceRateSquare => f[i] * s.w_b.norm_squared(),
            Form::Drift { t0 } => (s.t_s - t0) / 3600.0,
            Form::Decay { t0, tau } => (-(s.t_s - t0).max(0.0) / tau).exp(),
            // Derived from the bias column (add_steps): never evaluated per sample.
            Form::Step { .. } => 0.0,
        }
    }

    /// Whether the form is a function of time alone (a drift, decay or step of the bias).
    pub(crate) fn in_time(&self) -> bool {
        matches!(
            self.form,
            Form::Drift { .. } | Form::Decay { .. } | Form::Step { .. }
        )
    }

    /// What a term of this form is, in an engineer's words.
    pub(crate) fn reading(&self) -> &'static str {
        let gyro = self.sensor == Sensor::Gyro;
        match self.form {
            Form::ForceSquare if gyro => {
                "the gyro output grows with the square of the specific force: g^2 (anisoelastic) sensitivity"
            }
            Form::ForceSquare => {
                "output grows with the square of the specific force along its own axis: an even-order nonlinearity (IEEE 1293 K2)"
            }
            Form::ForceProduct(..) if gyro => {
                "the gyro output follows a product of two specific-force components: g^2 (anisoelastic) cross sensitivity"
            }
            Form::ForceProduct(..) => {
                "the output follows a product of two specific-force components: cross-axis nonlinearity (IEEE 1293 cross-coupling)"
            }
            Form::ForceAbs if gyro => {
                "the gyro output depends on the magnitude of the specific force, not its sign"
            }
            Form::ForceAbs => {
                "the output depends on the sign of the specific force: scale asymmetry (+g and -g differ)"
            }
            Form::RateAbs => "the output depends on the sign of the rate: scale asymmetry",
            Form::RateSquare => "the output grows with the square of the rate, whatever its sign",
            Form::ForceRateSquare => {
                "the output follows the specific force times the rate squared: a timing error's second order, or a scale that changes with the rate"
            }
            Form::Drift { .. } => "the bias drifts linearly with time",
            Form::Decay { .. } => "the bias decays with time since the recording began: warm-up",
            Form::Step { .. } => "the bias jumps between two segments: a bias step",
        }
    }
}

impl Effect for Probe {
    fn id(&self) -> &'static str {
        self.id
    }

    fn explanation(&self) -> &'static str {
        self.reading()
    }

    fn follows(&self) -> &'static str {
        "a form outside the registry"
    }

    fn params(&self) -> &'static [Param] {
        self.params
    }

    fn sensors(&self) -> &'static [Sensor] {
        self.sensor.only()
    }

    fn regressors(&self, s: &Signals, out: &mut [Partials]) {
        for (i, p) in out.iter_mut().enumerate() {
            *p = Partials::axis(self.sensor, i, self.value(s, i));
        }
    }
}

/// Time constants of the decays tried, s.
const DECAYS_S: [f64; 1] = [600.0];

/// The sampled probes for a recording that begins at `t0`.
pub(crate) fn sampled(t0: f64) -> Vec<&'static Probe> {
    let mut out: Vec<&'static Probe> = Vec::new();
    for sensor in [Sensor::Accel, Sensor::Gyro] {
        let mut forms = vec![
            Form::ForceSquare,
            Form::ForceProduct(0, 1),
            Form::ForceProduct(0, 2),
            Form::ForceProduct(1, 2),
            Form::ForceAbs,
            Form::Drift { t0 },
        ];
        if sensor == Sensor::Gyro {
            forms.extend([Form::RateAbs, Form::RateSquare]);
        } else {
            forms.push(Form::ForceRateSquare);
        }
        forms.extend(DECAYS_S.iter().map(|&tau| Form::Decay { t0, tau }));
        out.extend(forms.into_iter().map(|f| Probe::new(sensor, f)));
    }
    out
}

/// Adds a derived step probe per sensor at every gap between consecutive segments (its
/// instant the middle of the gap) to the layout and every segment's factor and blocks.
/// Returns the new effects' layout indices with their probes.
pub(crate) fn add_steps(
    layout: &mut Layout,
    accs: &mut [SegAcc],
    starts: &[(f64, f64)],
) -> Vec<(usize, &'static Probe)> {
    let mut order: Vec<usize> = (0..accs.len()).collect();
    order.sort_by(|&a, &b| starts[a].0.total_cmp(&starts[b].0));
    let mut instants = Vec::new();
    for w in order.windows(2) {
        let (end, next) = (starts[w[0]].1, starts[w[1]].0);
        if next > end {
            instants.push(0.5 * (end + next));
        }
    }
    let bias = |s: Sensor| {
        let id = match s {
            Sensor::Accel => "accel_bias",
            Sensor::Gyro => "gyro_bias",
        };
        layout.index(id).map(|e| layout.first[e])
    };
    let (Some(ba), Some(bg)) = (bias(Sensor::Accel), bias(Sensor::Gyro)) else {
        return Vec::new();
    };
    let mut added = Vec::new();
    let mut effects = layout.effects.clone();
    for &at in &instants {
        for sensor in [Sensor::Accel, Sensor::Gyro] {
            let p = Probe::new(sensor, Form::Step { at });
            added.push((effects.len(), p));
            effects.push(p as &dyn Effect);
        }
    }
    let old = layout.clone();
    *layout = Layout::new(effects);
    for (i, acc) in accs.iter_mut().enumerate() {
        let t = starts[i].0;
        for c in 0..6 {
            // Every sensor has a step at each instant, in order: the channel's new columns.
            // The bias column of this channel's own axis.
            let base = if c < 3 { ba + c } else { bg + c - 3 };
            let k_old = old.by_channel[c].len();
            let local_bias = old.by_channel[c].iter().position(|&g| g == base);
            let k_new = layout.by_channel[c].len();
            let r = &acc.r[c];
            let mut m = nalgebra::DMatrix::zeros(k_new + 1, k_new + 1);
            let rows = r.nrows().min(k_old + 1);
            for row in 0..rows {
                for col in 0..k_old {
                    m[(row, col)] = r[(row, col)];
                }
                m[(row, k_new)] = r[(row, k_old)];
            }
            for (j, at) in instants.iter().enumerate() {
                if t > *at
                    && let Some(lb) = local_bias
                {
                    for row in 0..rows {
                        m[(row, k_old + j)] = r[(row, lb)];
                    }
                }
            }
            // Still upper triangular: the copies sit above the diagonal (the bias column's
            // rows), their own diagonal is zero, and `m^T m` is the Gram matrix of
            // `[X steps y]`, which is all a factor has to be.
            acc.r[c] = m;
            for b in &mut acc.blocks {
                let bias_sum = local_bias.map_or(0.0, |lb| b.sx[c][lb]);
                for at in &instants {
                    b.sx[c].push(if t > *at { bias_sum } else { 0.0 });
                }
            }
        }
    }
    added
}

/// Probes most worth a full test beside `terms` over `segs`: each probe fitted with a
/// white-noise covariance (cheap), its Wald statistic per sensor, the `keep` strongest of
/// each sensor kept, strongest first.
pub(crate) fn screen(
    data: &super::data::Data,
    terms: &super::model::Terms,
    segs: &[usize],
    keep: usize,
) -> Vec<usize> {
    use rayon::prelude::*;
    let lay = &data.layout;
    let mut scored: Vec<(usize, Sensor, f64)> = data
        .probes
        .par_iter()
        .map(|&(e, p)| {
            let mut t = terms.clone();
            t.effects.push(e);
            let (f, _) = super::model::fit_with(data, &t, segs, segs, true);
            let cols: Vec<usize> = lay.columns_of(e).collect();
            (e, p.sensor, super::select::wald(&f, &cols).0)
        })
        .collect();
    scored.sort_by(|a, b| b.2.total_cmp(&a.2));
    let mut out = Vec::new();
    for sensor in [Sensor::Accel, Sensor::Gyro] {
        out.extend(
            scored
                .iter()
                .filter(|s| s.1 == sensor)
                .take(keep)
                .map(|s| s.0),
        );
    }
    out
}
