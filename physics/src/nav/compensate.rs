//! Size-effect compensation, Kozlov & Kapralov's equation (1): each accelerometer output is
//! brought from its sensing point to the IMU reference centre.

use crate::{Mat3, Vec3};

/// Angular acceleration at each sample (rad/s^2) by central differences of the rates `w`
/// (rad/s) at times `t` (s); one-sided at the ends.
pub fn angular_accel(t: &[f64], w: &[Vec3]) -> Vec<Vec3> {
    let n = t.len().min(w.len());
    (0..n)
        .map(|k| {
            let (a, b) = (k.saturating_sub(1), (k + 1).min(n - 1));
            let dt = t[b] - t[a];
            if dt > 0.0 {
                (w[b] - w[a]) / dt
            } else {
                Vec3::zeros()
            }
        })
        .collect()
}

/// Specific force at the reference centre from accelerometer outputs `f_b` (m/s^2), body
/// rate `w` (rad/s), its derivative `dw` (rad/s^2) and sensing points `r` (rows `r_i`, m):
/// `f_i'' = f_i' - e_i . (dw x r_i + w x (w x r_i))`.
pub fn compensate(f_b: &Vec3, w: &Vec3, dw: &Vec3, r: &Mat3) -> Vec3 {
    Vec3::from_fn(|i, _| {
        let r_i: Vec3 = r.row(i).transpose();
        f_b[i] - (dw.cross(&r_i) + w.cross(&w.cross(&r_i)))[i]
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{AxisMotion, Geometry, ImuErrors, Site, TableState};

    #[test]
    fn undoes_the_measurement_models_lever_arm() {
        // The measurement model puts accelerometer i at R_i; compensating with r = R brings
        // every output to the table centre, which reads gravity alone.
        let site = Site {
            latitude_deg: 10.0,
            gravity_mps2: 9.78,
        };
        let geo = Geometry::seed();
        let lever = Mat3::new(0.01, 0.02, -0.03, 0.004, -0.02, 0.05, 0.03, 0.01, 0.02);
        let s = TableState {
            outer: AxisMotion {
                angle: 0.3,
                rate: 1.2,
                accel: -2.0,
            },
            inner: AxisMotion {
                angle: -0.7,
                rate: 0.8,
                accel: 3.0,
            },
        };
        let imu = ImuErrors {
            lever_m: lever,
            ..Default::default()
        };
        let (sensed, _) = imu.measure(&s, &geo, &site, imu.t_ref_c);
        let f_b0 = s.f_b(&geo, &site, &Vec3::zeros());
        let w = s.w_b(&geo);
        let dw = geo.c_pb.transpose() * s.dw_p(&geo);
        let f = compensate(&sensed, &w, &dw, &lever);
        assert!((f - f_b0).norm() < 1e-12, "{f} vs {f_b0}");
    }

    #[test]
    fn angular_accel_of_a_ramp() {
        let t: Vec<f64> = (0..5).map(|k| k as f64 * 0.1).collect();
        let w: Vec<Vec3> = t.iter().map(|t| Vec3::new(2.0 * t, -t, 0.5)).collect();
        for dw in angular_accel(&t, &w) {
            assert!((dw - Vec3::new(2.0, -1.0, 0.0)).norm() < 1e-12);
        }
    }
}
