//! From the fit's segments to cycles: a cycle is one navigation run, from a static block
//! (the initial alignment) through the oscillation segments swayed at that block's attitude
//! under the same mount. The attitude is the IMU's own (the mean specific force in body
//! axes), so an axis brought up by the table (an inner-axis tilt) and one brought up by a
//! remount are told apart alike, whatever the manifest's mounts say.

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
    (b > a).then(|| {
        Vec3::from_fn(|c, _| imu.accel[c][a..b].iter().sum::<f64>() / (b - a) as f64)
    })
}

fn angle_deg(a: &Vec3, b: &Vec3) -> f64 {
    a.normalize().dot(&b.normalize()).clamp(-1.0, 1.0).acos().to_degrees()
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
        let Some(f) = mean_f(rec, s.t_start, s.t_end) else {
            leave(i, "no IMU samples in it".into());
            continue;
        };
        let matches = |st: usize, fs: &Vec3| {
            same_mount(&geos[st].c_pb, &geos[i].c_pb) && angle_deg(fs, &f) < SAME_ATTITUDE_DEG
        };
        // The cycle goes on while the mount and the attitude stay those of its alignment.
        if let Some(c) = cycles.last_mut()
            && let Some((_, fs)) = statics.iter().find(|(st, _)| *st == c.align)
            && matches(c.align, fs)
            && !statics.iter().any(|(st, fs)| {
                let t = &segs[*st];
                t.t_start >= segs[c.align].t_end && t.t_end <= s.t_start && !matches(*st, fs)
            })
        {
            c.segs.push(i);
            continue;
        }
        // Otherwise a new run: the last static block before it at its attitude.
        let align = statics
            .iter()
            .filter(|(st, fs)| segs[*st].t_end <= s.t_start && matches(*st, fs))
            .map(|(st, _)| *st)
            .max_by(|a, b| segs[*a].t_end.total_cmp(&segs[*b].t_end));
        // ...with nothing between at another attitude (a remount or a tilt breaks the run).
        let align = align.filter(|&a| {
            !statics.iter().any(|(st, fs)| {
                let t = &segs[*st];
                t.t_start >= segs[a].t_end && t.t_end <= s.t_start && !matches(*st, fs)
            })
        });
        match align {
            Some(align) => cycles.push(Cycle {
                align,
                segs: vec![i],
            }),
            None => leave(
                i,
                "no static segment before it at its attitude and mount to align on (a cycle \
                 starts with one at rest)"
                    .into(),
            ),
        }
    }
    (cycles, left)
}
