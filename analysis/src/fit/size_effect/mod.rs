//! The size-effect fit (Kozlov & Kapralov, ISS 2019; spec/physics.md): the IMU navigates
//! on its own data through each swaying cycle, the velocity drift of each oscillation
//! segment is its mean horizontal acceleration error, and the sensing-point coordinates
//! come from one least-squares over every segment, with per cycle an instrumental constant
//! that the periods' difference cancels and a tilt error that the stretches at rest measure.

mod cycles;
mod drifts;
mod solve;

pub use cycles::LeftOut;
pub use drifts::{MAX_AXIS_TILT_DEG, MAX_UP_AXIS_DEG, MIN_PERIODS, RestDrift, SegmentDrift};
pub use solve::{CycleTerms, SizeEffect};

use super::Out;
use crate::recording::Recording;
use crate::results::{
    Parameter, SegmentDriftReport, SegmentLeftOut, SizeEffectCycle, SizeEffectDrifts,
};

/// The six coordinates, as `(row i, column j)` of `r_ij` and their results names.
pub const COORDS: [(usize, usize, &str); 6] = [
    (0, 1, "rxy"),
    (0, 2, "rxz"),
    (1, 0, "ryx"),
    (1, 2, "ryz"),
    (2, 0, "rzx"),
    (2, 1, "rzy"),
];

const AXIS: [&str; 3] = ["x", "y", "z"];

/// Estimates the coordinates from the oscillation segments `ix` of a recording.
pub fn estimate(rec: &Recording, ix: &[usize]) -> SizeEffect {
    let (cycles, mut left_out) = cycles::plan(rec, ix);
    let runs = drifts::runs(rec, &cycles);
    left_out.extend(runs.left_out);
    let mut est = SizeEffect::default();
    solve::solve(runs.segments, runs.rests, &mut est);
    for l in &left_out {
        est.warnings.push(format!(
            "size effect: segment {} is left out: {}",
            l.segment, l.reason
        ));
    }
    est.left_out = left_out;
    est.cycle_align = cycles
        .iter()
        .map(|c| rec.manifest.segments[c.align].id.clone())
        .collect();
    est
}

impl SizeEffect {
    /// The size-effect part of a segment's drift (East, North), m/s^2.
    pub fn explained(&self, d: &SegmentDrift) -> [f64; 2] {
        std::array::from_fn(|c| {
            (0..6)
                .filter_map(|m| self.coords_m[m].map(|(v, _)| d.h[c][m] * v))
                .sum()
        })
    }

    /// The instrumental part of a segment's drift (constant and tilt), m/s^2.
    pub fn instrumental(&self, d: &SegmentDrift) -> [f64; 2] {
        let Some(terms) = self.cycles.get(d.group) else {
            return [0.0; 2];
        };
        let tilt = terms.tilt(d.elapsed_s);
        std::array::from_fn(|c| tilt[c] + terms.constant.map_or(0.0, |k| k[c].0))
    }

    /// Per cycle, how well the periods cancelled the instrumental terms.
    pub fn cycle_reports(&self) -> Vec<SizeEffectCycle> {
        let mut out = Vec::new();
        for (g, terms) in self.cycles.iter().enumerate() {
            let ds: Vec<&SegmentDrift> = self.drifts.iter().filter(|d| d.group == g).collect();
            let (Some(short), Some(long)) = (
                ds.iter().min_by(|a, b| a.period_s.total_cmp(&b.period_s)),
                ds.iter().max_by(|a, b| a.period_s.total_cmp(&b.period_s)),
            ) else {
                continue;
            };
            let (es, el) = (self.explained(short), self.explained(long));
            let (ts, tl) = (terms.tilt(short.elapsed_s), terms.tilt(long.elapsed_s));
            let diff: [f64; 2] = std::array::from_fn(|c| short.drift_mps2[c] - long.drift_mps2[c]);
            let se: [f64; 2] = std::array::from_fn(|c| es[c] - el[c]);
            let tilt: [f64; 2] = std::array::from_fn(|c| ts[c] - tl[c]);
            let (up, off) = short.up_axis;
            out.push(SizeEffectCycle {
                align: self.cycle_align.get(g).cloned().unwrap_or_default(),
                segments: ds.iter().map(|d| d.id.clone()).collect(),
                up_axis: AXIS[up].into(),
                up_axis_off_deg: off,
                periods_s: [short.period_s, long.period_s],
                difference_mps2: diff,
                size_effect_mps2: se,
                tilt_change_mps2: tilt,
                residual_mps2: std::array::from_fn(|c| diff[c] - se[c] - tilt[c]),
                u_mps2: std::array::from_fn(|c| short.u_mps2[c].hypot(long.u_mps2[c])),
                instrumental_mps2: terms.constant.map(|k| k.map(|(v, u)| [v, u])),
                tilt_growth_mps3: terms.growth_sway,
                rests: self.rests.iter().filter(|r| r.group == g).count(),
            });
        }
        out
    }
}

/// Runs the fit into the analysis output: `size_effect.r<i><j>_mm` parameters.
pub(crate) fn fit(rec: &Recording, ix: &[usize], out: &mut Out) {
    let est = estimate(rec, ix);
    let mut worst: Option<f64> = None;
    for (k, (_, _, name)) in COORDS.iter().enumerate() {
        let key = format!("size_effect.{name}_mm");
        match est.coords_m[k] {
            Some((v, u)) => {
                out.params
                    .insert(key, Parameter::estimate(v * 1e3, u * 1e3, "mm"));
                worst = Some(worst.map_or(u, |w: f64| w.max(u)));
            }
            None => {
                let needs = format!(
                    "a swaying cycle about a vertical axis with {} up, at two periods",
                    solve::needed_axis(k)
                );
                out.params.insert(key.clone(), Parameter::needs(&needs));
                out.observability.insert(key, est.unobservable[k].clone());
            }
        }
    }
    if let Some(u) = worst {
        out.quantities
            .insert("size_effect.uncertainty".into(), (u, 0.0));
    }
    // Cycles with no usable segment are not reported: number the others.
    let mut groups: Vec<usize> = est.drifts.iter().map(|d| d.group).collect();
    groups.dedup();
    let cycle_of = |g: usize| groups.iter().position(|&x| x == g).unwrap_or(0);
    out.size_effect = Some(SizeEffectDrifts {
        segments: est
            .drifts
            .iter()
            .map(|d| SegmentDriftReport {
                segment: d.id.clone(),
                period_s: d.period_s,
                east_mps2: [d.drift_mps2[0], d.u_mps2[0]],
                north_mps2: [d.drift_mps2[1], d.u_mps2[1]],
                velocity: d.velocity.clone(),
                cycle: cycle_of(d.group),
                up_axis: AXIS[d.up_axis.0].into(),
                sway_axis_tilt_deg: d.sway_axis_tilt_deg,
                trend_mps3: d.trend.map(|(v, u)| [v, u]),
                instrumental_mps2: est.instrumental(d),
                size_effect_mps2: est.explained(d),
            })
            .collect(),
        cycles: est.cycle_reports(),
        left_out: est
            .left_out
            .iter()
            .map(|l| SegmentLeftOut {
                segment: l.segment.clone(),
                reason: l.reason.clone(),
            })
            .collect(),
    });
    out.warnings.extend(est.warnings);
}
