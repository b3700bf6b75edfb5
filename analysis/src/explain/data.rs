//! The recording accumulated once for every model explain will try: every segment, every
//! registry effect's columns, and which segments are held out.

use super::earth::candidate::EARTH_HELD;
use super::probe::{self, Probe};
use crate::fit::joint::{Layout, SegAcc, excitation};
use crate::fit::{Retime, Source};
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
    /// Layout indices of the effects forward selection may add (the registry's catalogue
    /// with the Earth's rate held, and user effects).
    pub candidates: Vec<usize>,
    /// Layout indices of the probes, with their forms: what a leftover may follow.
    pub probes: Vec<(usize, &'static Probe)>,
    /// Layout index of the Earth's rate as explain tries it ([`super::earth`]).
    pub earth: usize,
    /// What fits over each segment set share, for the sets fitted so far: explain fits
    /// hundreds of models over a handful of sets.
    pub merged: Merged,
    /// The timing error the signals were evaluated with: the timing columns
    /// (`time_offset`, `clock_rate`) measure what is left about it.
    pub retime: Retime,
    /// Static segments left out because their attitude is unknown (`up: oblique`): ids.
    pub left_out: Vec<String>,
    /// Per accumulation: whether its segment is static (the table at rest at a known
    /// attitude).
    pub at_rest: Vec<bool>,
    /// The factor on the library forms' consumer ranges for the IMU's grade
    /// (`plausible::grade_scale`).
    pub grade: f64,
    /// Whether the table stream is a table's feedback (not synthesized from declared
    /// attitudes by an import with `table: none`): table-side effects need it.
    pub table_feedback: bool,
    /// The largest `tolerance_deg` of the nominal static segments, rad (0 without any): a
    /// face placed by hand tilts within it, which a misalignment mimics.
    pub tilt_rad: f64,
}

/// Whether a segment's attitude is unknown to the recording: a pose of a multi-position
/// session that no body axis is near vertical in (`up: oblique`). Its specific force is
/// not the table stream's, so no fit may use it as such.
fn attitude_unknown(s: &crate::recording::Segment) -> bool {
    s.is_oblique()
}

/// The largest tolerance of the recording's nominal static attitudes, rad.
fn placement_tilt_rad(m: &crate::recording::Manifest) -> f64 {
    m.segments
        .iter()
        .filter(|s| s.attitude() == crate::recording::Attitude::Nominal)
        .filter_map(|s| s.tolerance_deg)
        .fold(0.0, f64::max)
        .to_radians()
}

/// Whether the manifest's table stream is a table's feedback: `ratecal import` names a
/// synthesized one `none: ...` (docs/import.md).
pub(crate) fn has_table_feedback(m: &crate::recording::Manifest) -> bool {
    !m.station
        .table
        .model
        .as_deref()
        .is_some_and(|t| t.starts_with("none"))
}

/// Merged factors by (accelerometer segments, gyro segments).
pub(crate) type Merged = std::sync::Mutex<
    Vec<(
        (Vec<usize>, Vec<usize>),
        std::sync::Arc<crate::fit::joint::Pooled>,
    )>,
>;

impl Data {
    /// Accumulates every segment (in parallel) over these effects (the registry's and user
    /// effects) and chooses the held-out ones: every third segment of each kind, never the
    /// longest static one.
    ///
    /// Besides `effects`, the layout holds the Earth's rate as explain tries it (held at
    /// the manifest's latitude, the heading free) and the probe library.
    pub(crate) fn with_effects<S: Source>(
        src: &S,
        mut effects: Vec<&'static dyn Effect>,
        retime: Retime,
    ) -> Result<Data, S::Error> {
        let segs = &src.manifest().segments;
        let t0 = segs.iter().map(|s| s.t_start).fold(f64::INFINITY, f64::min);
        let t0 = if t0.is_finite() { t0.floor() } else { 0.0 };
        let mut candidates: Vec<usize> = (0..effects.len())
            .filter(|&e| !effects[e].nominal() && effects[e].id() != "earth_rate")
            .collect();
        let earth = effects.len();
        candidates.push(earth);
        effects.push(&EARTH_HELD);
        let t1 = segs.iter().map(|s| s.t_end).fold(t0, f64::max);
        let m = src.manifest();
        let grade = super::plausible::grade_scale(m.imu.get("grade").map(String::as_str));
        let sampled = probe::sampled(t0, t1 - t0, grade);
        let mut probes: Vec<(usize, &'static Probe)> = Vec::new();
        for p in sampled {
            probes.push((effects.len(), p));
            effects.push(p);
        }
        let mut layout = Layout::new(effects);
        let mut accs = crate::fit::accumulate_all(src, &layout, retime)?;
        let left_out: Vec<String> = accs
            .iter()
            .filter(|a| attitude_unknown(&segs[a.seg]))
            .map(|a| segs[a.seg].id.clone())
            .collect();
        // A hand turn has no reference either: no table follows the hand (its integral is
        // the manual calibration's, `ratecal analyze`).
        accs.retain(|a| !attitude_unknown(&segs[a.seg]) && segs[a.seg].kind != SegmentKind::Turn);
        let spans: Vec<(f64, f64)> = accs
            .iter()
            .map(|a| (segs[a.seg].t_start, segs[a.seg].t_end))
            .collect();
        let g = m.station.site.gravity_mps2;
        let turning: Vec<bool> = accs
            .iter()
            .map(|a| segs[a.seg].kind != SegmentKind::Static)
            .collect();
        probes.extend(probe::add_steps(
            &mut layout,
            &mut accs,
            &spans,
            &turning,
            g,
            grade,
        ));
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
        let at_rest: Vec<bool> = accs
            .iter()
            .map(|a| segs[a.seg].kind == SegmentKind::Static)
            .collect();
        Ok(Data {
            at_rest,
            layout,
            accs,
            held,
            excitation,
            candidates,
            probes,
            earth,
            merged: Default::default(),
            retime,
            left_out,
            table_feedback: has_table_feedback(m),
            grade,
            tilt_rad: placement_tilt_rad(m),
        })
    }

    /// The channels' factors merged over these segments, kept for the next model.
    pub(crate) fn merged(
        &self,
        accel: &[usize],
        gyro: &[usize],
    ) -> std::sync::Arc<crate::fit::joint::Pooled> {
        let key = (accel.to_vec(), gyro.to_vec());
        if let Some(m) = self
            .merged
            .lock()
            .expect("not poisoned")
            .iter()
            .find(|e| e.0 == key)
        {
            return m.1.clone();
        }
        let req = crate::fit::joint::FitRequest {
            layout: &self.layout,
            cols: Vec::new(),
            fixed: Vec::new(),
            accel: accel.iter().map(|&i| &self.accs[i]).collect(),
            gyro: gyro.iter().map(|&i| &self.accs[i]).collect(),
            merged: None,
            wander: crate::fit::joint::WanderRule::Estimated,
        };
        let m = std::sync::Arc::new(crate::fit::joint::Pooled::of(&req));
        let mut cache = self.merged.lock().expect("not poisoned");
        if cache.len() >= 16 {
            cache.remove(0);
        }
        cache.push((key, m.clone()));
        m
    }

    /// The probe behind layout effect `e`, if it is one.
    pub(crate) fn probe(&self, e: usize) -> Option<&'static Probe> {
        self.probes.iter().find(|q| q.0 == e).map(|q| q.1)
    }

    /// The fitted (not held-out) accumulations.
    pub(crate) fn working(&self) -> Vec<usize> {
        (0..self.accs.len())
            .filter(|i| !self.held.contains(i))
            .collect()
    }
}
