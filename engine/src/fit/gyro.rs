//! Gyro models: static bias and noise from the long static block, per-axis scale from
//! rate points with the bias held fixed (seed model), and the full 3x3 model.

use super::accel::{Sensor, k_name, k_param, model_residuals};
use super::lsq::Normal;
use super::prep::SegData;
use super::stats::{Inflation, mean, std};
use super::{AXES, Out, residual_stats};
use crate::results::Parameter;
use ratecal_physics::{Mat3, Vec3};

/// Static bias: mean output minus the Earth-rate reference over the block, after outlier
/// removal; its uncertainty from batch means (a wandering bias correlates the samples).
/// Returns the bias (deg/s) and its standard uncertainty per axis.
pub(crate) fn fit_bias(block: &SegData, scale: &Vec3, out: &mut Out) -> (Vec3, Vec3) {
    let mut b = Vec3::zeros();
    let mut ub = Vec3::zeros();
    let mut worst_noise = (0.0f64, 0.0f64);
    for ax in 0..3 {
        let r: Vec<f64> = (0..block.t.len())
            .map(|i| block.gyro[ax][i] - (1.0 + scale[ax]) * block.w_ref[ax][i])
            .collect();
        let keep = &block.keep_g;
        let m = mean(&r, keep);
        let sd = std(&r, keep);
        let n = keep.iter().filter(|k| **k).count() as f64;
        let mut infl = Inflation::default();
        infl.add(&r, keep);
        b[ax] = m;
        ub[ax] = sd * (infl.factor() / n).sqrt();
        let name = AXES[ax];
        out.params.insert(
            format!("gyro.bias.{name}"),
            Parameter::estimate(m, ub[ax], "deg/s"),
        );
        let u_sd = sd / (2.0 * (n - 1.0)).sqrt();
        out.params.insert(
            format!("gyro.noise.{name}"),
            Parameter::estimate(sd, u_sd, "deg/s"),
        );
        if sd > worst_noise.0 {
            worst_noise = (sd, u_sd);
        }
        let centred: Vec<f64> = r.iter().map(|v| v - m).collect();
        out.residuals
            .push(residual_stats(block, "gyro", ax, &centred, keep, "deg/s"));
    }
    out.quantities.insert("gyro.bias.std".into(), worst_noise);
    out.quantities.insert("gyro.noise".into(), worst_noise);
    (b, ub)
}

/// One rate point: segment means of output and reference, and the variance of the
/// output mean from within the segment.
struct Point {
    o: Vec3,
    r: Vec3,
    var_o: Vec3,
}

fn points(segs: &[&SegData]) -> Vec<Point> {
    segs.iter()
        .map(|s| {
            let mut p = Point {
                o: Vec3::zeros(),
                r: Vec3::zeros(),
                var_o: Vec3::zeros(),
            };
            let n = s.keep_g.iter().filter(|k| **k).count() as f64;
            for ax in 0..3 {
                p.o[ax] = mean(&s.gyro[ax], &s.keep_g);
                p.r[ax] = mean(&s.w_ref[ax], &s.keep_g);
                let d: Vec<f64> = (0..s.t.len())
                    .map(|i| s.gyro[ax][i] - s.w_ref[ax][i])
                    .collect();
                let mut infl = Inflation::default();
                infl.add(&d, &s.keep_g);
                p.var_o[ax] = std(&d, &s.keep_g).powi(2) * infl.factor() / n;
            }
            p
        })
        .collect()
}

/// Smallest reference excursion (deg/s RMS over the rate points) that determines a scale.
const MIN_EXCITATION_DPS: f64 = 1.0;

/// Seed model: per axis `w = K (w_ref + b)` with the bias fixed; returns `K - 1` per axis
/// (0 where not determined).
pub(crate) fn fit_scale(
    segs: &[&SegData],
    axes: &[usize],
    bias: (Vec3, Vec3),
    out: &mut Out,
) -> Vec3 {
    let pts = points(segs);
    let (b, ub) = bias;
    let mut s_out = Vec3::zeros();
    for ax in 0..3 {
        let name = AXES[ax];
        if !axes.contains(&ax) {
            out.unobservable(
                &format!("gyro.scale.{name}"),
                "not included in the procedure's gyro scale fit",
            );
            continue;
        }
        let srr: f64 = pts.iter().map(|p| p.r[ax] * p.r[ax]).sum();
        let sr: f64 = pts.iter().map(|p| p.r[ax]).sum();
        if pts.len() < 2 || (srr / pts.len() as f64).sqrt() < MIN_EXCITATION_DPS {
            out.unobservable(
                &format!("gyro.scale.{name}"),
                "no rate point rotated the IMU about this axis",
            );
            continue;
        }
        let k = pts.iter().map(|p| p.r[ax] * (p.o[ax] - b[ax])).sum::<f64>() / srr;
        // Scatter of the points about the line (bias wander between the points shows
        // here), never below what the within-segment noise implies.
        let n = pts.len() as f64;
        let scatter = pts
            .iter()
            .map(|p| (p.o[ax] - b[ax] - k * p.r[ax]).powi(2))
            .sum::<f64>()
            / (n - 1.0);
        let white = pts.iter().map(|p| p.var_o[ax]).sum::<f64>() / n;
        let var_k = scatter.max(white) / srr + (sr / srr * ub[ax]).powi(2);
        s_out[ax] = k - 1.0;
        out.params.insert(
            format!("gyro.scale.{name}"),
            Parameter::estimate((k - 1.0) * 1e6, var_k.sqrt() * 1e6, "ppm"),
        );
    }
    let k = Mat3::from_diagonal(&(s_out + Vec3::repeat(1.0)));
    finish(segs, k, b, out);
    s_out
}

/// Full model from rate points: per output axis, a row of `K_g` and a bias; input axes
/// the motion did not excite are unobservable.
pub(crate) fn fit_full(segs: &[&SegData], out: &mut Out) {
    let pts = points(segs);
    let mut k = Mat3::identity();
    let mut b = Vec3::zeros();
    for ax in 0..3 {
        let mut ne = Normal::new(4);
        for p in &pts {
            ne.add(&[p.r[0], p.r[1], p.r[2], 1.0], p.o[ax]);
        }
        let excited: Vec<usize> = (0..3)
            .filter(|&j| {
                (pts.iter().map(|p| p.r[j] * p.r[j]).sum::<f64>() / pts.len().max(1) as f64).sqrt()
                    >= MIN_EXCITATION_DPS
            })
            .collect();
        let mut cols = excited.clone();
        cols.push(3);
        let sol = ne.solve(&cols);
        let white = pts.iter().map(|p| p.var_o[ax]).sum::<f64>() / pts.len().max(1) as f64;
        for j in 0..4 {
            let name = if j == 3 {
                format!("gyro.bias.{}", AXES[ax])
            } else {
                k_name("gyro", ax, j)
            };
            let (Some(sol), Some(c)) = (&sol, cols.iter().position(|&x| x == j)) else {
                out.unobservable(&name, "no rate point rotated the IMU about this input axis");
                continue;
            };
            let v = sol.x[c];
            let u = (sol.sigma2.max(white) * sol.inv[(c, c)]).sqrt();
            if j == 3 {
                b[ax] = v;
                out.params.insert(name, Parameter::estimate(v, u, "deg/s"));
            } else {
                k[(ax, j)] = v;
                out.params.insert(name, k_param(ax, j, v, u));
            }
        }
    }
    finish(segs, k, b, out);
}

fn finish(segs: &[&SegData], k: Mat3, b: Vec3, out: &mut Out) {
    let worst = model_residuals(segs, Sensor::Gyro, &k, &b, out);
    out.quantities.insert("gyro.residual.std".into(), worst);
    out.gyro_model = Some((k, b));
}

/// Rate of the bias random walk per axis, q^2 in (deg/s)^2 per s, from the segment means
/// of output minus model across the run (segments that did not rotate about the axis):
/// consecutive means differ by `q^2 dt` beyond their white-noise variances.
pub(crate) fn wander_q2(segs: &[&SegData], model: &(Mat3, Vec3)) -> Vec3 {
    let (k, b) = model;
    let mut q2 = Vec3::zeros();
    for ax in 0..3 {
        let mut pts: Vec<(f64, f64, f64)> = segs
            .iter()
            .filter(|s| mean(&s.w_ref[ax], &s.keep_g).abs() < MIN_EXCITATION_DPS)
            .map(|s| {
                let d: Vec<f64> = (0..s.t.len())
                    .map(|i| {
                        s.gyro[ax][i]
                            - b[ax]
                            - (0..3).map(|j| k[(ax, j)] * s.w_ref[j][i]).sum::<f64>()
                    })
                    .collect();
                let n = s.keep_g.iter().filter(|k| **k).count().max(1) as f64;
                let tm = (s.t[0] + s.t[s.t.len() - 1]) / 2.0;
                (tm, mean(&d, &s.keep_g), std(&d, &s.keep_g).powi(2) / n)
            })
            .collect();
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        let (mut num, mut den) = (0.0, 0.0);
        for w in pts.windows(2) {
            num += (w[1].1 - w[0].1).powi(2) - w[0].2 - w[1].2;
            den += w[1].0 - w[0].0;
        }
        if pts.len() >= 3 && den > 0.0 {
            q2[ax] = (num / den).max(0.0);
        }
    }
    q2
}
