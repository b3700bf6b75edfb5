//! The recording accumulated once for every model explain will try: every segment, every
//! registry effect's columns, and which segments are held out.

use crate::fit::Source;
use crate::fit::joint::{Layout, SegAcc, excitation};
use crate::recording::SegmentKind;
use ratecal_physics::Effect;

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
    /// Accumulates every segment (in parallel) over these effects (the registry's and user
    /// effects) and chooses the held-out ones: every third segment of each kind, never the
    /// longest static one.
    pub(crate) fn with_effects<S: Source>(
        src: &S,
        effects: Vec<&'static dyn Effect>,
    ) -> Result<Data, S::Error> {
        let layout = Layout::new(effects);
        let segs = &src.manifest().segments;
        let accs = crate::fit::accumulate_all(src, &layout)?;
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
        let excitation: Vec<Vec<f64>> = accs.iter().map(|a| excitation(&layout, a)).collect();
        Ok(Data {
            layout,
            accs,
            held,
            excitation,
        })
    }

    /// The fitted (not held-out) accumulations.
    pub(crate) fn working(&self) -> Vec<usize> {
        (0..self.accs.len())
            .filter(|i| !self.held.contains(i))
            .collect()
    }
}
