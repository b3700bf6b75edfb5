//! Checks on the frame data that stations and recordings give: a mount `C_PB` must be a
//! proper rotation. One predicate serves the station loader and the recording reader.

use crate::Mat3;

/// Why a matrix is not a proper rotation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum NotARotation {
    /// A number is NaN or infinite (which a max-based orthonormality test would skip).
    NotFinite,
    /// `|R^T R - I|` reaches this (largest entry), above the tolerance.
    NotOrthonormal(f64),
    /// Orthonormal, but a reflection (determinant -1).
    Reflection,
}

impl std::fmt::Display for NotARotation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            NotARotation::NotFinite => write!(f, "holds a number that is not finite"),
            NotARotation::NotOrthonormal(e) => write!(f, "is not orthonormal (off by {e:.2e})"),
            NotARotation::Reflection => write!(f, "is a reflection (determinant -1)"),
        }
    }
}

/// Whether `r` is a proper rotation to `tol` (largest entry of `|R^T R - I|`).
pub fn check_rotation(r: &Mat3, tol: f64) -> Result<(), NotARotation> {
    if !r.iter().all(|x| x.is_finite()) {
        return Err(NotARotation::NotFinite);
    }
    let err = (r.transpose() * r - Mat3::identity()).abs().max();
    if err > tol {
        Err(NotARotation::NotOrthonormal(err))
    } else if r.determinant() < 0.0 {
        Err(NotARotation::Reflection)
    } else {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{DEG, Vec3, rotation};

    #[test]
    fn proper_rotations_pass_and_others_say_why() {
        let yaw = rotation(&Vec3::z(), 30.0 * DEG) * rotation(&Vec3::x(), -70.0 * DEG);
        assert_eq!(check_rotation(&yaw, 1e-12), Ok(()));
        let mirror = Mat3::from_diagonal(&Vec3::new(1.0, 1.0, -1.0));
        assert_eq!(check_rotation(&mirror, 1e-6), Err(NotARotation::Reflection));
        let scaled = Mat3::from_diagonal(&Vec3::new(1.01, 1.0, 1.0));
        match check_rotation(&scaled, 1e-3) {
            // (1.01^2 - 1 = 0.0201)
            Err(NotARotation::NotOrthonormal(e)) => assert!((e - 0.0201).abs() < 1e-12),
            other => panic!("{other:?}"),
        }
        assert_eq!(check_rotation(&scaled, 0.05), Ok(()));
        let mut nan = Mat3::identity();
        nan[(0, 0)] = f64::NAN;
        assert_eq!(check_rotation(&nan, 1e-6), Err(NotARotation::NotFinite));
    }
}
