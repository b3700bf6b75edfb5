//! Initial alignment at rest: levelling by the accelerometers, heading by gyrocompassing.

use crate::{Mat3, Vec3};

/// Why an alignment could not be made.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AlignError {
    /// The mean specific force is not close to gravity (the IMU was not at rest).
    NotAtRest,
    /// The horizontal Earth rate is lost in the gyro errors (or the site is at a pole).
    NoNorth,
}

/// `C_LB` from the mean specific force `f_b` (m/s^2) and mean inertial rate `w_ib` (rad/s)
/// of a static block, with `g` the local gravity.
pub fn align(f_b: &Vec3, w_ib: &Vec3, g: f64) -> Result<Mat3, AlignError> {
    let n = f_b.norm();
    if !n.is_finite() || (n - g).abs() > 0.05 * g {
        return Err(AlignError::NotAtRest);
    }
    let up = f_b / n;
    let w_h = w_ib - up * w_ib.dot(&up);
    // A tenth of the Earth rate's horizontal part at 85 deg latitude.
    if !w_h.norm().is_finite() || w_h.norm() < 6e-7 {
        return Err(AlignError::NoNorth);
    }
    let north = w_h.normalize();
    let east = north.cross(&up);
    // Rows of C_LB are the L axes (E, N, U) written in body axes.
    Ok(Mat3::from_rows(&[
        east.transpose(),
        north.transpose(),
        up.transpose(),
    ]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Geometry, Site, TableState};

    #[test]
    fn recovers_a_tilted_attitude() {
        let site = Site {
            latitude_deg: 55.7,
            gravity_mps2: 9.8156,
        };
        let geo = Geometry::vertical_outer();
        let s = TableState::at_rest_deg(37.0, 4.0);
        let snap = s.snapshot(&geo, &site);
        let c = align(&snap.gravity_b, &snap.w_ib(), site.gravity_mps2).unwrap();
        let want = geo.c_lb(37.0 * crate::DEG, 4.0 * crate::DEG);
        assert!((c - want).norm() < 1e-12, "{c} vs {want}");
    }

    #[test]
    fn refuses_motion_and_the_pole() {
        let w = Vec3::new(0.0, 4e-5, 6e-5);
        assert_eq!(
            align(&Vec3::new(0.0, 0.0, 12.0), &w, 9.8),
            Err(AlignError::NotAtRest)
        );
        assert_eq!(
            align(&Vec3::new(0.0, 0.0, 9.8), &Vec3::new(0.0, 0.0, 7e-5), 9.8),
            Err(AlignError::NoNorth)
        );
    }
}
