//! The IMU's deterministic errors as a station states them (spec/physics.md, "The IMU
//! measurement model"), and their translation into registry terms. The model itself (what
//! each term adds) lives in the effect registry; this is only the truth's container.

use crate::effects::{ImuModel, Signals};
use crate::{Geometry, Mat3, Site, TableState, Vec3};
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
    /// Time offset: the sample stamped t measured the motion at t - tau, s.
    pub tau_s: f64,
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
            tau_s: 0.0,
        }
    }
}

fn offdiag(k: &Mat3) -> Vec<f64> {
    [(0, 1), (0, 2), (1, 0), (1, 2), (2, 0), (2, 1)]
        .iter()
        .map(|&(i, j)| k[(i, j)] * 1e3)
        .collect()
}

impl ImuErrors {
    /// These errors as registry terms at a site (the Earth's rate is one of them).
    pub fn model(&self, site: &Site) -> ImuModel {
        let mut m = ImuModel {
            terms: Vec::new(),
            t_ref_c: self.t_ref_c,
        };
        let v = |x: Vec3| x.iter().copied().collect::<Vec<f64>>();
        let diag = |k: &Mat3| {
            (0..3)
                .map(|i| (k[(i, i)] - 1.0) * 1e6)
                .collect::<Vec<f64>>()
        };
        m.push("accel_bias", v(self.b_a));
        m.push("accel_scale", diag(&self.k_a));
        m.push("gyro_bias", v(self.b_g));
        m.push("gyro_scale", diag(&self.k_g));
        m.push(
            "earth_rate",
            crate::effects::EarthRate::values(site.latitude_deg).to_vec(),
        );
        m.push(
            "lever_arm",
            self.lever_m.transpose().iter().map(|x| x * 1e3).collect(),
        );
        m.push("time_offset", vec![self.tau_s * 1e3]);
        m.push("accel_misalignment", offdiag(&self.k_a));
        m.push("gyro_misalignment", offdiag(&self.k_g));
        m.push(
            "g_sensitivity",
            (self.g_sens.transpose() * site.gravity_mps2)
                .iter()
                .copied()
                .collect(),
        );
        m.push("gyro_thermal_drift", v(self.gyro_thermal));
        m.push("accel_thermal_drift", v(self.accel_thermal));
        m.push("gyro_scale_nonlinearity", v(self.gyro_nonlinearity));
        m
    }

    /// Noise-free accelerometer (m/s^2) and gyro (deg/s) outputs at temperature `temp_c`
    /// for a table state (the motion itself, the time offset not applied).
    pub fn measure(
        &self,
        state: &TableState,
        geo: &Geometry,
        site: &Site,
        temp_c: f64,
    ) -> (Vec3, Vec3) {
        let snap = state.snapshot(geo, site);
        let s = Signals::new(&snap, site, temp_c - self.t_ref_c);
        self.model(site).outputs(&s)
    }
}
