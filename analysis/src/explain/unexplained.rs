//! What remains unexplained once selection stops: the final model's residuals tested
//! against the honest noise model (white noise plus the wandering bias) for structure that
//! the probe library's forms pick up (specific-force and rate forms within and across
//! segments, drifts, decays and steps in time).
//!
//! Each probe is added alone to the final model, fitted on every segment, and each of its
//! columns (one per channel) is judged by a Wald test with the honest covariance. The
//! p-values are corrected for the number of tests by Bonferroni (docs/explain.md); a
//! sensor with any test under the threshold gets one entry, its signature the forms it
//! follows, each with the share of the leftover it explains.

use super::data::Data;
use super::model::{Terms, fit, misfit};
use super::output::{Signature, Unexplained};
use super::stats::p_value;
use crate::fit::joint::{CHANNELS, Fit, seg_rss};
use crate::recording::Manifest;
use ratecal_physics::effects::Sensor;

/// Most forms listed in a signature.
const MOST_FORMS: usize = 5;
/// Probes per sensor given the honest test after the white-noise screen.
const SCREEN: usize = 8;
/// Most segments listed.
const MOST_SEGMENTS: usize = 8;

/// One probe column's test.
struct Test {
    /// Probe layout index.
    probe: usize,
    /// Channel.
    c: usize,
    /// Wald statistic, 1 dof.
    chi2: f64,
    /// Fit with the probe.
    fit: usize,
}

/// Tests the final model `terms` for leftover structure; `base` is its fit on every
/// segment (explain has it already), `alpha` the family-wise threshold over every test.
pub(crate) fn leftover(
    m: &Manifest,
    data: &Data,
    terms: &Terms,
    base: &Fit,
    alpha: f64,
) -> Vec<Unexplained> {
    use rayon::prelude::*;
    let lay = &data.layout;
    let all: Vec<usize> = (0..data.accs.len()).collect();
    // Screened with white noise alone; the strongest of each sensor get the honest
    // covariance. The correction still counts every probe's every column.
    let short = super::select::screen(data, terms, &all, SCREEN);
    let fits: Vec<Fit> = short
        .par_iter()
        .map(|&e| {
            let mut t = terms.clone();
            t.effects.push(e);
            fit(data, &t, &all, &all).0
        })
        .collect();
    let mut tests = Vec::new();
    for (k, &e) in short.iter().enumerate() {
        let f = &fits[k];
        for g in lay.columns_of(e) {
            if !f.estimated.contains(&g) {
                continue;
            }
            let var = f.cov[(g, g)];
            if var <= 0.0 {
                continue;
            }
            let Some((s, ax)) = lay.param(g).channel else {
                continue;
            };
            let c = if s == Sensor::Accel { ax } else { 3 + ax };
            tests.push(Test {
                probe: e,
                c,
                chi2: f.theta[g] * f.theta[g] / var,
                fit: k,
            });
        }
    }
    let m_tests = (3 * data.probes.len()).max(1) as f64;
    let p_adj = |chi2: f64| (p_value(chi2, 1) * m_tests).min(1.0);
    let mut out = Vec::new();
    for sensor in [Sensor::Accel, Sensor::Gyro] {
        let range = if sensor == Sensor::Accel { 0..3 } else { 3..6 };
        let sig: Vec<&Test> = tests
            .iter()
            .filter(|t| range.contains(&t.c) && p_adj(t.chi2) < alpha)
            .collect();
        if sig.is_empty() {
            continue;
        }
        let mut channels: Vec<usize> = sig.iter().map(|t| t.c).collect();
        channels.sort_unstable();
        channels.dedup();
        let p_min = sig.iter().map(|t| p_adj(t.chi2)).fold(1.0, f64::min);
        // The leftover of a channel: what its best probe removes. Each form's share is
        // what it removes of that.
        let mut forms: Vec<(f64, f64, Signature)> = Vec::new();
        for &c in &channels {
            let sigma = base.noise[c].sigma.max(1e-300);
            let before = misfit(data, base, c, &all, sigma);
            let drops: Vec<(&Test, f64)> = tests
                .iter()
                .filter(|t| t.c == c)
                .map(|t| (t, before - misfit(data, &fits[t.fit], c, &all, sigma)))
                .collect();
            let top = drops.iter().map(|d| d.1).fold(0.0, f64::max);
            if top <= 0.0 {
                continue;
            }
            for (t, d) in drops {
                let Some(probe) = data.probe(t.probe) else {
                    continue;
                };
                let share = (d / top).clamp(0.0, 1.0);
                if share < 0.05 {
                    continue;
                }
                let (_, ax) = crate::fit::joint::channel(c);
                forms.push((
                    share,
                    t.chi2,
                    Signature {
                        expression: probe.expression(ax),
                        share,
                        channel: CHANNELS[c].into(),
                        reading: probe.reading().into(),
                        in_time: probe.in_time(),
                    },
                ));
            }
        }
        // Largest share first, then the strongest test; forms that tie (on six faces f^2
        // and |f| are one column) in the channel's and the expression's order, not in the
        // order their last bits of rounding happen to give.
        forms.sort_by(|a, b| {
            (sig9(b.0).total_cmp(&sig9(a.0)))
                .then(sig9(b.1).total_cmp(&sig9(a.1)))
                .then_with(|| a.2.channel.cmp(&b.2.channel))
                .then_with(|| a.2.expression.cmp(&b.2.expression))
        });
        forms.truncate(MOST_FORMS);
        // Where it shows: the segments whose residual the strongest test's probe removes
        // most, in units of the channel's noise.
        let best = sig
            .iter()
            .max_by(|a, b| a.chi2.total_cmp(&b.chi2))
            .expect("non-empty");
        let bf = &fits[best.fit];
        let mut segs: Vec<(f64, String)> = Vec::new();
        for acc in &data.accs {
            let mut d = 0.0;
            for &c in &channels {
                let sigma = base.noise[c].sigma.max(1e-300);
                d += (seg_rss(acc, lay, c, &base.theta) - seg_rss(acc, lay, c, &bf.theta))
                    / (sigma * sigma);
            }
            if d >= 9.0 {
                segs.push((d, m.segments[acc.seg].id.clone()));
            }
        }
        segs.sort_by(|a, b| b.0.total_cmp(&a.0));
        segs.truncate(MOST_SEGMENTS);
        let z = sig.iter().map(|t| t.chi2.sqrt()).fold(0.0, f64::max);
        out.push(Unexplained {
            sensor: sensor.name().into(),
            channels: channels.iter().map(|&c| CHANNELS[c].to_string()).collect(),
            segments: segs.into_iter().map(|s| s.1).collect(),
            p_value: p_min,
            standard_errors: z,
            signature: forms.into_iter().map(|f| f.2).collect(),
            note: None,
        });
    }
    out
}

/// `x` to nine significant digits: what a sort compares where values equal but for their
/// rounding must tie.
fn sig9(x: f64) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    let scale = 10f64.powi(8 - x.abs().log10().floor() as i32);
    (x * scale).round() / scale
}

#[cfg(test)]
mod tests {
    use super::sig9;

    #[test]
    fn values_equal_but_for_rounding_tie_and_others_keep_their_order() {
        let a = 1089.123456789;
        assert_eq!(sig9(a), sig9(a * (1.0 + 4e-16)));
        assert_eq!(sig9(1.0), sig9(1.0 - 1e-15));
        assert!(sig9(1089.1235) > sig9(1089.1234));
        assert!(sig9(-2.5e-7) < sig9(-2.4e-7));
        assert_eq!(sig9(0.0), 0.0);
    }
}
