//! One pass over a segment's samples: the kinematic signals at each IMU stamp (table
//! feedback interpolated, through `ratecal_physics`), every effect's regressors, and per
//! output channel the triangular factor of `[X y]` plus one-second block sums.

use super::tri::Tri;
use super::{Layout, channel};
use crate::fit::prep::{SegData, rest_angles, steady_rates, unwrap};
use crate::recording::Recording;
use nalgebra::{DMatrix, DVector};
use ratecal_physics::effects::{Partials, Signals};
use ratecal_physics::{AxisMotion, DEG, Geometry, Site, TableState};

/// Length of the blocks kept for the noise analysis, s.
pub(crate) const BLOCK_S: f64 = 1.0;

/// Sums over one block of samples of one segment.
#[derive(Debug, Clone)]
pub(crate) struct Block {
    /// Mean stamp, s.
    pub t: f64,
    /// Samples.
    pub n: usize,
    /// Per channel, the sum of each of its regressors.
    pub sx: [Vec<f64>; 6],
    /// Per channel, the sum of the observations.
    pub sy: [f64; 6],
}

/// What a segment contributes to any fit.
#[derive(Debug, Clone)]
pub(crate) struct SegAcc {
    /// Index of the segment in the manifest.
    pub seg: usize,
    /// Per channel, the factor of `[X y]` over the channel's columns.
    pub r: [DMatrix<f64>; 6],
    /// One-second blocks in time order.
    pub blocks: Vec<Block>,
    /// Samples.
    pub n: usize,
}

/// The table state at each IMU stamp, from the feedback by linear interpolation; the
/// angular acceleration is the slope of the interpolated rate (one feedback step: a wider
/// difference would smear the start of the next motion into the end of a segment).
pub(crate) fn state_at(rec: &Recording, j: &mut usize, t: f64) -> TableState {
    let tab = &rec.table;
    let last = tab.t.len().saturating_sub(2);
    while *j < last && tab.t[*j + 1] <= t {
        *j += 1;
    }
    let jj = (*j).min(last);
    let (t0, t1) = (tab.t[jj], tab.t[jj + 1]);
    let w = ((t - t0) / (t1 - t0)).clamp(0.0, 1.0);
    let lerp = |x: &[f64]| x[jj] + w * (x[jj + 1] - x[jj]);
    let angle = |x: &[f64]| x[jj] + w * unwrap(x[jj + 1] - x[jj]);
    let slope = |x: &[f64]| (x[jj + 1] - x[jj]) / (t1 - t0);
    TableState {
        outer: AxisMotion {
            angle: angle(&tab.outer) * DEG,
            rate: lerp(&tab.outer_rate) * DEG,
            accel: slope(&tab.outer_rate) * DEG,
        },
        inner: AxisMotion {
            angle: angle(&tab.inner) * DEG,
            rate: lerp(&tab.inner_rate) * DEG,
            accel: slope(&tab.inner_rate) * DEG,
        },
    }
}

/// The IMU temperature the thermal terms refer to: the recording's mean.
pub(crate) fn mean_temperature(rec: &Recording) -> f64 {
    rec.imu.temp.as_ref().map_or(0.0, |t| {
        let (s, n) = t
            .iter()
            .filter(|x| x.is_finite())
            .fold((0.0, 0usize), |(s, n), x| (s + x, n + 1));
        if n == 0 { 0.0 } else { s / n as f64 }
    })
}

/// Accumulates one segment. `t_ref_c` is the temperature the thermal terms refer to.
/// With the segment's preprocessed data (`prepped`, over the same samples), the outputs
/// are its (filtered) ones and the samples it flagged as outliers are left out.
pub(crate) fn accumulate(
    rec: &Recording,
    seg: usize,
    geo: &Geometry,
    layout: &Layout,
    t_ref_c: f64,
    prepped: Option<&SegData>,
) -> SegAcc {
    let s = &rec.manifest.segments[seg];
    let site: Site = rec.manifest.station.site;
    let imu = &rec.imu;
    let a = imu.t.partition_point(|&t| t < s.t_start);
    let b = imu.t.partition_point(|&t| t <= s.t_end);
    let prepped = prepped.filter(|d| d.t.len() == b - a);
    let ncol = layout.cols.len();
    let at_rest = s.kind == crate::recording::SegmentKind::Static;
    let rest = if at_rest {
        rest_angles(rec, s.t_start, s.t_end)
    } else {
        None
    };
    // At rest the kinematic state is the same at every sample: evaluated once.
    let mut rest_snap = None;
    let steady = s.kind == crate::recording::SegmentKind::Rate;
    let mean_rates = {
        let (o, i) = steady_rates(rec, s.t_start, s.t_end);
        (o * DEG, i * DEG)
    };
    let mut tris: Vec<Tri> = (0..6)
        .map(|c| Tri::new(layout.by_channel[c].len() + 1))
        .collect();
    let mut parts = vec![Partials::default(); ncol];
    let mut row: Vec<f64> = Vec::with_capacity(ncol + 1);
    let mut blocks: Vec<Block> = Vec::new();
    let new_block = |layout: &Layout| Block {
        t: 0.0,
        n: 0,
        sx: std::array::from_fn(|c| vec![0.0; layout.by_channel[c].len()]),
        sy: [0.0; 6],
    };
    let mut cur = new_block(layout);
    let mut block_end = s.t_start + BLOCK_S;
    let mut j = 0usize;
    if rec.table.t.len() >= 2 {
        j = rec
            .table
            .t
            .partition_point(|&x| x <= imu.t.get(a).copied().unwrap_or(0.0))
            .saturating_sub(1);
    }
    for i in a..b {
        let t = imu.t[i];
        if rec.table.t.len() < 2 {
            break;
        }
        if prepped.is_some_and(|d| !d.keep_a[i - a] || !d.keep_g[i - a]) {
            continue;
        }
        if t > block_end && cur.n > 0 {
            cur.t /= cur.n as f64;
            blocks.push(std::mem::replace(&mut cur, new_block(layout)));
            block_end += BLOCK_S * ((t - block_end) / BLOCK_S).ceil().max(1.0);
        }
        let mut state = state_at(rec, &mut j, t);
        if let Some((o, i)) = rest {
            // At rest: one attitude for the segment, the mean of its feedback angles.
            state.outer.angle = o * DEG;
            state.inner.angle = i * DEG;
        }
        if at_rest {
            // A static segment is at rest: the feedback's rate ripple is the table's
            // measurement noise, not motion the IMU felt.
            for ax in [&mut state.outer, &mut state.inner] {
                ax.rate = 0.0;
                ax.accel = 0.0;
            }
        } else if steady {
            // A rate segment turns at a constant rate: the feedback's ripple is measurement
            // noise (differencing it would invent angular accelerations), so the rates are
            // the segment's steady rates from the angle feedback.
            state.outer.rate = mean_rates.0;
            state.inner.rate = mean_rates.1;
            state.outer.accel = 0.0;
            state.inner.accel = 0.0;
        }
        let snap = match (&rest_snap, rest) {
            (Some(snap), Some(_)) => *snap,
            _ => state.snapshot(geo, &site),
        };
        if rest.is_some() && rest_snap.is_none() {
            rest_snap = Some(snap);
        }
        let dtemp = imu.temp.as_ref().map_or(0.0, |tc| tc[i] - t_ref_c);
        let sig = Signals::new(&snap, &site, if dtemp.is_finite() { dtemp } else { 0.0 }).at(t);
        for (e, fx) in layout.effects.iter().enumerate() {
            fx.regressors(&sig, &mut parts[layout.columns_of(e)]);
        }
        let base_a = sig.f_b;
        let base_g = sig.w_b_dps();
        let (acc, gyr) = match prepped {
            Some(d) => (
                [d.accel[0][i - a], d.accel[1][i - a], d.accel[2][i - a]],
                [d.gyro[0][i - a], d.gyro[1][i - a], d.gyro[2][i - a]],
            ),
            None => (
                [imu.accel[0][i], imu.accel[1][i], imu.accel[2][i]],
                [imu.gyro[0][i], imu.gyro[1][i], imu.gyro[2][i]],
            ),
        };
        let out = [
            acc[0] - base_a.x,
            acc[1] - base_a.y,
            acc[2] - base_a.z,
            gyr[0] - base_g.x,
            gyr[1] - base_g.y,
            gyr[2] - base_g.z,
        ];
        if out.iter().any(|v| !v.is_finite()) {
            continue;
        }
        for c in 0..6 {
            let (sensor, ax) = channel(c);
            row.clear();
            for &g in &layout.by_channel[c] {
                row.push(parts[g].of(sensor)[ax]);
            }
            row.push(out[c]);
            tris[c].push(&row);
            for (k, v) in row[..row.len() - 1].iter().enumerate() {
                cur.sx[c][k] += v;
            }
            cur.sy[c] += out[c];
        }
        cur.t += t;
        cur.n += 1;
    }
    if cur.n > 0 {
        cur.t /= cur.n as f64;
        blocks.push(cur);
    }
    let n = tris[0].n;
    let mut it = tris.into_iter().map(Tri::finish);
    SegAcc {
        seg,
        r: std::array::from_fn(|_| it.next().expect("six channels")),
        blocks,
        n,
    }
}

/// Residual sum of squares of channel `c` of a segment for global coefficients `theta`
/// (zero for columns outside the model): `|R [theta_c; -1]|^2`.
pub(crate) fn seg_rss(acc: &SegAcc, layout: &Layout, c: usize, theta: &DVector<f64>) -> f64 {
    let cols = &layout.by_channel[c];
    let mut v = DVector::zeros(cols.len() + 1);
    for (k, &g) in cols.iter().enumerate() {
        v[k] = theta[g];
    }
    v[cols.len()] = -1.0;
    (&acc.r[c] * v).norm_squared()
}
