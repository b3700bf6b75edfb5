//! The kinematic signals of one instant that every effect reads.

use crate::{DEG, Mat3, Site, Snapshot, TableState, Vec3};

/// What the table's motion and the IMU's temperature give at one instant, in body axes:
/// the inputs of every effect's forward contribution and regressors.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Signals {
    /// `f_B(0)`: specific force at the IMU reference point, m/s^2.
    pub f_b: Vec3,
    /// `w_B`: body rate relative to the lab, rad/s.
    pub w_b: Vec3,
    /// `dw_B/dt`: angular acceleration, rad/s^2.
    pub dw_b: Vec3,
    /// `C_LB^T`: attitude (lab vectors into body axes).
    pub c_bl: Mat3,
    /// `C_LB^T Omega_L`: the Earth's rate in body axes at the station latitude, rad/s.
    pub earth_b: Vec3,
    /// `d f_B(0)/dt`, m/s^3.
    pub df_b: Vec3,
    /// `d w_ib/dt`, rad/s^2.
    pub dw_ib: Vec3,
    /// IMU temperature minus the model's reference temperature, degC (0 when unknown).
    pub dtemp_c: f64,
    /// Local gravity, m/s^2.
    pub g: f64,
    /// Time stamp of the instant, s (the recording's time axis; 0 unless set with
    /// [`Signals::at`]). The clock rate reads it; user effects may.
    pub t_s: f64,
    /// The table's angles, rates and accelerations the signals were computed from (rad):
    /// the table's feedback in the analysis, the true motion in the simulator. The encoder
    /// eccentricity reads them.
    pub table: TableState,
    /// The outer axis `a_o` in body axes (`C_LB^T a_o`).
    pub outer_b: Vec3,
    /// The inner axis `a_i` in body axes (`C_PB^T a_i`).
    pub inner_b: Vec3,
}

impl Signals {
    /// The signals of a kinematic snapshot, with the temperature offset `dtemp_c`.
    pub fn new(snap: &Snapshot, site: &Site, dtemp_c: f64) -> Self {
        let w_b = snap.c_bp * snap.w_p;
        let f_b = snap.gravity_b;
        let earth_b = snap.earth_rate_b;
        // dC_BL/dt = -[w_B]x C_BL: a lab-fixed vector turns the other way in body axes.
        Signals {
            f_b,
            w_b,
            dw_b: snap.c_bp * snap.dw_p,
            c_bl: snap.c_bl,
            earth_b,
            df_b: -w_b.cross(&f_b),
            dw_ib: snap.c_bp * snap.dw_p - w_b.cross(&earth_b),
            dtemp_c,
            g: site.gravity_mps2,
            t_s: 0.0,
            table: snap.state,
            outer_b: snap.outer_b,
            inner_b: snap.inner_b,
        }
    }

    /// The same signals stamped at time `t_s`, s.
    pub fn at(mut self, t_s: f64) -> Self {
        self.t_s = t_s;
        self
    }

    /// `w_ib` in deg/s: what ideal gyros read (table motion and the Earth's rate).
    pub fn w_ib_dps(&self) -> Vec3 {
        (self.w_b + self.earth_b) / DEG
    }

    /// The motion part of the gyro reference, deg/s (no Earth rate).
    pub fn w_b_dps(&self) -> Vec3 {
        self.w_b / DEG
    }

    /// The matrix `M` with `s_i = f_i + (M R_i)_i` for a sensing point `R_i` (body axes):
    /// `[dw]x + [w]x^2` (tangential and centripetal acceleration).
    pub fn lever_matrix(&self) -> Mat3 {
        let w = crate::skew(&self.w_b);
        crate::skew(&self.dw_b) + w * w
    }
}
