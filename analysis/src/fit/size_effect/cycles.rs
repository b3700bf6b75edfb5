//! From the fit's segments to cycles: a cycle is one navigation run, from a static block
//! (the initial alignment) through the oscillation segments after it under the same mount,
//! until a block at rest at another attitude. The attitude is the IMU's own (the mean
//! specific force in body axes), so an axis brought up by the table (an inner-axis tilt)
//! and one brought up by a remount are told apart alike, whatever the manifest's mounts say.

use crate::fit::prep::geometries;
use crate::recording::{Recording, SegmentKind};
use ratecal_physics::{Mat3, Vec3};

/// A segment the size effect could not use, and why.
#[derive(Debug, Clone, PartialEq)]
pub struct LeftOut {
    /// Segment id.
    pub segment: String,
    /// Why it was left out.
    pub reason: String,
}

/// One navigation run: the static block it aligns on and the oscillation segments after it.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Cycle {
    /// Index of the static segment (alignment).
    pub align: usize,
    /// Indices of the oscillation segments, in time order.
    pub segs: Vec<usize>,
}

/// The largest angle between a static block's and a sway's mean specific force (body axes)
/// for the sway to count as swayed at that block's attitude: the swaying's own mean
/// centripetal acceleration tilts it by well under a degree.
const SAME_ATTITUDE_DEG: f64 = 3.0;

/// Mean specific force (body axes, m/s^2) over `[t0, t1]`, or `None` without samples.
pub(crate) fn mean_f(rec: &Recording, t0: f64, t1: f64) -> Option<Vec3> {
    let imu = &rec.imu;
    let a = imu.t.partition_point(|&t| t < t0);
    let b = imu.t.partition_point(|&t| t <= t1);
    (b > a).then(|| Vec3::from_fn(|c, _| imu.accel[c][a..b].iter().sum::<f64>() / (b - a) as f64))
}

fn angle_deg(a: &Vec3, b: &Vec3) -> f64 {
    a.normalize()
        .dot(&b.normalize())
        .clamp(-1.0, 1.0)
        .acos()
        .to_degrees()
}

/// Sorts the fit's segments into cycles; what cannot join one is left out with the reason.
pub(crate) fn plan(rec: &Recording, ix: &[usize]) -> (Vec<Cycle>, Vec<LeftOut>) {
    let segs = &rec.manifest.segments;
    let geos = geometries(&rec.manifest);
    let same_mount = |a: &Mat3, b: &Mat3| (a - b).norm() < 1e-6;
    let mut left = Vec::new();
    let mut leave = |i: usize, reason: String| {
        left.push(LeftOut {
            segment: segs[i].id.clone(),
            reason,
        })
    };
    let mut osc: Vec<usize> = Vec::new();
    for &i in ix {
        if segs[i].kind == SegmentKind::Oscillation {
            osc.push(i);
        } else {
            leave(i, "not an oscillation segment".into());
        }
    }
    osc.sort_by(|a, b| segs[*a].t_start.total_cmp(&segs[*b].t_start));
    let statics: Vec<(usize, Vec3)> = (0..segs.len())
        .filter(|&i| segs[i].kind == SegmentKind::Static)
        .filter_map(|i| Some((i, mean_f(rec, segs[i].t_start, segs[i].t_end)?)))
        .collect();
    let mut cycles: Vec<Cycle> = Vec::new();
    for &i in &osc {
        let s = &segs[i];
        if !s.period_s.is_some_and(|p| p > 0.0 && p.is_finite()) {
            leave(i, "it has no period (period_s)".into());
            continue;
        }
        if mean_f(rec, s.t_start, s.t_end).is_none() {
            leave(i, "no IMU samples in it".into());
            continue;
        }
        // Static blocks are compared with each other only (at rest the specific force is
        // gravity alone; a sway's mean is not, when its axis is off the vertical).
        let at_rest_like = |a: usize, b: usize| {
            let fa = statics.iter().find(|(st, _)| *st == a).map(|x| x.1);
            let fb = statics.iter().find(|(st, _)| *st == b).map(|x| x.1);
            same_mount(&geos[a].c_pb, &geos[b].c_pb)
                && matches!((fa, fb), (Some(fa), Some(fb)) if angle_deg(&fa, &fb) < SAME_ATTITUDE_DEG)
        };
        let between = |a: usize| {
            statics
                .iter()
                .map(|(st, _)| *st)
                .filter(move |&st| segs[st].t_start >= segs[a].t_end && segs[st].t_end <= s.t_start)
        };
        // The cycle goes on while the mount stays and every block at rest since its
        // alignment is at the alignment's attitude (a tilt or a remount starts another).
        if let Some(c) = cycles.last_mut()
            && same_mount(&geos[c.align].c_pb, &geos[i].c_pb)
            && between(c.align).all(|st| at_rest_like(st, c.align))
        {
            c.segs.push(i);
            continue;
        }
        // Otherwise a new run, from the last static block before it under its mount.
        let align = statics
            .iter()
            .map(|(st, _)| *st)
            .filter(|&st| segs[st].t_end <= s.t_start && same_mount(&geos[st].c_pb, &geos[i].c_pb))
            .max_by(|a, b| segs[*a].t_end.total_cmp(&segs[*b].t_end));
        match align {
            Some(align) => cycles.push(Cycle {
                align,
                segs: vec![i],
            }),
            None => leave(
                i,
                "no static segment before it under its mount to align on (a cycle starts with \
                 one at rest)"
                    .into(),
            ),
        }
    }
    (cycles, left)
}
