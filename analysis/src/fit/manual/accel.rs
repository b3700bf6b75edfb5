//! The accelerometer model `a = K_a s + b_a` from static poses. Unknown attitudes (Tedaldi,
//! Pretto, Menegatti 2014; imu_tk): gravity's magnitude alone, by Levenberg-Marquardt over
//! the poses' means; three of the nine terms of `K_a` are then fixed by convention (gravity's
//! direction is unknown, so the body frame may turn freely): `K_a` upper triangular,
//! `K_a[y][x] = K_a[z][x] = K_a[z][y] = 0`, as imu_tk's upper-triangular `T_a`. Nominal faces
//! (Ferraris): the six-face solution, each face's tilt a nuisance whose prior standard
//! deviation is the face's tolerance: the values are those of exact faces, the tilts widen
//! the uncertainties.

use super::Triad;
use super::data::Pose;
use super::lsq;
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

/// The convention that fixes three misalignments when the attitude is unknown.
pub(crate) const CONVENTION: &str = "K_a upper triangular: accel.misalignment.yx, .zx and .zy \
    fixed at 0 (the body z axis is the z accelerometer's sensing axis, the body y axis lies \
    in the plane of the y and z sensing axes), as imu_tk's upper-triangular T_a";

/// The off-diagonal terms of `K_a` the poses determine with an unknown attitude.
const UPPER: [(usize, usize); 3] = [(0, 1), (0, 2), (1, 2)];

/// Parameters of the full (9) or reduced (6: bias and scale) unknown-attitude model.
fn model(x: &DVector<f64>) -> (Matrix3<f64>, Vector3<f64>) {
    let b = Vector3::new(x[0], x[1], x[2]);
    let mut k = Matrix3::from_diagonal(&Vector3::new(x[3], x[4], x[5]));
    if x.len() == 9 {
        for (p, &(i, j)) in UPPER.iter().enumerate() {
            k[(i, j)] = x[6 + p];
        }
    }
    (k, b)
}

/// Each pose's `|K^-1 (a - b)| - g`.
fn magnitude_residuals(poses: &[&Pose], g: f64, x: &DVector<f64>) -> DVector<f64> {
    let (k, b) = model(x);
    let inv = k.try_inverse().unwrap_or_else(Matrix3::identity);
    DVector::from_fn(poses.len(), |p, _| {
        (inv * (Vector3::from(poses[p].f) - b)).norm() - g
    })
}

/// Fewest poses for the full model (bias, scale, three misalignments): the procedure's
/// twelve, which also leaves three degrees of freedom for the noise.
pub(crate) const FULL_MIN_POSES: usize = 12;
/// Fewest poses for bias and scale (six terms, one degree of freedom for the noise).
pub(crate) const REDUCED_MIN_POSES: usize = 7;

/// The unknown-attitude fit (gravity's magnitude `g`), or `None` when too few poses.
pub(crate) fn from_magnitude(poses: &[&Pose], g: f64) -> Option<Triad> {
    let full = poses.len() >= FULL_MIN_POSES;
    if poses.len() < REDUCED_MIN_POSES {
        return None;
    }
    let mut x0 = vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0];
    if full {
        x0.extend([0.0; 3]);
    }
    let f = |x: &DVector<f64>| magnitude_residuals(poses, g, x);
    let fit = lsq::solve(&f, DVector::from_vec(x0.clone()), 1.0).or_else(|| {
        full.then(|| lsq::solve(&f, DVector::from_vec(x0[..6].to_vec()), 1.0))
            .flatten()
    })?;
    let (k, b) = model(&fit.x);
    let mut t = Triad::new("accel", k, b, "m/s^2");
    for i in 0..3 {
        t.bias(i, fit.x[i], fit.cov[(i, i)].sqrt());
        t.scale(i, fit.x[3 + i], fit.cov[(3 + i, 3 + i)].sqrt());
    }
    let why = "gravity's direction is unknown at every pose: fixed at 0 by the convention \
               (K_a upper triangular, as imu_tk)";
    let few = format!(
        "{} poses: the misalignments need at least {FULL_MIN_POSES} poses of varied attitude",
        poses.len()
    );
    for (i, j) in [(1, 0), (2, 0), (2, 1)] {
        t.unobservable(i, j, if fit.x.len() == 9 { why } else { &few });
    }
    for (p, &(i, j)) in UPPER.iter().enumerate() {
        if fit.x.len() == 9 {
            t.misalignment(i, j, fit.x[6 + p], fit.cov[(6 + p, 6 + p)].sqrt());
        } else {
            t.unobservable(i, j, &few);
        }
    }
    t.rms = fit.rms;
    Some(t)
}

/// The six-face solution over nominal faces, or `None` when the faces do not determine
/// every term (both faces of every axis are needed).
pub(crate) fn from_faces(poses: &[&Pose], g: f64) -> Option<Triad> {
    let faces: Vec<(&Pose, usize, f64)> = poses
        .iter()
        .filter_map(|p| p.face.map(|(j, s)| (*p, j, s)))
        .collect();
    let m = 3 * faces.len();
    // Unknowns: b (3), then K row-major (9).
    let mut a = DMatrix::zeros(m, 12);
    let mut y = DVector::zeros(m);
    for (r, (p, j, s)) in faces.iter().enumerate() {
        for i in 0..3 {
            a[(3 * r + i, i)] = 1.0;
            a[(3 * r + i, 3 + 3 * i + j)] = s * g;
            y[3 * r + i] = p.f[i];
        }
    }
    let inv = lsq::normal_inverse(&a)?;
    let gain = &inv * a.transpose();
    let x = &gain * &y;
    let k = Matrix3::from_fn(|i, j| x[3 + 3 * i + j]);
    let b = Vector3::new(x[0], x[1], x[2]);
    let resid = &y - &a * &x;
    let dof = m.saturating_sub(12);
    let s2 = if dof > 0 {
        resid.norm_squared() / dof as f64
    } else {
        0.0
    };
    let sigma = face_covariance(&faces, &k, g, s2);
    let cov = &gain * sigma * gain.transpose();
    let mut t = Triad::new("accel", k, b, "m/s^2");
    for i in 0..3 {
        t.bias(i, b[i], cov[(i, i)].sqrt());
        for j in 0..3 {
            let c = 3 + 3 * i + j;
            if i == j {
                t.scale(i, k[(i, i)], cov[(c, c)].sqrt());
            } else {
                t.misalignment(i, j, k[(i, j)], cov[(c, c)].sqrt());
            }
        }
    }
    t.rms = (resid.norm_squared() / m as f64).sqrt();
    Some(t)
}

/// The covariance of the faces' means: their noise and the misfit (`s2`), plus each
/// face's tilt (two angles of standard deviation `tol` about the axes across the face,
/// first order; the loss of the component along the face, second order).
fn face_covariance(
    faces: &[(&Pose, usize, f64)],
    k: &Matrix3<f64>,
    g: f64,
    s2: f64,
) -> DMatrix<f64> {
    let m = 3 * faces.len();
    let mut sigma = DMatrix::zeros(m, m);
    for (r, (p, j, _)) in faces.iter().enumerate() {
        let e = Vector3::ith(*j, 1.0);
        let across = Matrix3::identity() - e * e.transpose();
        let tilt = k * across * k.transpose() * (g * p.tol_rad).powi(2)
            + k * e * e.transpose() * k.transpose() * (g * p.tol_rad.powi(2)).powi(2);
        for i in 0..3 {
            for l in 0..3 {
                sigma[(3 * r + i, 3 * r + l)] = tilt[(i, l)];
            }
            let mean_var = p.f_std[i].powi(2) / p.n as f64;
            sigma[(3 * r + i, 3 * r + i)] += mean_var + s2;
        }
    }
    sigma
}

/// The specific force of each pose through the calibration, m/s^2.
pub(crate) fn calibrated(t: &Triad, p: &Pose) -> Vector3<f64> {
    t.k.try_inverse().unwrap_or_else(Matrix3::identity) * (Vector3::from(p.f) - t.b)
}
