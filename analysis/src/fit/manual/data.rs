//! What the manual fits read of a recording: each static pose's mean specific force and
//! rate (with their scatter), and each turn's raw gyro samples with the poses around it.

use crate::fit::Source;
use crate::recording::{Attitude, Manifest, SegmentKind};

/// A static pose: its means and scatter.
#[derive(Debug, Clone)]
pub(crate) struct Pose {
    /// Manifest index.
    pub seg: usize,
    pub id: String,
    pub attitude: Attitude,
    /// The nominal face (body axis index, sign) when one is declared.
    pub face: Option<(usize, f64)>,
    /// Tolerance of a nominal attitude, rad.
    pub tol_rad: f64,
    /// Samples.
    pub n: usize,
    /// Mean specific force, m/s^2.
    pub f: [f64; 3],
    /// Standard deviation of the specific force per axis, m/s^2.
    pub f_std: [f64; 3],
    /// Mean rate, deg/s.
    pub w: [f64; 3],
    /// Standard deviation of the rate per axis, deg/s.
    pub w_std: [f64; 3],
}

/// A turn between two poses: its raw gyro samples.
#[derive(Debug, Clone)]
pub(crate) struct Turn {
    pub id: String,
    /// Signed body axis and nominal angle, deg, when declared.
    pub axis: Option<(usize, f64)>,
    pub angle_deg: Option<f64>,
    /// Index into the poses of the pose just before and just after, when adjacent.
    pub from: Option<usize>,
    pub to: Option<usize>,
    /// Stamps, s, and rates, deg/s.
    pub t: Vec<f64>,
    pub w: Vec<[f64; 3]>,
}

/// Poses and turns of a manual recording, in manifest order.
#[derive(Debug, Clone, Default)]
pub(crate) struct Data {
    pub poses: Vec<Pose>,
    pub turns: Vec<Turn>,
}

/// `+x`, `-z` to (index, sign).
pub(crate) fn signed_axis(s: &str) -> Option<(usize, f64)> {
    let (sign, name) = match s.trim().strip_prefix('-') {
        Some(n) => (-1.0, n),
        None => (1.0, s.trim().trim_start_matches('+')),
    };
    let k = ["x", "y", "z"].iter().position(|a| *a == name)?;
    Some((k, sign))
}

/// Whether the recording is calibrated without a table: some static segment's attitude
/// is `nominal` or `unknown` and none is held by feedback.
pub(crate) fn is_manual(m: &Manifest) -> bool {
    let statics = || m.segments.iter().filter(|s| s.kind == SegmentKind::Static);
    statics().any(|s| s.attitude() != Attitude::Feedback)
        && statics().all(|s| s.attitude() != Attitude::Feedback)
}

/// Reads the poses and turns of `src`.
pub(crate) fn read<S: Source>(src: &S) -> Result<Data, S::Error> {
    let m = src.manifest();
    let mut d = Data::default();
    let mut last_pose: Option<(usize, usize)> = None; // (manifest index, pose index)
    let mut pending: Vec<usize> = Vec::new(); // turns waiting for their next pose
    // A run resumed between a pose and the turn after it: the unit lay anywhere meanwhile,
    // so that turn does not start from that pose.
    let resumed_at: Vec<f64> = m.run.as_ref().map_or(Vec::new(), |r| {
        r.resumes.iter().filter_map(|x| x.t).collect()
    });
    for (i, s) in m.segments.iter().enumerate() {
        match s.kind {
            SegmentKind::Static => {
                let pose = src.rows(s.t_start, s.t_end, |v| pose_of(i, s, v))?;
                let Some(pose) = pose else { continue };
                d.poses.push(pose);
                let k = d.poses.len() - 1;
                for t in pending.drain(..) {
                    if d.turns[t].from.is_some_and(|f| d.poses[f].seg + 2 == i) {
                        d.turns[t].to = Some(k);
                    }
                }
                last_pose = Some((i, k));
            }
            SegmentKind::Turn => {
                let (t, w) = src.rows(s.t_start, s.t_end, |v| {
                    let w = (0..v.t.len())
                        .map(|r| [v.gyro[0][r], v.gyro[1][r], v.gyro[2][r]])
                        .collect::<Vec<_>>();
                    (v.t.to_vec(), w)
                })?;
                let from = last_pose
                    .filter(|(j, _)| j + 1 == i)
                    .filter(|(j, _)| {
                        let end = m.segments[*j].t_end;
                        !resumed_at.iter().any(|&t| end <= t && t < s.t_start)
                    })
                    .map(|p| p.1);
                d.turns.push(Turn {
                    id: s.id.clone(),
                    axis: s.axis.as_deref().and_then(signed_axis),
                    angle_deg: s.angle_deg,
                    from,
                    to: None,
                    t,
                    w,
                });
                pending.push(d.turns.len() - 1);
            }
            _ => pending.clear(),
        }
    }
    Ok(d)
}

/// The means and scatter of one static segment (`None` with fewer than two samples).
fn pose_of(i: usize, s: &crate::recording::Segment, v: crate::fit::ImuView<'_>) -> Option<Pose> {
    let n = v.t.len();
    if n < 2 {
        return None;
    }
    let stats = |x: &[f64]| {
        let mean = x.iter().sum::<f64>() / n as f64;
        let var = x.iter().map(|y| (y - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
        (mean, var.sqrt())
    };
    let fa: [(f64, f64); 3] = std::array::from_fn(|k| stats(v.accel[k]));
    let wa: [(f64, f64); 3] = std::array::from_fn(|k| stats(v.gyro[k]));
    Some(Pose {
        seg: i,
        id: s.id.clone(),
        attitude: s.attitude(),
        face: s.up.as_deref().and_then(signed_axis),
        tol_rad: s.tolerance_deg.unwrap_or(0.0).to_radians(),
        n,
        f: fa.map(|a| a.0),
        f_std: fa.map(|a| a.1),
        w: wa.map(|a| a.0),
        w_std: wa.map(|a| a.1),
    })
}
