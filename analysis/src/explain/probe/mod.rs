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

mod form;
pub(crate) mod range;

pub(crate) use form::{AXES, Form};

use crate::fit::joint::{Layout, SegAcc};
use ratecal_physics::effects::{Effect, Param, Partials, Sensor, Signals};

/// A probe: one form on each axis of one sensor.
#[derive(Debug)]
pub(crate) struct Probe {
    id: &'static str,
    pub(crate) sensor: Sensor,
    pub(crate) form: Form,
    params: &'static [Param],
}

impl Probe {
    /// The probe of `form` on `sensor`, its plausible range `max_abs` (the form's unit).
    fn new(sensor: Sensor, form: Form, max_abs: f64) -> &'static Probe {
        let id: &'static str = Box::leak(
            format!("probe:{}:{}", sensor.name(), form.expression(sensor, 0)).into_boxed_str(),
        );
        let params: Vec<Param> = (0..3)
            .map(|i| Param {
                name: AXES[i],
                unit: form.unit(sensor),
                channel: Some((sensor, i)),
                needs: form.needs(),
                max_abs,
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
        self.form.expression(self.sensor, i)
    }

    /// Whether the form is a function of time alone (a drift, decay or step of the bias).
    pub(crate) fn in_time(&self) -> bool {
        self.form.in_time()
    }

    /// What a term of this form is, in an engineer's words.
    pub(crate) fn reading(&self) -> &'static str {
        self.form.reading(self.sensor)
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
        let v = self.form.values(self.sensor, s);
        for (i, p) in out.iter_mut().enumerate() {
            *p = Partials::axis(self.sensor, i, v[i]);
        }
    }

    fn varies_at_rest(&self) -> bool {
        self.form.varies_at_rest()
    }
}

/// The decays' time constants: a geometric grid (ratio 1.5) from 30 s to half the
/// recording's span, so that a warm-up's time constant is located to a grid step and refined
/// by the profile of the misfit (`discover::tau`).
pub(crate) fn decay_grid(span_s: f64) -> Vec<f64> {
    let mut out = Vec::new();
    let mut tau: f64 = 30.0;
    while tau <= (0.5 * span_s).max(60.0) {
        out.push(tau.round());
        tau *= 1.5;
    }
    out
}

/// The sampled probes for a recording that begins at `t0` and spans `span_s` seconds, with
/// their plausible ranges times `grade` (`plausible::grade_scale`).
pub(crate) fn sampled(t0: f64, span_s: f64, grade: f64) -> Vec<&'static Probe> {
    let mut out: Vec<&'static Probe> = Vec::new();
    for sensor in [Sensor::Accel, Sensor::Gyro] {
        let mut forms = vec![
            Form::ForceSquare,
            Form::ForceProduct(0, 1),
            Form::ForceProduct(0, 2),
            Form::ForceProduct(1, 2),
            Form::ForceAbs,
            Form::Drift { t0 },
            Form::Drift2 { t0 },
            Form::ScaleDrift { t0 },
            Form::ThermalScale,
        ];
        if sensor == Sensor::Gyro {
            forms.extend([Form::RateAbs, Form::RateSquare, Form::RateCube]);
        } else {
            forms.extend([Form::ForceCube, Form::ForceRateSquare]);
        }
        forms.extend(
            decay_grid(span_s)
                .into_iter()
                .map(|tau| Form::Decay { t0, tau }),
        );
        let span_h = span_s / 3600.0;
        out.extend(
            forms
                .into_iter()
                .map(|f| Probe::new(sensor, f, grade * range::max_abs(f, sensor, span_h))),
        );
    }
    out
}

/// Adds derived step probes per sensor, a bias step and a scale-factor step (`g` the
/// site's gravity, for the bias step's scale; `grade` the ranges' factor), at every gap
/// between consecutive segments (the instant the middle of the gap), to the layout and
/// every segment's factor and blocks.
/// Returns the new effects' layout indices with their probes.
pub(crate) fn add_steps(
    layout: &mut Layout,
    accs: &mut [SegAcc],
    starts: &[(f64, f64)],
    turning: &[bool],
    g: f64,
    grade: f64,
) -> Vec<(usize, &'static Probe)> {
    let mut order: Vec<usize> = (0..accs.len()).collect();
    order.sort_by(|&a, &b| starts[a].0.total_cmp(&starts[b].0));
    // (instant, whether a gyro scale step is tried there: between two turning segments,
    // where the rate tests' passes meet; elsewhere it is a copy of one of these on the
    // gyros' inputs).
    let mut instants: Vec<(f64, bool)> = Vec::new();
    for w in order.windows(2) {
        let (end, next) = (starts[w[0]].1, starts[w[1]].0);
        if next > end {
            instants.push((0.5 * (end + next), turning[w[0]] && turning[w[1]]));
        }
    }
    let first = |id: &str| layout.index(id).map(|e| layout.first[e]);
    let (Some(ba), Some(bg), Some(sg)) =
        (first("accel_bias"), first("gyro_bias"), first("gyro_scale"))
    else {
        return Vec::new();
    };
    let mut added = Vec::new();
    let mut effects = layout.effects.clone();
    let mut push = |sensor: Sensor, form: Form, effects: &mut Vec<&'static dyn Effect>| {
        let p = Probe::new(sensor, form, grade * range::max_abs(form, sensor, 0.0));
        added.push((effects.len(), p));
        effects.push(p as &dyn Effect);
    };
    for &(at, scale) in &instants {
        push(Sensor::Accel, Form::Step { at }, &mut effects);
        push(Sensor::Gyro, Form::Step { at }, &mut effects);
        if scale {
            push(Sensor::Gyro, Form::ScaleStep { at }, &mut effects);
        }
    }
    let old = layout.clone();
    *layout = Layout::new(effects);
    for (i, acc) in accs.iter_mut().enumerate() {
        let t = starts[i].0;
        for c in 0..6 {
            // The channel's new columns in layout order: per instant the step (a copy of
            // the bias column of this channel's axis, in ug or deg/h), and on the gyros the
            // scale step where one is tried (a copy of the scale column, in ppm like it).
            let local = |gcol: usize| old.by_channel[c].iter().position(|&x| x == gcol);
            let (bias, unit) = if c < 3 {
                (local(ba + c), 1e-6 * g)
            } else {
                (local(bg + c - 3), 1.0 / 3600.0)
            };
            let mut cols = Vec::new();
            for &(at, scale) in &instants {
                cols.push((bias, unit, t > at));
                if scale && c >= 3 {
                    cols.push((local(sg + c - 3), 1.0, t > at));
                }
            }
            extend(acc, c, &old, layout, &cols);
        }
    }
    added
}

/// Extends segment `acc`'s factor and block sums on channel `c` (laid out as `old`) by the
/// new columns of `layout`, in order: each a copy of a source column (its local index in
/// the old factor) times a scale where the segment is after the column's instant, zero
/// before.
///
/// The result is not triangular: the copies sit above the diagonal (the source column's
/// rows) with a zero diagonal of their own, and `m^T m` is the Gram matrix of
/// `[X copies y]`, which is all a factor has to be.
fn extend(
    acc: &mut SegAcc,
    c: usize,
    old: &Layout,
    layout: &Layout,
    cols: &[(Option<usize>, f64, bool)],
) {
    let k_old = old.by_channel[c].len();
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
    for (j, &(src, scale, on)) in cols.iter().enumerate() {
        if let (true, Some(l)) = (on, src) {
            for row in 0..rows {
                m[(row, k_old + j)] = scale * r[(row, l)];
            }
        }
    }
    acc.r[c] = m;
    acc.blocks_changed();
    for b in &mut acc.blocks {
        for j in 0..cols.len() {
            let (src, scale, on) = cols[j];
            let v = match (on, src) {
                (true, Some(l)) => scale * b.sx[c][l],
                _ => 0.0,
            };
            b.sx[c].push(v);
        }
    }
}
