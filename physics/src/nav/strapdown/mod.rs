//! The strapdown mechanization in L (East-North-Up, fixed to the Earth at the station):
//! `dC_LB/dt = C_LB [w_ib]x - [Omega_L]x C_LB`, `dv/dt = C_LB f_B + [0, 0, -g] - 2 Omega_L x v`.
//! The transport rate is left out: the IMU stays on the table (a few metres of position
//! error per hour of velocity error change it by less than 1e-9 rad/s).

use crate::{Mat3, Site, Vec3};
use nalgebra::{Rotation3, UnitQuaternion};

/// A navigation solution being propagated sample by sample.
#[derive(Debug, Clone)]
pub struct Strapdown {
    q_lb: UnitQuaternion<f64>,
    v_l: Vec3,
    omega_l: Vec3,
    g_l: Vec3,
    coriolis: bool,
    prev: Option<(f64, Vec3, Vec3)>,
}

impl Strapdown {
    /// Starts at rest with attitude `c_lb` at the given site.
    pub fn new(c_lb: &Mat3, site: &Site) -> Self {
        let rot = Rotation3::from_matrix(c_lb);
        Strapdown {
            q_lb: UnitQuaternion::from_rotation_matrix(&rot),
            v_l: Vec3::zeros(),
            omega_l: site.earth_rate_l(),
            g_l: Vec3::new(0.0, 0.0, -site.gravity_mps2),
            coriolis: true,
            prev: None,
        }
    }

    /// The same mechanization without the Coriolis term, for an IMU that stays on the table:
    /// its true velocity is a small periodic one, and the Coriolis term of a growing
    /// velocity error would turn the East drift into North and back (at 2 Omega_U).
    pub fn on_table(mut self) -> Self {
        self.coriolis = false;
        self
    }

    /// Takes one sample: time (s), inertial rate `w_ib` (rad/s) and specific force `f_b`
    /// (m/s^2), both body axes; the first sample only sets the start.
    pub fn step(&mut self, t: f64, w_ib: &Vec3, f_b: &Vec3) {
        let Some((t0, w0, _)) = self.prev else {
            self.prev = Some((t, *w_ib, *f_b));
            return;
        };
        let dt = t - t0;
        self.advance(t, (w0 + w_ib) * (0.5 * dt), w_ib, f_b);
    }

    /// Moves to the sample at `t` given the rate's integral over the step (`theta`, rad);
    /// the coning term is added here.
    fn advance(&mut self, t: f64, theta: Vec3, w_ib: &Vec3, f_b: &Vec3) {
        let Some((t0, w0, f0)) = self.prev.replace((t, *w_ib, *f_b)) else {
            return;
        };
        let dt = t - t0;
        if dt <= 0.0 || !dt.is_finite() {
            return;
        }
        let c0 = self.q_lb.to_rotation_matrix();
        // Rotation vector over the step: the increment plus the coning term
        // (1/12) w0 x w1 dt^2 of a rate varying linearly between the samples.
        let phi = theta + w0.cross(w_ib) * (dt * dt / 12.0);
        let body = UnitQuaternion::from_scaled_axis(phi);
        let lab = UnitQuaternion::from_scaled_axis(-self.omega_l * dt);
        self.q_lb = (lab * self.q_lb * body).renormalize_fast_owned();
        let c1 = self.q_lb.to_rotation_matrix();
        // Trapezoid on C_LB f_B: its error telescopes over a period instead of drifting.
        let f_l = (c0 * f0 + c1 * f_b) * 0.5;
        let coriolis = if self.coriolis {
            self.omega_l.cross(&self.v_l) * 2.0
        } else {
            Vec3::zeros()
        };
        self.v_l += (f_l + self.g_l - coriolis) * dt;
    }

    /// Velocity in L, m/s.
    pub fn velocity(&self) -> Vec3 {
        self.v_l
    }

    /// Attitude `C_LB`.
    pub fn attitude(&self) -> Mat3 {
        *self.q_lb.to_rotation_matrix().matrix()
    }
}

trait RenormalizeOwned {
    fn renormalize_fast_owned(self) -> Self;
}

impl RenormalizeOwned for UnitQuaternion<f64> {
    fn renormalize_fast_owned(mut self) -> Self {
        self.renormalize_fast();
        self
    }
}

/// A navigation solution over a stretch of samples: velocity and attitude at each.
#[derive(Debug, Clone, Default)]
pub struct Trajectory {
    /// Time stamps, s.
    pub t: Vec<f64>,
    /// Velocity in L, m/s.
    pub v_l: Vec<Vec3>,
    /// Attitude `C_LB`.
    pub c_lb: Vec<Mat3>,
}

/// Navigates over samples `t` (s) with inertial rates `w_ib` (rad/s) and specific forces
/// `f_b` (m/s^2) from the attitude `c_lb` at rest at `t[0]`, with the Coriolis term or
/// (`coriolis` false) as [`Strapdown::on_table`].
pub fn navigate(
    t: &[f64],
    w_ib: &[Vec3],
    f_b: &[Vec3],
    c_lb: &Mat3,
    site: &Site,
    coriolis: bool,
) -> Trajectory {
    let n = t.len().min(w_ib.len()).min(f_b.len());
    let mut nav = Strapdown::new(c_lb, site);
    nav.coriolis = coriolis;
    let uniform = |a: usize, b: usize| {
        let (h0, h1) = (t[a + 1] - t[a], t[b + 1] - t[b]);
        (h0 - h1).abs() <= 1e-6 * h0.abs()
    };
    let mut out = Trajectory {
        t: Vec::with_capacity(n),
        v_l: Vec::with_capacity(n),
        c_lb: Vec::with_capacity(n),
    };
    for k in 0..n {
        if k == 0 {
            nav.prev = Some((t[0], w_ib[0], f_b[0]));
        } else {
            // The rate's integral over [t(k-1), t(k)]: a cubic through four samples where
            // the spacing is even (fourth order), the trapezoid at the ends and at gaps.
            let dt = t[k] - t[k - 1];
            let theta = if k >= 2 && k + 1 < n && uniform(k - 2, k) && uniform(k - 1, k - 1) {
                (w_ib[k - 1] * 13.0 + w_ib[k] * 13.0 - w_ib[k - 2] - w_ib[k + 1]) * (dt / 24.0)
            } else {
                (w_ib[k - 1] + w_ib[k]) * (0.5 * dt)
            };
            nav.advance(t[k], theta, &w_ib[k], &f_b[k]);
        }
        out.t.push(t[k]);
        out.v_l.push(nav.velocity());
        out.c_lb.push(nav.attitude());
    }
    out
}

#[cfg(test)]
mod tests;
