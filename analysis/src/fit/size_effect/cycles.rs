//! From a recording to one drift per oscillation segment: cycles (a run of oscillation
//! segments under one mount), the static block each aligns on, the navigation through the
//! cycle, and each segment's velocity drift with the regressors of the six coordinates
//! built from the navigation's own kinematics (actual attitude, rates and angular
//! accelerations: tangential and centripetal terms, tilted axes included).

use super::COORDS;
use crate::fit::prep::geometries;
use crate::recording::{Recording, SegmentKind};
use ratecal_physics::nav::{align, angular_accel, navigate};
use ratecal_physics::{DEG, Mat3, Vec3};

/// One oscillation segment's fitted velocity drift and what each coordinate adds to it.
#[derive(Debug, Clone, PartialEq)]
pub struct SegmentDrift {
    /// Segment id.
    pub id: String,
    /// Group: segments of one cycle at one centre and amplitude share an instrumental term.
    pub group: usize,
    /// Period, s (the segment's own).
    pub period_s: f64,
    /// The whole periods used: start and end, s.
    pub span_s: (f64, f64),
    /// Middle of the span, s.
    pub t_mid_s: f64,
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

/// Drifts of the oscillation segments `ix`, and warnings for what had to be left out.
pub(crate) fn drifts(rec: &Recording, ix: &[usize]) -> (Vec<SegmentDrift>, Vec<String>) {
    let segs = &rec.manifest.segments;
    let geos = geometries(&rec.manifest);
    let mut warnings = Vec::new();
    let mut osc: Vec<usize> = Vec::new();
    for &i in ix {
        if segs[i].kind == SegmentKind::Oscillation {
            osc.push(i);
        } else {
            warnings.push(format!(
                "size effect: segment {} is not an oscillation; left out",
                segs[i].id
            ));
        }
    }
    osc.sort_by(|a, b| segs[*a].t_start.total_cmp(&segs[*b].t_start));
    // A cycle: consecutive oscillation segments under one mount.
    let same = |a: &Mat3, b: &Mat3| (a - b).norm() < 1e-6;
    let mut cycles: Vec<Vec<usize>> = Vec::new();
    for &i in &osc {
        match cycles.last_mut() {
            Some(c) if same(&geos[c[0]].c_pb, &geos[i].c_pb) => c.push(i),
            _ => cycles.push(vec![i]),
        }
    }
    let mut out = Vec::new();
    let mut groups: Vec<(usize, i64, i64)> = Vec::new();
    for (ci, cycle) in cycles.iter().enumerate() {
        match cycle_drifts(rec, cycle, &geos[cycle[0]].c_pb, &osc) {
            Ok((ds, w)) => {
                warnings.extend(w);
                for (i, mut d) in ds {
                    let s = &segs[i];
                    let key = (
                        ci,
                        (s.center_deg.unwrap_or(0.0)).round() as i64,
                        (s.amplitude_deg.unwrap_or(0.0)).round() as i64,
                    );
                    d.group = groups.iter().position(|g| *g == key).unwrap_or_else(|| {
                        groups.push(key);
                        groups.len() - 1
                    });
                    out.push(d);
                }
            }
            Err(why) => warnings.push(format!(
                "size effect: the cycle of {} is left out: {why}",
                segs[cycle[0]].id
            )),
        }
    }
    (out, warnings)
}

type CycleOut = (Vec<(usize, SegmentDrift)>, Vec<String>);

/// Aligns, navigates and fits the drifts of one cycle.
fn cycle_drifts(
    rec: &Recording,
    cycle: &[usize],
    c_pb: &Mat3,
    all_osc: &[usize],
) -> Result<CycleOut, String> {
    let segs = &rec.manifest.segments;
    let geos = geometries(&rec.manifest);
    let first = &segs[cycle[0]];
    let last = &segs[cycle[cycle.len() - 1]];
    // The static block to align on: the last one before the cycle under the same mount,
    // with no other oscillation in between.
    let prev_osc_end = all_osc
        .iter()
        .map(|&i| &segs[i])
        .filter(|s| s.t_end <= first.t_start && !cycle.iter().any(|&c| segs[c].id == s.id))
        .map(|s| s.t_end)
        .fold(f64::MIN, f64::max);
    let st = (0..segs.len())
        .filter(|&i| {
            let s = &segs[i];
            s.kind == SegmentKind::Static
                && s.t_end <= first.t_start
                && s.t_start >= prev_osc_end
                && (geos[i].c_pb - c_pb).norm() < 1e-6
        })
        .max_by(|a, b| segs[*a].t_end.total_cmp(&segs[*b].t_end))
        .ok_or("no static segment before it to align on (the procedure acquires one at rest)")?;
    let imu = &rec.imu;
    let a = imu.t.partition_point(|&t| t < segs[st].t_start);
    let a_end = imu.t.partition_point(|&t| t <= segs[st].t_end);
    let b = imu.t.partition_point(|&t| t <= last.t_end);
    if a_end < a + 10 || b < a_end + 10 {
        return Err("too few IMU samples".into());
    }
    let t = &imu.t[a..b];
    let step = crate::fit::stats::median_step(t);
    if let Some(k) = (1..t.len()).find(|&k| t[k] - t[k - 1] > 10.0 * step + 0.01) {
        return Err(format!(
            "the IMU stream has a gap of {:.3} s at t = {:.3} s, which breaks the navigation",
            t[k] - t[k - 1],
            t[k - 1]
        ));
    }
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
            segs[st].id,
            match e {
                ratecal_physics::nav::AlignError::NotAtRest =>
                    "its mean specific force is not gravity (was the IMU at rest?)",
                ratecal_physics::nav::AlignError::NoNorth =>
                    "the gyros do not resolve the Earth's horizontal rate",
            }
        )
    })?;
    let nav = navigate(t, &w, &f, &c0, &site, false);
    let g_int = regressors(t, &w, &nav.c_lb, &site.earth_rate_l());
    let mut out = Vec::new();
    let mut warnings = Vec::new();
    for &i in cycle {
        let s = &segs[i];
        let Some(period) = s.period_s.filter(|p| *p > 0.0 && p.is_finite()) else {
            warnings.push(format!(
                "size effect: segment {} has no period; left out",
                s.id
            ));
            continue;
        };
        let n_per = ((s.t_end - s.t_start) / period + 1e-9).floor();
        if n_per < 5.0 {
            warnings.push(format!(
                "size effect: segment {} holds fewer than 5 whole periods; left out",
                s.id
            ));
            continue;
        }
        let span = (s.t_start, s.t_start + n_per * period);
        let k0 = t.partition_point(|&x| x < span.0);
        let k1 = t.partition_point(|&x| x <= span.1);
        let ts = &t[k0..k1];
        let t_mid = 0.5 * (span.0 + span.1);
        let mut d = SegmentDrift {
            id: s.id.clone(),
            group: 0,
            period_s: period,
            span_s: span,
            t_mid_s: t_mid,
            drift_mps2: [0.0; 2],
            u_mps2: [0.0; 2],
            trend: [(0.0, 0.0); 2],
            h: [[0.0; 6]; 2],
            h_trend: [[0.0; 6]; 2],
            velocity: Vec::new(),
        };
        let blocks = Blocks::new(ts, span.0, period, n_per as usize, t_mid);
        for c in 0..2 {
            let v: Vec<f64> = nav.v_l[k0..k1].iter().map(|v| v[c]).collect();
            let q = blocks.fit(&v);
            d.drift_mps2[c] = q.c1;
            d.u_mps2[c] = q.u1;
            d.trend[c] = (2.0 * q.c2, 2.0 * q.u2);
            for m in 0..6 {
                let g: Vec<f64> = g_int[k0..k1].iter().map(|g| g[m][c]).collect();
                let q = blocks.fit(&g);
                d.h[c][m] = q.c1;
                d.h_trend[c][m] = 2.0 * q.c2;
            }
        }
        let every = ((1.0 / step).round() as usize).max(1);
        d.velocity = (k0..k1)
            .step_by(every)
            .map(|k| [t[k], nav.v_l[k].x, nav.v_l[k].y])
            .collect();
        out.push((i, d));
    }
    Ok((out, warnings))
}

/// Integrated horizontal acceleration error per metre of each coordinate, per sample:
/// accelerometer i gains `(dw x e_j)_i + w_i w_j` per metre of `r_ij`, seen in L along
/// `C_LB e_i`.
fn regressors(t: &[f64], w_ib: &[Vec3], c_lb: &[Mat3], omega_l: &Vec3) -> Vec<[[f64; 2]; 6]> {
    let w: Vec<Vec3> = w_ib
        .iter()
        .zip(c_lb)
        .map(|(w, c)| w - c.transpose() * omega_l)
        .collect();
    let dw = angular_accel(t, &w);
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

/// Whole periods of a span: each period's mean removes the swaying's own periodic part.
struct Blocks {
    ranges: Vec<(usize, usize)>,
    tau: Vec<f64>,
}

/// A quadratic `c0 + c1 tau + c2 tau^2` through block means, with uncertainties.
struct Quad {
    c1: f64,
    u1: f64,
    c2: f64,
    u2: f64,
}

impl Blocks {
    fn new(t: &[f64], t0: f64, period: f64, n: usize, t_mid: f64) -> Self {
        let mut ranges = Vec::with_capacity(n);
        let mut tau = Vec::with_capacity(n);
        for b in 0..n {
            let (lo, hi) = (t0 + b as f64 * period, t0 + (b + 1) as f64 * period);
            let k0 = t.partition_point(|&x| x < lo);
            let k1 = t.partition_point(|&x| x < hi);
            if k1 > k0 {
                ranges.push((k0, k1));
                tau.push(t[k0..k1].iter().sum::<f64>() / (k1 - k0) as f64 - t_mid);
            }
        }
        Blocks { ranges, tau }
    }

    fn fit(&self, y: &[f64]) -> Quad {
        let yb: Vec<f64> = self
            .ranges
            .iter()
            .map(|&(a, b)| y[a..b].iter().sum::<f64>() / (b - a) as f64)
            .collect();
        let n = yb.len();
        let mut ata = nalgebra::Matrix3::<f64>::zeros();
        let mut aty = Vec3::zeros();
        for (tau, y) in self.tau.iter().zip(&yb) {
            let row = Vec3::new(1.0, *tau, tau * tau);
            ata += row * row.transpose();
            aty += row * *y;
        }
        let Some(inv) = ata.try_inverse().filter(|_| n > 3) else {
            return Quad {
                c1: 0.0,
                u1: f64::INFINITY,
                c2: 0.0,
                u2: f64::INFINITY,
            };
        };
        let c = inv * aty;
        let rss: f64 = self
            .tau
            .iter()
            .zip(&yb)
            .map(|(tau, y)| (y - c[0] - c[1] * tau - c[2] * tau * tau).powi(2))
            .sum();
        let s2 = (rss / (n - 3) as f64).max(1e-30);
        Quad {
            c1: c[1],
            u1: (s2 * inv[(1, 1)]).sqrt(),
            c2: c[2],
            u2: (s2 * inv[(2, 2)]).sqrt(),
        }
    }
}
