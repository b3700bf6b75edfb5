//! The size-effect fit (Kozlov & Kapralov, ISS 2019; spec/physics.md): the IMU navigates
//! on its own data through each swaying cycle, the velocity drift of each oscillation
//! segment is its mean horizontal acceleration error, and the sensing-point coordinates
//! come from one least-squares over every segment, with an instrumental constant per cycle
//! that the periods' difference cancels.

mod cycles;
mod solve;

pub use cycles::SegmentDrift;
pub use solve::SizeEffect;

use super::Out;
use crate::recording::Recording;
use crate::results::{Parameter, SegmentDriftReport, SizeEffectDrifts};

/// The six coordinates, as `(row i, column j)` of `r_ij` and their results names.
pub const COORDS: [(usize, usize, &str); 6] = [
    (0, 1, "rxy"),
    (0, 2, "rxz"),
    (1, 0, "ryx"),
    (1, 2, "ryz"),
    (2, 0, "rzx"),
    (2, 1, "rzy"),
];

/// Estimates the coordinates from the oscillation segments `ix` of a recording.
pub fn estimate(rec: &Recording, ix: &[usize]) -> SizeEffect {
    let (drifts, mut warnings) = cycles::drifts(rec, ix);
    let mut est = solve::solve(&drifts, &mut warnings);
    est.warnings = warnings;
    est
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
            None => out.unobservable(
                &key,
                "no swaying cycle with the right axis up excited this coordinate",
            ),
        }
    }
    if let Some(u) = worst {
        out.quantities
            .insert("size_effect.uncertainty".into(), (u, 0.0));
    }
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
            })
            .collect(),
    });
    out.warnings.extend(est.warnings);
}
