//! One navigation run per cycle, and what the size-effect solution reads from it: each
//! oscillation segment's mean horizontal acceleration error (the velocity drift) with the
//! regressors of the six coordinates built from the navigation's own kinematics (actual
//! attitude, rates and angular accelerations: tangential and centripetal terms, tilted axes
//! included), and each stretch at rest, where the velocity's slope is the tilt error alone
//! (the accelerometer biases project the same way at every rest at one attitude).

use super::COORDS;
use super::cycles::{Cycle, LeftOut};
use crate::fit::prep::geometries;
use crate::recording::{Recording, SegmentKind};
use ratecal_physics::nav::{AlignError, align, angular_accel, navigate};
use ratecal_physics::{DEG, Mat3, Vec3};

/// One oscillation segment's fitted velocity drift and what each coordinate adds to it.
#[derive(Debug, Clone, PartialEq)]
pub struct SegmentDrift {
    /// Segment id.
    pub id: String,
    /// The cycle (navigation run) it belongs to.
    pub group: usize,
    /// Period, s (the segment's own).
    pub period_s: f64,
    /// The whole periods used: start and end, s.
    pub span_s: (f64, f64),
    /// Middle of the span, s.
    pub t_mid_s: f64,
    /// Time at rest and time moving from the cycle's start to `t_mid_s`, s.
    pub elapsed_s: [f64; 2],
    /// The body axis nearest the sway axis (0 = X) and its angle from it, deg.
    pub up_axis: (usize, f64),
    /// Angle of the sway axis from the vertical, deg.
    pub sway_axis_tilt_deg: f64,
    /// Drift of the East and North velocity (mean acceleration error at mid-span), m/s^2.
    pub drift_mps2: [f64; 2],
    /// Standard uncertainty of each drift, m/s^2.
    pub u_mps2: [f64; 2],
    /// Change of the acceleration error over the span (a growing tilt), m/s^3, and its u.
    pub trend: [(f64, f64); 2],
    /// Drift per metre of each coordinate (order of `COORDS`), East and North rows, 1/s^2.
    pub h: [[f64; 6]; 2],
    /// Trend per metre of each coordinate, 1/s^3 (next to nothing for a steady sway).
    pub h_trend: [[f64; 6]; 2],
    /// Velocity over the span at about 1 Hz: (t s, East m/s, North m/s).
    pub velocity: Vec<[f64; 3]>,
}

/// A stretch at rest at the cycle's attitude: the slope of the velocity there is the
/// horizontal tilt error times g (plus a constant the alignment sets to zero).
#[derive(Debug, Clone, PartialEq)]
pub struct RestDrift {
    /// The cycle.
    pub group: usize,
    /// Start and end, s.
    pub span_s: (f64, f64),
    /// Time at rest and time moving from the cycle's start to the stretch's middle, s.
    pub elapsed_s: [f64; 2],
    /// East and North slope at the middle, m/s^2, with u.
    pub slope: [(f64, f64); 2],
    /// Its change over the stretch, m/s^3, with u.
    pub trend: [(f64, f64); 2],
}

/// What the navigation runs give the solution.
#[derive(Debug, Clone, Default)]
pub(crate) struct Runs {
    pub segments: Vec<SegmentDrift>,
    pub rests: Vec<RestDrift>,
    pub left_out: Vec<LeftOut>,
}

/// A sway axis further than this from the vertical is not the experiment of the paper.
pub const MAX_AXIS_TILT_DEG: f64 = 5.0;
/// The body axis nearest the sway axis must be within this of it.
pub const MAX_UP_AXIS_DEG: f64 = 20.0;
/// The fewest whole periods a segment must hold.
pub const MIN_PERIODS: f64 = 5.0;
/// Rates below this (rad/s, 0.5 deg/s) are at rest; a sway passes it in milliseconds.
const REST_RATE: f64 = 0.5 * DEG;
/// The shortest stretch at rest used, s, and what is trimmed off each of its ends.
const MIN_REST_S: f64 = 10.0;
const REST_TRIM_S: f64 = 2.0;
/// How far (rad) the attitude at rest may be from the alignment's: the navigation's own
/// drift stays far below it, a table move at the slowest rate does not.
const REST_TURN: f64 = 0.2 * DEG;
/// Cosine of the largest angle (1 deg) between a sample's specific force at rest and the
/// alignment's mean: noise stays far below it.
const REST_TILT_COS: f64 = 0.99985;
/// How far past its last segment a cycle is navigated to find the rest after it, s.
const TAIL_S: f64 = 180.0;

/// Navigates each cycle and fits its segments' drifts and its stretches at rest.
pub(crate) fn runs(rec: &Recording, cycles: &[Cycle]) -> Runs {
    let mut out = Runs::default();
    for (ci, cycle) in cycles.iter().enumerate() {
        if let Err(why) = run(rec, ci, cycle, &mut out) {
            let segs = &rec.manifest.segments;
            for &i in &cycle.segs {
                out.left_out.push(LeftOut {
                    segment: segs[i].id.clone(),
                    reason: why.clone(),
                });
            }
        }
    }
    out
}

fn run(rec: &Recording, ci: usize, cycle: &Cycle, out: &mut Runs) -> Result<(), String> {
    let segs = &rec.manifest.segments;
    let geos = geometries(&rec.manifest);
    let st = &segs[cycle.align];
    let last = &segs[*cycle.segs.last().expect("a cycle has a segment")];
    // Past the last segment to the rest after it, but not into another mount.
    let mut end = last.t_end + TAIL_S;
    for (k, s) in segs.iter().enumerate() {
        if s.t_start >= last.t_end && (geos[k].c_pb - geos[cycle.align].c_pb).norm() > 1e-6 {
            end = end.min(s.t_start);
        }
    }
    let imu = &rec.imu;
    let a = imu.t.partition_point(|&t| t < st.t_start);
    let a_end = imu.t.partition_point(|&t| t <= st.t_end);
    let mut b = imu.t.partition_point(|&t| t <= end);
    let b_need = imu.t.partition_point(|&t| t <= last.t_end);
    if a_end < a + 10 || b_need < a_end + 10 {
        return Err("too few IMU samples".into());
    }
    let step = crate::fit::stats::median_step(&imu.t[a..b]);
    if let Some(k) = (a + 1..b).find(|&k| imu.t[k] - imu.t[k - 1] > 10.0 * step + 0.01) {
        if k < b_need {
            return Err(format!(
                "the IMU stream has a gap of {:.3} s at t = {:.3} s, which breaks the navigation",
                imu.t[k] - imu.t[k - 1],
                imu.t[k - 1]
            ));
        }
        b = k;
    }
    let t = &imu.t[a..b];
    let f: Vec<Vec3> = (a..b)
        .map(|k| Vec3::new(imu.accel[0][k], imu.accel[1][k], imu.accel[2][k]))
        .collect();
    let w: Vec<Vec3> = (a..b)
        .map(|k| Vec3::new(imu.gyro[0][k], imu.gyro[1][k], imu.gyro[2][k]) * DEG)
        .collect();
    let n_st = (a_end - a) as f64;
    let f0 = f[..a_end - a].iter().sum::<Vec3>() / n_st;
    let w0 = w[..a_end - a].iter().sum::<Vec3>() / n_st;
    let site = rec.manifest.station.site;
    let c0 = align(&f0, &w0, site.gravity_mps2).map_err(|e| {
        format!(
            "cannot align on {}: {}",
            st.id,
            match e {
                AlignError::NotAtRest =>
                    "its mean specific force is not gravity (was the IMU at rest?)",
                AlignError::NoNorth => "the gyros do not resolve the Earth's horizontal rate",
            }
        )
    })?;
    let nav = navigate(t, &w, &f, &c0, &site, false);
    let omega_l = site.earth_rate_l();
    // The table's rate in body axes (the gyros less the Earth's rate).
    let w_t: Vec<Vec3> = w
        .iter()
        .zip(&nav.c_lb)
        .map(|(w, c)| w - c.transpose() * omega_l)
        .collect();
    let g_int = regressors(t, &w_t, &nav.c_lb);
    // Time at rest and time moving since the start, per sample.
    let moving: Vec<bool> = w_t.iter().map(|w| w.norm() >= REST_RATE).collect();
    let mut elapsed = Vec::with_capacity(t.len());
    let mut acc = [0.0, 0.0];
    for k in 0..t.len() {
        if k > 0 {
            acc[usize::from(moving[k])] += t[k] - t[k - 1];
        }
        elapsed.push(acc);
    }
    let at = |x: f64| elapsed[t.partition_point(|&s| s < x).min(t.len() - 1)];
    let every = ((1.0 / step).round() as usize).max(1);
    for &i in &cycle.segs {
        let s = &segs[i];
        let period = s.period_s.unwrap_or(f64::NAN);
        let leave = |out: &mut Runs, reason: String| {
            out.left_out.push(LeftOut {
                segment: s.id.clone(),
                reason,
            })
        };
        let n_per = ((s.t_end - s.t_start) / period + 1e-9).floor();
        if n_per < MIN_PERIODS {
            leave(
                out,
                format!(
                    "too short: {n_per:.0} whole periods of {period} s (the drift needs {MIN_PERIODS:.0} or more)"
                ),
            );
            continue;
        }
        let span = (s.t_start, s.t_start + n_per * period);
        let k0 = t.partition_point(|&x| x < span.0);
        let k1 = t.partition_point(|&x| x <= span.1);
        // The sway axis: the principal direction of the table's rate in body axes.
        let cov = w_t[k0..k1]
            .iter()
            .fold(Mat3::zeros(), |m, w| m + w * w.transpose());
        // Bounded (nalgebra's plain `symmetric_eigen` iterates without limit).
        let Some(eig) = nalgebra::SymmetricEigen::try_new(cov, f64::EPSILON, 10_000) else {
            leave(out, "the table's rate in this segment is not finite".into());
            continue;
        };
        let imax = eig.eigenvalues.imax();
        let axis_b: Vec3 = eig.eigenvectors.column(imax).into();
        let axis_l = nav.c_lb[(k0 + k1) / 2] * axis_b;
        let tilt = axis_l.z.abs().clamp(0.0, 1.0).acos().to_degrees();
        let up = axis_b.iamax();
        let off = axis_b[up].abs().clamp(0.0, 1.0).acos().to_degrees();
        if tilt > MAX_AXIS_TILT_DEG {
            leave(
                out,
                format!(
                    "the sway axis is {tilt:.1} deg from the vertical (the method sways about a vertical axis, within {MAX_AXIS_TILT_DEG} deg)"
                ),
            );
            continue;
        }
        // Gravity's component along the sway axis does not change while swaying about it:
        // if it is not the alignment's, the IMU was tilted or remounted in between without
        // the navigation seeing it (the stream jumped).
        let f_mean = f[k0..k1].iter().sum::<Vec3>() / (k1 - k0).max(1) as f64;
        let jump = (f_mean.dot(&axis_b) - f0.dot(&axis_b)).abs();
        if jump > 0.02 * site.gravity_mps2 {
            leave(
                out,
                format!(
                    "its attitude is not that of {} (gravity along the sway axis differs by {:.3} m/s^2): no alignment at rest at its attitude",
                    st.id, jump
                ),
            );
            continue;
        }
        if off > MAX_UP_AXIS_DEG {
            leave(
                out,
                format!(
                    "no body axis near the sway axis: the nearest, {}, is {off:.1} deg from it (within {MAX_UP_AXIS_DEG} deg needed)",
                    ["X", "Y", "Z"][up]
                ),
            );
            continue;
        }
        let ts = &t[k0..k1];
        let t_mid = 0.5 * (span.0 + span.1);
        let edges: Vec<f64> = (0..=n_per as usize)
            .map(|b| span.0 + b as f64 * period)
            .collect();
        let blocks = Blocks::new(ts, &edges);
        let mut d = SegmentDrift {
            id: s.id.clone(),
            group: ci,
            period_s: period,
            span_s: span,
            t_mid_s: t_mid,
            elapsed_s: at(t_mid),
            up_axis: (up, off),
            sway_axis_tilt_deg: tilt,
            drift_mps2: [0.0; 2],
            u_mps2: [0.0; 2],
            trend: [(0.0, 0.0); 2],
            h: [[0.0; 6]; 2],
            h_trend: [[0.0; 6]; 2],
            velocity: Vec::new(),
        };
        for c in 0..2 {
            let v: Vec<f64> = nav.v_l[k0..k1].iter().map(|v| v[c]).collect();
            let q = blocks.line(&v, t_mid);
            d.drift_mps2[c] = q.c0;
            d.u_mps2[c] = q.u0;
            d.trend[c] = (q.c1, q.u1);
            for m in 0..6 {
                let g: Vec<f64> = g_int[k0..k1].iter().map(|g| g[m][c]).collect();
                let q = blocks.line(&g, t_mid);
                d.h[c][m] = q.c0;
                d.h_trend[c][m] = q.c1;
            }
        }
        d.velocity = (k0..k1)
            .step_by(every)
            .map(|k| [t[k], nav.v_l[k].x, nav.v_l[k].y])
            .collect();
        out.segments.push(d);
    }
    // Stretches at rest at the alignment's attitude, outside every oscillation segment.
    let swaying = |x: f64| {
        segs.iter()
            .any(|s| s.kind == SegmentKind::Oscillation && s.t_start <= x && x <= s.t_end)
    };
    // Same attitude as the alignment all through (a rest after a tilt or a remount is at
    // another one, where the biases project otherwise).
    // The specific force is checked too: a stream that jumps to another attitude between
    // two samples (a remount with the recording running) shows it there alone.
    let c0_t = c0.transpose();
    let up0 = f0.normalize();
    let still = |k: usize| {
        let turn = ((c0_t * nav.c_lb[k]).trace() - 1.0) / 2.0;
        !moving[k]
            && turn.clamp(-1.0, 1.0).acos() < REST_TURN
            && f[k].normalize().dot(&up0) > REST_TILT_COS
            && !swaying(t[k])
    };
    let mut k = 0;
    while k < t.len() {
        if !still(k) {
            k += 1;
            continue;
        }
        let k_start = k;
        while k < t.len() && still(k) {
            k += 1;
        }
        if k == k_start {
            k += 1;
            continue;
        }
        let (lo, hi) = (t[k_start] + REST_TRIM_S, t[k - 1] - REST_TRIM_S);
        if hi - lo < MIN_REST_S - 2.0 * REST_TRIM_S {
            continue;
        }
        let (r0, r1) = (
            t.partition_point(|&x| x < lo),
            t.partition_point(|&x| x <= hi),
        );
        let n_blocks = (hi - lo).floor() as usize;
        let edges: Vec<f64> = (0..=n_blocks)
            .map(|b| lo + (hi - lo) * b as f64 / n_blocks as f64)
            .collect();
        let blocks = Blocks::new(&t[r0..r1], &edges);
        let t_mid = 0.5 * (lo + hi);
        let mut r = RestDrift {
            group: ci,
            span_s: (lo, hi),
            elapsed_s: at(t_mid),
            slope: [(0.0, 0.0); 2],
            trend: [(0.0, 0.0); 2],
        };
        for c in 0..2 {
            let v: Vec<f64> = nav.v_l[r0..r1].iter().map(|v| v[c]).collect();
            let q = blocks.line(&v, t_mid);
            r.slope[c] = (q.c0, q.u0);
            r.trend[c] = (q.c1, q.u1);
        }
        if r.slope.iter().all(|s| s.1.is_finite()) {
            out.rests.push(r);
        }
    }
    Ok(())
}

/// Integrated horizontal acceleration error per metre of each coordinate, per sample:
/// accelerometer i gains `(dw x e_j)_i + w_i w_j` per metre of `r_ij`, seen in L along
/// `C_LB e_i`.
fn regressors(t: &[f64], w: &[Vec3], c_lb: &[Mat3]) -> Vec<[[f64; 2]; 6]> {
    let dw = angular_accel(t, w);
    let mut acc = [[0.0; 2]; 6];
    let mut prev: Option<[[f64; 2]; 6]> = None;
    let mut out = Vec::with_capacity(t.len());
    for k in 0..t.len() {
        let mut g = [[0.0; 2]; 6];
        for (m, &(i, j, _)) in COORDS.iter().enumerate() {
            let e_j = Vec3::ith(j, 1.0);
            let s = dw[k].cross(&e_j)[i] + w[k][i] * w[k][j];
            g[m] = [c_lb[k][(0, i)] * s, c_lb[k][(1, i)] * s];
        }
        if let Some(p) = prev {
            let dt = t[k] - t[k - 1];
            for m in 0..6 {
                for c in 0..2 {
                    acc[m][c] += 0.5 * (p[m][c] + g[m][c]) * dt;
                }
            }
        }
        prev = Some(g);
        out.push(acc);
    }
    out
}

/// Consecutive blocks of a span (whole periods of a sway, or about a second at rest): the
/// difference of neighbouring blocks' mean velocities over their distance is a mean
/// acceleration, free of the sway's periodic velocity, and nearly independent of the next
/// one where the noise is a random walk of velocity (white accelerometer noise).
struct Blocks {
    ranges: Vec<(usize, usize)>,
    t: Vec<f64>,
}

/// `c0 + c1 (t - t_mid)` through the blocks' accelerations, with uncertainties.
struct Line {
    c0: f64,
    u0: f64,
    c1: f64,
    u1: f64,
}

impl Blocks {
    fn new(t: &[f64], edges: &[f64]) -> Self {
        let mut ranges = Vec::with_capacity(edges.len());
        let mut tb = Vec::with_capacity(edges.len());
        for e in edges.windows(2) {
            let k0 = t.partition_point(|&x| x < e[0]);
            let k1 = t.partition_point(|&x| x < e[1]);
            if k1 > k0 {
                ranges.push((k0, k1));
                tb.push(t[k0..k1].iter().sum::<f64>() / (k1 - k0) as f64);
            }
        }
        Blocks { ranges, t: tb }
    }

    fn line(&self, y: &[f64], t_mid: f64) -> Line {
        let yb: Vec<f64> = self
            .ranges
            .iter()
            .map(|&(a, b)| y[a..b].iter().sum::<f64>() / (b - a) as f64)
            .collect();
        let pts: Vec<(f64, f64)> = (1..yb.len())
            .map(|k| {
                let dt = self.t[k] - self.t[k - 1];
                (
                    0.5 * (self.t[k] + self.t[k - 1]) - t_mid,
                    (yb[k] - yb[k - 1]) / dt,
                )
            })
            .collect();
        let n = pts.len();
        let none = Line {
            c0: 0.0,
            u0: f64::INFINITY,
            c1: 0.0,
            u1: f64::INFINITY,
        };
        if n < 4 {
            return none;
        }
        let nf = n as f64;
        let mx = pts.iter().map(|p| p.0).sum::<f64>() / nf;
        let my = pts.iter().map(|p| p.1).sum::<f64>() / nf;
        let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
        if sxx <= 0.0 {
            return none;
        }
        let c1 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>() / sxx;
        let c0 = my - c1 * mx;
        let rss: f64 = pts.iter().map(|p| (p.1 - c0 - c1 * p.0).powi(2)).sum();
        // Neighbouring differences share a block: their errors correlate (1.5 on the
        // variance of a mean for a random walk).
        let s2 = (1.5 * rss / (nf - 2.0)).max(1e-30);
        Line {
            c0,
            u0: (s2 * (1.0 / nf + mx * mx / sxx)).sqrt(),
            c1,
            u1: (s2 / sxx).sqrt(),
        }
    }
}
