//! The recording accumulated once for every model explain will try: every segment, every
//! registry effect's columns, and which segments are held out.

use crate::fit::joint::{Layout, SegAcc, accumulate};
use crate::fit::prep::geometries;
use crate::recording::{Recording, SegmentKind};
use ratecal_physics::{Effect, REGISTRY};

/// Accumulated segments and the split between fitted and held-out ones.
pub(crate) struct Data {
    /// Every registry effect, in registry order.
    pub layout: Layout,
    /// One accumulation per segment with samples, in manifest order.
    pub accs: Vec<SegAcc>,
    /// Indices into `accs` of the held-out segments.
    pub held: Vec<usize>,
    /// Column RMS per segment: how much each column varies there.
    pub excitation: Vec<Vec<f64>>,
}

impl Data {
    /// Accumulates every segment (in parallel) over the registry's effects and chooses the
    /// held-out ones: every third segment of each kind, never the longest static one.
    pub(crate) fn new(rec: &Recording) -> Data {
        Data::with_effects(rec, REGISTRY.to_vec())
    }

    /// The same over these effects (the registry's and user effects).
    pub(crate) fn with_effects(rec: &Recording, effects: Vec<&'static dyn Effect>) -> Data {
        use rayon::prelude::*;
        let layout = Layout::new(effects);
        let geos = geometries(rec);
        let t_ref = rec.imu.temp.as_ref().map_or(0.0, |t| {
            let v: Vec<f64> = t.iter().copied().filter(|x| x.is_finite()).collect();
            if v.is_empty() {
                0.0
            } else {
                v.iter().sum::<f64>() / v.len() as f64
            }
        });
        let segs = &rec.manifest.segments;
        let accs: Vec<SegAcc> = (0..segs.len())
            .into_par_iter()
            .map(|i| accumulate(rec, i, &geos[i], &layout, t_ref))
            .filter(|a| a.n > 0)
            .collect();
        let longest = accs
            .iter()
            .enumerate()
            .filter(|(_, a)| segs[a.seg].kind == SegmentKind::Static)
            .max_by(|a, b| a.1.n.cmp(&b.1.n))
            .map(|(i, _)| i);
        let mut held = Vec::new();
        for kind in [
            SegmentKind::Static,
            SegmentKind::Rate,
            SegmentKind::Oscillation,
        ] {
            let of: Vec<usize> = (0..accs.len())
                .filter(|&i| segs[accs[i].seg].kind == kind && Some(i) != longest)
                .collect();
            if of.len() >= 3 {
                held.extend(of.iter().skip(2).step_by(3));
            }
        }
        held.sort_unstable();
        let excitation: Vec<Vec<f64>> = accs
            .iter()
            .map(|a| {
                let mut ex = vec![0.0f64; layout.cols.len()];
                for c in 0..6 {
                    let r = &a.r[c];
                    for (k, &g) in layout.by_channel[c].iter().enumerate() {
                        let rms = r.column(k).norm() / (a.n.max(1) as f64).sqrt();
                        ex[g] = ex[g].max(rms);
                    }
                }
                ex
            })
            .collect();
        Data {
            layout,
            accs,
            held,
            excitation,
        }
    }

    /// The fitted (not held-out) accumulations.
    pub(crate) fn working(&self) -> Vec<usize> {
        (0..self.accs.len())
            .filter(|i| !self.held.contains(i))
            .collect()
    }
}
