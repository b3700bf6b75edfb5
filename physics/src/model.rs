//! The IMU measurement model (spec/physics.md, "The IMU measurement model"), noise-free.
//! Noise, bias wander and the time offset belong to whoever produces samples (the
//! simulator evaluates the motion at `t - tau`).

use crate::{DEG, Geometry, Mat3, Site, TableState, Vec3};
use serde::{Deserialize, Serialize};

/// Deterministic error parameters of an IMU, in the spec's internal units.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ImuErrors {
    /// `K_a`: accelerometer sensitivity matrix (diagonal 1 + scale error, off-diagonal misalignment).
    pub k_a: Mat3,
    /// `b_a`: accelerometer bias, m/s^2 (output at zero input).
    pub b_a: Vec3,
    /// `K_g`: gyro sensitivity matrix.
    pub k_g: Mat3,
    /// `b_g`: gyro bias, deg/s (output at zero input, at `t_ref_c`).
    pub b_g: Vec3,
    /// `G`: gyro sensitivity to specific force, (deg/s) per (m/s^2).
    pub g_sens: Mat3,
    /// Rows are `R_i`: accelerometer i's sensing point, body axes, metres, from the table axes' intersection.
    pub lever_m: Mat3,
    /// Gyro thermal drift, (deg/s) per degC.
    pub gyro_thermal: Vec3,
    /// Accelerometer thermal drift, (m/s^2) per degC.
    pub accel_thermal: Vec3,
    /// Reference temperature of the biases, degC.
    pub t_ref_c: f64,
    /// Gyro scale nonlinearity, ppm per deg/s: output gains `n_i w_i |w_i|`.
    pub gyro_nonlinearity: Vec3,
}

impl Default for ImuErrors {
    fn default() -> Self {
        ImuErrors {
            k_a: Mat3::identity(),
            b_a: Vec3::zeros(),
            k_g: Mat3::identity(),
            b_g: Vec3::zeros(),
            g_sens: Mat3::zeros(),
            lever_m: Mat3::zeros(),
            gyro_thermal: Vec3::zeros(),
            accel_thermal: Vec3::zeros(),
            t_ref_c: 20.0,
            gyro_nonlinearity: Vec3::zeros(),
        }
    }
}

/// What ideal sensors read at one instant: specific force at each sensing point projected
/// on its axis (m/s^2), inertial rate (deg/s), and specific force at the reference point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IdealOutputs {
    /// `s_i = e_i . f_B(C_PB R_i)`, m/s^2.
    pub s: Vec3,
    /// `w_ib`, deg/s.
    pub w_ib_dps: Vec3,
    /// `f_B(0)`, m/s^2.
    pub f_b0: Vec3,
}

/// Noise-free sensed quantities for a table state.
pub fn ideal_outputs(
    state: &TableState,
    geo: &Geometry,
    site: &Site,
    lever_m: &Mat3,
) -> IdealOutputs {
    let snap = state.snapshot(geo, site);
    let f_b0 = snap.f_b(&Vec3::zeros());
    let mut s = Vec3::zeros();
    for i in 0..3 {
        let r_i: Vec3 = lever_m.row(i).transpose();
        let f = if r_i == Vec3::zeros() {
            f_b0
        } else {
            snap.f_b(&(geo.c_pb * r_i))
        };
        s[i] = f[i];
    }
    IdealOutputs {
        s,
        w_ib_dps: snap.w_ib() / DEG,
        f_b0,
    }
}

impl ImuErrors {
    /// Noise-free accelerometer (m/s^2) and gyro (deg/s) outputs at temperature `temp_c`.
    pub fn measure(
        &self,
        state: &TableState,
        geo: &Geometry,
        site: &Site,
        temp_c: f64,
    ) -> (Vec3, Vec3) {
        let ideal = ideal_outputs(state, geo, site, &self.lever_m);
        self.apply(&ideal, temp_c)
    }

    /// Applies the error model to ideal sensed quantities.
    pub fn apply(&self, ideal: &IdealOutputs, temp_c: f64) -> (Vec3, Vec3) {
        let dt = temp_c - self.t_ref_c;
        let a = self.k_a * ideal.s + self.b_a + self.accel_thermal * dt;
        let w = ideal.w_ib_dps;
        let nonlin = Vec3::from_fn(|i, _| self.gyro_nonlinearity[i] * 1e-6 * w[i] * w[i].abs());
        let g =
            self.k_g * w + self.b_g + self.gyro_thermal * dt + self.g_sens * ideal.f_b0 + nonlin;
        (a, g)
    }
}
