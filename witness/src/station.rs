//! The station (site, table axes, mount) and the kinematics of physics.md in closed form:
//! from both axes' angle, rate and acceleration to what an ideal IMU senses ([`Instant`]).

use crate::rot::{self, M3, V3};

/// The Earth's rotation rate, rad/s (physics.md).
pub const OMEGA_E: f64 = 7.2921150e-5;

/// Where the table stands and how the IMU sits on it.
#[derive(Debug, Clone, PartialEq)]
pub struct Station {
    /// Site latitude, deg (written to the manifest).
    pub latitude_deg: f64,
    /// Local gravity, m/s^2 (written to the manifest).
    pub gravity_mps2: f64,
    /// True azimuth of the table's nominal North (the manifest's lab +y), deg clockwise
    /// from true north seen from above; 0 for a table aligned with the site. Not written to
    /// the manifest: a lab may not know it.
    pub heading_deg: f64,
    /// `a_o`, the outer axis in the lab frame.
    pub outer_axis: V3,
    /// `a_i`, the inner axis at outer angle zero.
    pub inner_axis: V3,
    /// `C_PB`, row-major (its columns are the body axes in platform axes).
    pub mount: M3,
}

impl Default for Station {
    /// The seed station (physics.md) at latitude 40 deg, g = 9.80160 m/s^2, like the shared
    /// open-* examples.
    fn default() -> Self {
        Station {
            latitude_deg: 40.0,
            gravity_mps2: 9.80160,
            heading_deg: 0.0,
            outer_axis: [0.0, -1.0, 0.0],
            inner_axis: [1.0, 0.0, 0.0],
            mount: rot::IDENTITY,
        }
    }
}

/// What an ideal IMU senses at one instant, and when: the argument of every hidden effect.
#[derive(Debug, Clone, PartialEq)]
pub struct Instant {
    /// Table time of the motion this sample describes, s.
    pub t: f64,
    /// The IMU's time stamp of the sample, s (differs from `t` under a clock rate or a time
    /// offset).
    pub t_stamp: f64,
    /// IMU internal temperature, degC.
    pub temp_c: f64,
    /// Outer and inner angles, deg.
    pub angles_deg: [f64; 2],
    /// Outer and inner rates, deg/s.
    pub rates_dps: [f64; 2],
    /// `C_LB` (maps body vectors into the lab frame the manifest's axes are written in).
    pub c_lb: M3,
    /// Specific force at the body origin, body axes, m/s^2.
    pub f_b: V3,
    /// Inertial rate `w_ib` in body axes, deg/s (table rate plus the Earth's).
    pub w_ib_dps: V3,
    /// Table rate relative to the lab in body axes, rad/s.
    pub w_b_rps: V3,
    /// Its time derivative, rad/s^2.
    pub dw_b_rps2: V3,
    /// Local gravity, m/s^2.
    pub g: f64,
}

impl Station {
    /// The Earth's rate in the lab frame of the manifest's axes, rad/s:
    /// `Omega_E [-cos(lat) sin(h), cos(lat) cos(h), sin(lat)]` for heading `h` (with `h = 0`
    /// physics.md's `Omega_E [0, cos(lat), sin(lat)]`).
    pub fn earth_rate_lab(&self) -> V3 {
        let (sl, cl) = self.latitude_deg.to_radians().sin_cos();
        let (sh, ch) = self.heading_deg.to_radians().sin_cos();
        rot::scale([-cl * sh, cl * ch, sl], OMEGA_E)
    }

    /// The ideal sensed quantities for the axes' state `axes` (`[outer, inner]` of angle deg,
    /// rate deg/s, acceleration deg/s^2).
    pub fn instant(&self, t: f64, t_stamp: f64, temp_c: f64, axes: [[f64; 3]; 2]) -> Instant {
        let [[th_o, dth_o, ddth_o], [th_i, dth_i, ddth_i]] = axes.map(|a| a.map(f64::to_radians));
        let (a_o, a_i) = (self.outer_axis, self.inner_axis);
        let r_o = rot::rodrigues(a_o, th_o);
        let r_i = rot::rodrigues(a_i, th_i);
        let c_lp = rot::mul(&r_o, &r_i);
        let c_lb = rot::mul(&c_lp, &self.mount);
        // w_P = R(a_i, th_i)^T a_o dth_o + a_i dth_i; d/dt R(a_i, th_i)^T = -dth_i [a_i]x R^T.
        let ao_p = rot::mul_tv(&r_i, a_o);
        let w_p = rot::add(rot::scale(ao_p, dth_o), rot::scale(a_i, dth_i));
        let dw_p = rot::add(
            rot::add(rot::scale(ao_p, ddth_o), rot::scale(a_i, ddth_i)),
            rot::scale(rot::cross(a_i, ao_p), -dth_i * dth_o),
        );
        let w_b = rot::mul_tv(&self.mount, w_p);
        let dw_b = rot::mul_tv(&self.mount, dw_p);
        let f_b = rot::mul_tv(&c_lb, [0.0, 0.0, self.gravity_mps2]);
        let earth_b = rot::mul_tv(&c_lb, self.earth_rate_lab());
        let w_ib_dps = rot::add(w_b, earth_b).map(f64::to_degrees);
        Instant {
            t,
            t_stamp,
            temp_c,
            angles_deg: [axes[0][0], axes[1][0]],
            rates_dps: [axes[0][1], axes[1][1]],
            c_lb,
            f_b,
            w_ib_dps,
            w_b_rps: w_b,
            dw_b_rps2: dw_b,
            g: self.gravity_mps2,
        }
    }
}

impl Instant {
    /// Specific force at `r_m` (body axes, m, from the table axes' intersection), body axes:
    /// `f_b + dw_b x r + w_b x (w_b x r)`.
    pub fn f_at(&self, r_m: V3) -> V3 {
        let w = self.w_b_rps;
        let tangential = rot::cross(self.dw_b_rps2, r_m);
        let centripetal = rot::cross(w, rot::cross(w, r_m));
        rot::add(self.f_b, rot::add(tangential, centripetal))
    }
}
