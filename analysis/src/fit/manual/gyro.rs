//! The gyro model `w = K_g w_ib + b_g` from the turns between poses. Unknown attitudes:
//! the bias from the initial rest, then `K_g` (scale and every cross-axis term, in the
//! accelerometers' body frame) by integrating each turn's raw samples and matching the
//! change of gravity's direction from one pose to the next (imu_tk). Nominal faces: the
//! bias from the faces' mean (the Earth's rate cancels between opposite faces), then the
//! column of `K_g` of each turn about a stated body axis: the integrated rate over its
//! nominal angle (Ferraris).

use super::Triad;
use super::data::{Pose, Turn};
use super::lsq;
use nalgebra::{DVector, Matrix3, Rotation3, Vector3};

/// The Earth's rate, deg/s: an unknown attitude leaves its projection in the bias.
const EARTH_DPS: f64 = 7.292_115e-5 * 57.295_779_513_082_32;

/// A turn ready to integrate: midpoint raw rates less the bias (deg/s), steps (s), and the
/// gravity directions before and after (unit, body axes).
pub(crate) struct Prepared {
    pub mid: Vec<Vector3<f64>>,
    pub dt: Vec<f64>,
    pub from: Vector3<f64>,
    pub to: Vector3<f64>,
}

impl Prepared {
    /// The turn of `t` with `bias`, between the calibrated gravity directions `from`, `to`.
    pub(crate) fn of(t: &Turn, bias: &Vector3<f64>, from: Vector3<f64>, to: Vector3<f64>) -> Self {
        let n = t.t.len();
        let w = |r: usize| Vector3::from(t.w[r]) - bias;
        Prepared {
            mid: (1..n).map(|r| (w(r - 1) + w(r)) * 0.5).collect(),
            dt: (1..n).map(|r| t.t[r] - t.t[r - 1]).collect(),
            from: from.normalize(),
            to: to.normalize(),
        }
    }

    /// Gravity's direction after the turn as the gyros calibrated by `k_inv` carry it.
    pub(crate) fn carried(&self, k_inv: &Matrix3<f64>) -> Vector3<f64> {
        let mut r = Rotation3::identity();
        for (w, dt) in self.mid.iter().zip(&self.dt) {
            let step = k_inv * w * (dt * std::f64::consts::PI / 180.0);
            r *= Rotation3::new(step);
        }
        r.inverse() * self.from
    }

    /// Angle between the carried and the measured direction after the turn, deg.
    pub(crate) fn miss_deg(&self, k_inv: &Matrix3<f64>) -> f64 {
        let c = self.carried(k_inv);
        c.cross(&self.to).norm().atan2(c.dot(&self.to)).to_degrees()
    }
}

/// The order of the off-diagonal terms in the full model's parameters.
const OFF: [(usize, usize); 6] = [(0, 1), (0, 2), (1, 0), (1, 2), (2, 0), (2, 1)];

fn model(x: &DVector<f64>) -> Matrix3<f64> {
    let mut k = Matrix3::from_diagonal(&Vector3::new(x[0], x[1], x[2]));
    if x.len() == 9 {
        for (p, &(i, j)) in OFF.iter().enumerate() {
            k[(i, j)] = x[3 + p];
        }
    }
    k
}

/// Fewest turns for every term of `K_g` (two equations a turn, nine terms).
pub(crate) const FULL_MIN_TURNS: usize = 11;
/// Fewest turns for the scales alone.
pub(crate) const REDUCED_MIN_TURNS: usize = 3;

/// The bias from the rest `p`: its mean, u from its noise and the Earth's rate it holds.
pub(crate) fn rest_bias(p: &Pose) -> (Vector3<f64>, [f64; 3]) {
    let u = std::array::from_fn(|k| {
        ((p.w_std[k].powi(2) / p.n as f64) + EARTH_DPS.powi(2) / 3.0).sqrt()
    });
    (Vector3::from(p.w), u)
}

/// The miss of every turn (three rows a turn) with the gyro model `x`.
fn misses(turns: &[Prepared], x: &DVector<f64>) -> DVector<f64> {
    let k_inv = model(x).try_inverse().unwrap_or_else(Matrix3::identity);
    let mut r = DVector::zeros(3 * turns.len());
    for (p, t) in turns.iter().enumerate() {
        let d = t.to - t.carried(&k_inv);
        r.rows_mut(3 * p, 3).copy_from(&d);
    }
    r
}

/// The unknown-attitude gyro fit over `turns`, with the bias (and its u) of the rest.
/// `shifted` holds the same turns prepared with one axis's bias moved by its u (one set an
/// axis): the bias is fixed before the fit, so its error bends every turn alike, which the
/// residuals' scatter does not show; each set is fitted again and the change of each
/// parameter adds to its variance.
pub(crate) fn from_turns(
    turns: &[Prepared],
    bias: (Vector3<f64>, [f64; 3]),
    shifted: &[Vec<Prepared>],
) -> Option<Triad> {
    if turns.len() < REDUCED_MIN_TURNS {
        return None;
    }
    let full = turns.len() >= FULL_MIN_TURNS;
    let mut x0 = vec![1.0, 1.0, 1.0];
    if full {
        x0.extend([0.0; 6]);
    }
    let fit = lsq::solve(&|x| misses(turns, x), DVector::from_vec(x0), 2.0 / 3.0)?;
    let mut var = fit.cov.diagonal();
    for set in shifted {
        if let Some(moved) = lsq::solve(&|x| misses(set, x), fit.x.clone(), 2.0 / 3.0) {
            var += (&moved.x - &fit.x).map(|d| d * d);
        }
    }
    let mut t = Triad::new("gyro", model(&fit.x), bias.0, "deg/s");
    for i in 0..3 {
        t.bias(i, bias.0[i], bias.1[i]);
        t.scale(i, fit.x[i], var[i].sqrt());
    }
    let few = format!(
        "{} turns between poses: the cross-axis terms need at least {FULL_MIN_TURNS}",
        turns.len()
    );
    for (p, &(i, j)) in OFF.iter().enumerate() {
        if full {
            t.misalignment(i, j, fit.x[3 + p], var[3 + p].sqrt());
        } else {
            t.unobservable(i, j, &few);
        }
    }
    t.rms = fit.rms;
    Some(t)
}

/// The bias of nominal faces: the mean of their means, u from their spread.
pub(crate) fn faces_bias(faces: &[&Pose]) -> (Vector3<f64>, [f64; 3]) {
    let n = faces.len().max(1) as f64;
    let mean = faces
        .iter()
        .fold(Vector3::zeros(), |a, p| a + Vector3::from(p.w))
        / n;
    let u = std::array::from_fn(|k| {
        let var = faces
            .iter()
            .map(|p| (p.w[k] - mean[k]).powi(2))
            .sum::<f64>()
            / (n - 1.0).max(1.0);
        (var / n).sqrt()
    });
    (mean, u)
}

/// The Ferraris gyro: each turn about a stated body axis by its nominal angle gives that
/// column of `K_g`; `tol_rad` is how well the axis and the angle are known. `None` unless
/// all three axes were turned.
pub(crate) fn from_axis_turns(
    turns: &[Turn],
    bias: (Vector3<f64>, [f64; 3]),
    tol_rad: f64,
) -> Option<Triad> {
    let mut k = Matrix3::identity();
    let mut u = Matrix3::zeros();
    let mut seen = [false; 3];
    for t in turns {
        let (Some((j, sign)), Some(angle)) = (t.axis, t.angle_deg) else {
            continue;
        };
        // Another system's manifest may say anything: a turn of no angle determines nothing.
        if !angle.is_finite() || angle.abs() < 1.0 || t.t.len() < 2 {
            continue;
        }
        let n = t.t.len();
        let mut sum = Vector3::zeros();
        for r in 1..n {
            let w = (Vector3::from(t.w[r - 1]) + Vector3::from(t.w[r])) * 0.5 - bias.0;
            sum += w * (t.t[r] - t.t[r - 1]);
        }
        let dur = t.t[n.max(1) - 1] - t.t[0];
        let theta = sign * angle;
        k.set_column(j, &(sum / theta));
        for i in 0..3 {
            let from_bias = bias.1[i] * dur / theta.abs();
            // The angle is known within the tolerance (scale), the axis too (cross terms).
            let from_tol = if i == j {
                tol_rad.to_degrees() / theta.abs()
            } else {
                tol_rad
            };
            u[(i, j)] = (from_bias.powi(2) + from_tol.powi(2)).sqrt() * k[(j, j)].abs();
        }
        seen[j] = true;
    }
    if !seen.iter().all(|s| *s) {
        return None;
    }
    let mut g = Triad::new("gyro", k, bias.0, "deg/s");
    for i in 0..3 {
        g.bias(i, bias.0[i], bias.1[i]);
        for j in 0..3 {
            if i == j {
                g.scale(i, k[(i, i)], u[(i, i)]);
            } else {
                g.misalignment(i, j, k[(i, j)], u[(i, j)]);
            }
        }
    }
    Some(g)
}
