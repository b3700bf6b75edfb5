//! The statistics explain judges every candidate with: a Wald test on a fit's columns, its
//! chi-square tail probability, and the information criterion that ranks candidates. Pure
//! statistics: nothing here knows the recording or the models.

use crate::fit::joint::Fit;
use nalgebra::DMatrix;
use statrs::distribution::{ChiSquared, ContinuousCDF};

/// Wald statistic of the estimated columns of an effect, with its degrees of freedom.
pub(crate) fn wald(fit: &Fit, cols: &[usize]) -> (f64, usize) {
    let est: Vec<usize> = cols
        .iter()
        .copied()
        .filter(|g| fit.estimated.contains(g))
        .collect();
    let k = est.len();
    if k == 0 {
        return (0.0, 0);
    }
    let cov = DMatrix::from_fn(k, k, |i, j| fit.cov[(est[i], est[j])]);
    let th = nalgebra::DVector::from_fn(k, |i, _| fit.theta[est[i]]);
    // A non-finite covariance or value says nothing (and nalgebra's SVD of a non-finite
    // matrix never converges).
    if cov.iter().chain(th.iter()).any(|v| !v.is_finite()) {
        return (0.0, 0);
    }
    // Pseudo-inverse by the symmetric eigen-decomposition, with a bounded number of
    // sweeps (nalgebra's `pseudo_inverse` runs an SVD with no bound, which on an
    // ill-conditioned matrix can run forever): a direction the covariance cannot resolve
    // adds nothing.
    let tol = 1e-12 * cov.norm();
    let Some(eig) = nalgebra::SymmetricEigen::try_new(cov, f64::EPSILON, EIGEN_SWEEPS) else {
        return (0.0, 0);
    };
    let proj = eig.eigenvectors.transpose() * &th;
    let chi2 = proj
        .iter()
        .zip(eig.eigenvalues.iter())
        .filter(|(_, l)| **l > tol)
        .map(|(p, l)| p * p / l)
        .sum();
    (chi2, k)
}

/// Iterations allowed to an eigen-decomposition before it is given up as not converging.
const EIGEN_SWEEPS: usize = 10_000;

/// Upper-tail probability of a chi-square statistic.
pub(crate) fn p_value(chi2: f64, dof: usize) -> f64 {
    if dof == 0 {
        return 1.0;
    }
    ChiSquared::new(dof as f64).map_or(1.0, |d| d.sf(chi2))
}

/// The drop of the Bayesian information criterion an effect brings: its statistic less
/// `ln(n)` per parameter. Among significant candidates the one that explains most per
/// parameter wins, so a general term (nine g-sensitivities) does not take the place of
/// the physics it contains (the Earth's rate, two parameters).
pub(crate) fn score(chi2: f64, dof: usize, n: usize) -> f64 {
    chi2 - dof as f64 * (n.max(2) as f64).ln()
}
