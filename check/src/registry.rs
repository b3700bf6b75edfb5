//! Which registry effects a procedure's motion lets explain determine (docs/explain.md,
//! "not_observable"): the same question explain asks of a recording, asked of the plan.
//!
//! Every recorded segment is sampled at its nominal motion (a static attitude; a constant
//! rate at twelve angles round the turn; an oscillation at its peaks and zero crossings),
//! each registry effect's regressors are evaluated there with `ratecal_physics` (the
//! analysis's own), and each parameter's column is projected out of the nominal model's
//! (a bias and a scale factor per channel) and the effect's earlier columns. A parameter is
//! determined when what is left, at the largest plausible value, is at least
//! [`SIGNAL_FLOOR`] in the output's unit: round-off (`f_y f_z` on six faces) is not.

use super::Ck;
use super::steps::SegInfo;
use nalgebra::DMatrix;
use ratecal_physics::effects::Partials;
use ratecal_physics::{Effect, REGISTRY, Signals, Site, TableState};
use ratecal_plan::Axis;

/// Least signal (m/s^2 or deg/s, RMS over the samples) a parameter at its plausible range
/// must leave once the nominal model has taken its share.
const SIGNAL_FLOOR: f64 = 1e-7;
/// Seconds between consecutive segments' samples: the time a drift or clock term reads.
const SEGMENT_SPACING_S: f64 = 60.0;

/// What the plan lets explain determine of one registry effect.
#[derive(Debug, Clone, PartialEq)]
pub struct EffectObservability {
    /// The effect's id.
    pub effect: &'static str,
    /// Parameters the motion determines.
    pub determined: Vec<&'static str>,
    /// Parameters it does not, each with the motion that would (`Param::needs`).
    pub not: Vec<(&'static str, &'static str)>,
}

/// Every registry effect that is not part of the nominal model, over the signals sampled
/// from the recorded segments ([`Ck::sample_signals`]).
pub(crate) fn observe(signals: &[Signals]) -> Vec<EffectObservability> {
    if signals.is_empty() {
        return Vec::new();
    }
    let nominal = nominal_columns(signals);
    REGISTRY
        .iter()
        .filter(|e| !e.nominal())
        .map(|e| observe_effect(*e, signals, &nominal))
        .collect()
}

impl Ck<'_> {
    /// The signals at the sampled instants of every segment.
    pub(crate) fn sample_signals(&self, segs: &[SegInfo]) -> Vec<Signals> {
        let site = Site {
            latitude_deg: 45.0,
            gravity_mps2: 9.80665,
        };
        let mut out = Vec::new();
        for (k, s) in segs.iter().enumerate() {
            let geo = self.geometry.with_mount(s.motion.mount);
            let t = k as f64 * SEGMENT_SPACING_S;
            for (j, state) in states(s).into_iter().enumerate() {
                let snap = state.snapshot(&geo, &site);
                out.push(Signals::new(&snap, &site, 0.0).at(t + j as f64));
            }
        }
        out
    }
}

/// The table states a segment's samples are taken at.
fn states(s: &SegInfo) -> Vec<TableState> {
    let m = &s.motion;
    let base = TableState::at_rest_deg(m.outer.unwrap_or(0.0), m.inner.unwrap_or(0.0));
    if let Some((ax, amp, period)) = m.osc {
        let w = 2.0 * std::f64::consts::PI / period;
        return (0..8)
            .map(|k| {
                let ph = k as f64 * std::f64::consts::PI / 4.0;
                let mut st = base;
                let a = match ax {
                    Axis::Outer => &mut st.outer,
                    Axis::Inner => &mut st.inner,
                };
                a.angle += (amp * ph.sin()).to_radians();
                a.rate = (amp * w * ph.cos()).to_radians();
                a.accel = -(amp * w * w * ph.sin()).to_radians();
                st
            })
            .collect();
    }
    if m.outer_rate == 0.0 && m.inner_rate == 0.0 {
        return vec![base];
    }
    (0..12)
        .map(|k| {
            let turn = (k as f64 * 30.0).to_radians();
            let mut st = base;
            st.outer.rate = m.outer_rate.to_radians();
            st.inner.rate = m.inner_rate.to_radians();
            if m.outer_rate != 0.0 {
                st.outer.angle += turn;
            }
            if m.inner_rate != 0.0 {
                st.inner.angle += turn;
            }
            st
        })
        .collect()
}

/// The nominal model's columns over (sample, channel) rows: a bias and a scale factor per
/// channel.
fn nominal_columns(signals: &[Signals]) -> Vec<Vec<f64>> {
    let n = signals.len();
    let mut cols = Vec::new();
    for c in 0..6 {
        let mut bias = vec![0.0; 6 * n];
        let mut scale = vec![0.0; 6 * n];
        for (i, s) in signals.iter().enumerate() {
            bias[6 * i + c] = 1.0;
            scale[6 * i + c] = if c < 3 { s.f_b[c] } else { s.w_ib_dps()[c - 3] };
        }
        cols.push(bias);
        cols.push(scale);
    }
    cols
}

/// One effect's parameters, each projected out of the nominal columns and the effect's
/// earlier ones.
fn observe_effect(
    e: &dyn Effect,
    signals: &[Signals],
    nominal: &[Vec<f64>],
) -> EffectObservability {
    let params = e.params();
    let n = signals.len();
    let mut cols: Vec<Vec<f64>> = vec![vec![0.0; 6 * n]; params.len()];
    let mut out = vec![Partials::default(); params.len()];
    for (i, s) in signals.iter().enumerate() {
        out.iter_mut().for_each(|p| *p = Partials::default());
        e.regressors(s, &mut out);
        for (k, p) in out.iter().enumerate() {
            for a in 0..3 {
                cols[k][6 * i + a] = p.accel[a];
                cols[k][6 * i + 3 + a] = p.gyro[a];
            }
        }
    }
    let mut held: Vec<Vec<f64>> = nominal.to_vec();
    let mut res = EffectObservability {
        effect: e.id(),
        determined: Vec::new(),
        not: Vec::new(),
    };
    for (k, p) in params.iter().enumerate() {
        let left = residual_rms(&held, &cols[k]);
        let max = if p.max_abs.is_finite() {
            p.max_abs
        } else {
            1.0
        };
        if left * max >= SIGNAL_FLOOR {
            res.determined.push(p.name);
            held.push(cols[k].clone());
        } else {
            res.not.push((p.name, p.needs));
        }
    }
    res
}

/// RMS over the rows of what `x` leaves after least squares on the columns `held`.
fn residual_rms(held: &[Vec<f64>], x: &[f64]) -> f64 {
    let rows = x.len();
    let a = DMatrix::from_fn(rows, held.len(), |r, c| held[c][r]);
    let b = nalgebra::DVector::from_column_slice(x);
    let fitted = a
        .clone()
        .svd(true, true)
        .solve(&b, 1e-12)
        .map(|coef| &a * coef)
        .unwrap_or_else(|_| nalgebra::DVector::zeros(rows));
    ((b - fitted).norm_squared() / rows.max(1) as f64).sqrt()
}
