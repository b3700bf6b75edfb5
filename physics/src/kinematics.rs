//! Dual-axis table kinematics (spec/physics.md, "The dual-axis table").

use crate::{Mat3, Vec3};
use serde::{Deserialize, Serialize};

/// Degrees to radians.
pub const DEG: f64 = std::f64::consts::PI / 180.0;
/// The Earth's rotation rate, rad/s.
pub const EARTH_RATE_RADPS: f64 = 7.2921150e-5;
/// Standard gravity, m/s^2 (a unit, not the lab's gravity).
pub const STANDARD_GRAVITY: f64 = 9.80665;

/// Skew-symmetric cross-product matrix `[u]x`.
pub fn skew(u: &Vec3) -> Mat3 {
    Mat3::new(0.0, -u.z, u.y, u.z, 0.0, -u.x, -u.y, u.x, 0.0)
}

/// Right-handed rotation by `th` (rad) about unit vector `u` (Rodrigues).
pub fn rotation(u: &Vec3, th: f64) -> Mat3 {
    let k = skew(u);
    let (s, c) = th.sin_cos();
    Mat3::identity() + k * s + k * k * (1.0 - c)
}

/// The station site: latitude and local gravity.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Site {
    /// Geodetic latitude, degrees.
    pub latitude_deg: f64,
    /// Local gravity magnitude, m/s^2.
    pub gravity_mps2: f64,
}

impl Site {
    /// Earth rotation in L (ENU), rad/s: `Omega_E * [0, cos(lat), sin(lat)]`.
    pub fn earth_rate_l(&self) -> Vec3 {
        let lat = self.latitude_deg * DEG;
        Vec3::new(0.0, lat.cos(), lat.sin()) * EARTH_RATE_RADPS
    }
}

/// Table and mount geometry: axis unit vectors in L and the IMU mounting rotation `C_PB`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Geometry {
    /// `a_o`, outer axis unit vector in L.
    pub outer_axis: Vec3,
    /// `a_i`, inner axis unit vector in L at outer angle zero.
    pub inner_axis: Vec3,
    /// `C_PB`: columns are the body axes in P.
    pub c_pb: Mat3,
}

impl Geometry {
    /// The seed station: outer axis [0,-1,0] (pitch), inner axis [1,0,0] (roll), C_PB = I.
    pub fn seed() -> Self {
        Geometry {
            outer_axis: Vec3::new(0.0, -1.0, 0.0),
            inner_axis: Vec3::new(1.0, 0.0, 0.0),
            c_pb: Mat3::identity(),
        }
    }

    /// The size-effect station: vertical outer axis [0,0,1], inner axis [1,0,0].
    pub fn vertical_outer() -> Self {
        Geometry {
            outer_axis: Vec3::new(0.0, 0.0, 1.0),
            inner_axis: Vec3::new(1.0, 0.0, 0.0),
            c_pb: Mat3::identity(),
        }
    }

    /// The same geometry with another mount rotation.
    pub fn with_mount(mut self, c_pb: Mat3) -> Self {
        self.c_pb = c_pb;
        self
    }

    /// `C_LP = R(a_o, th_o) R(a_i, th_i)` (angles in rad).
    pub fn c_lp(&self, th_o: f64, th_i: f64) -> Mat3 {
        rotation(&self.outer_axis, th_o) * rotation(&self.inner_axis, th_i)
    }

    /// `C_LB = C_LP C_PB`.
    pub fn c_lb(&self, th_o: f64, th_i: f64) -> Mat3 {
        self.c_lp(th_o, th_i) * self.c_pb
    }
}

/// Motion of one axis at an instant: angle, rate and angular acceleration (rad, rad/s, rad/s^2).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct AxisMotion {
    /// Angle, rad.
    pub angle: f64,
    /// Rate, rad/s.
    pub rate: f64,
    /// Angular acceleration, rad/s^2.
    pub accel: f64,
}

/// The table's state at an instant: outer and inner axis motion.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct TableState {
    /// Outer axis.
    pub outer: AxisMotion,
    /// Inner axis.
    pub inner: AxisMotion,
}

impl TableState {
    /// A table at rest at the given angles (degrees).
    pub fn at_rest_deg(outer_deg: f64, inner_deg: f64) -> Self {
        TableState {
            outer: AxisMotion {
                angle: outer_deg * DEG,
                ..Default::default()
            },
            inner: AxisMotion {
                angle: inner_deg * DEG,
                ..Default::default()
            },
        }
    }

    /// Platform angular velocity relative to the lab, P axes (rad/s):
    /// `w_P = R(a_i, th_i)^T a_o dth_o + a_i dth_i`.
    pub fn w_p(&self, geo: &Geometry) -> Vec3 {
        let r_i = rotation(&geo.inner_axis, self.inner.angle);
        r_i.transpose() * geo.outer_axis * self.outer.rate + geo.inner_axis * self.inner.rate
    }

    /// Time derivative of `w_P`, P axes (rad/s^2).
    pub fn dw_p(&self, geo: &Geometry) -> Vec3 {
        let r_i = rotation(&geo.inner_axis, self.inner.angle);
        dw_p(geo, &(r_i.transpose() * geo.outer_axis), self)
    }

    /// Body angular velocity relative to the lab, B axes (rad/s): `w_B = C_PB^T w_P`.
    pub fn w_b(&self, geo: &Geometry) -> Vec3 {
        geo.c_pb.transpose() * self.w_p(geo)
    }

    /// Inertial rate that ideal gyros sense, B axes (rad/s): `w_ib = w_B + C_LB^T Omega_L`.
    pub fn w_ib(&self, geo: &Geometry, site: &Site) -> Vec3 {
        self.snapshot(geo, site).w_ib()
    }

    /// Specific force in B axes at a platform-fixed point `rho` (P axes, metres):
    /// `f_B = C_LB^T [0,0,g] + C_PB^T (dw_P x rho + w_P x (w_P x rho))`.
    pub fn f_b(&self, geo: &Geometry, site: &Site, rho: &Vec3) -> Vec3 {
        self.snapshot(geo, site).f_b(rho)
    }

    /// The kinematics of this instant with every rotation evaluated once, for callers that
    /// need several sensed quantities of the same state (the simulator, the analysis).
    pub fn snapshot(&self, geo: &Geometry, site: &Site) -> Snapshot {
        let r_o = rotation(&geo.outer_axis, self.outer.angle);
        let r_i = rotation(&geo.inner_axis, self.inner.angle);
        let c_bl = (r_o * r_i * geo.c_pb).transpose();
        let rt_ao = r_i.transpose() * geo.outer_axis;
        Snapshot {
            state: *self,
            outer_b: c_bl * geo.outer_axis,
            inner_b: geo.c_pb.transpose() * geo.inner_axis,
            c_bl,
            c_bp: geo.c_pb.transpose(),
            w_p: rt_ao * self.outer.rate + geo.inner_axis * self.inner.rate,
            dw_p: dw_p(geo, &rt_ao, self),
            gravity_b: c_bl * Vec3::new(0.0, 0.0, site.gravity_mps2),
            earth_rate_b: c_bl * site.earth_rate_l(),
        }
    }
}

/// `dw_P` given `R(a_i, th_i)^T a_o`: d/dt R^T = -[a_i]x R^T dth_i.
fn dw_p(geo: &Geometry, rt_ao: &Vec3, s: &TableState) -> Vec3 {
    rt_ao * s.outer.accel - geo.inner_axis.cross(rt_ao) * s.inner.rate * s.outer.rate
        + geo.inner_axis * s.inner.accel
}

/// One table state's kinematics, rotations done: see [`TableState::snapshot`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Snapshot {
    /// The table state it was computed from (angles, rates, accelerations).
    pub state: TableState,
    /// `a_o` in body axes at this instant (`C_LB^T a_o`).
    pub outer_b: Vec3,
    /// `a_i` in body axes (`C_PB^T a_i`, constant for a mount).
    pub inner_b: Vec3,
    /// `C_LB^T`.
    pub c_bl: Mat3,
    /// `C_PB^T`.
    pub c_bp: Mat3,
    /// `w_P`, rad/s.
    pub w_p: Vec3,
    /// `dw_P`, rad/s^2.
    pub dw_p: Vec3,
    /// `C_LB^T [0, 0, g]`, m/s^2.
    pub gravity_b: Vec3,
    /// `C_LB^T Omega_L`, rad/s.
    pub earth_rate_b: Vec3,
}

impl Snapshot {
    /// Specific force in B axes at platform point `rho` (P axes, metres), as
    /// [`TableState::f_b`].
    #[inline]
    pub fn f_b(&self, rho: &Vec3) -> Vec3 {
        let w = &self.w_p;
        self.gravity_b + self.c_bp * (self.dw_p.cross(rho) + w.cross(&w.cross(rho)))
    }

    /// Inertial rate in B axes, rad/s, as [`TableState::w_ib`].
    #[inline]
    pub fn w_ib(&self) -> Vec3 {
        self.c_bp * self.w_p + self.earth_rate_b
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SITE: Site = Site {
        latitude_deg: 55.7,
        gravity_mps2: 9.8156,
    };

    #[test]
    fn static_attitudes_match_the_seed_formula() {
        let geo = Geometry::seed();
        for (th, phi) in [
            (0.0, 0.0),
            (0.0, 180.0),
            (90.0, 0.0),
            (-90.0, 0.0),
            (0.0, 90.0),
            (37.0, -121.0),
        ] {
            let s = TableState::at_rest_deg(th, phi);
            let f = s.f_b(&geo, &SITE, &Vec3::zeros());
            let (t, p) = (th * DEG, phi * DEG);
            let want = Vec3::new(t.sin(), t.cos() * p.sin(), t.cos() * p.cos()) * SITE.gravity_mps2;
            assert!(
                (f - want).norm() < 1e-12,
                "pitch {th} roll {phi}: {f} vs {want}"
            );
        }
    }

    #[test]
    fn outer_rotation_at_roll_zero_is_sensed_by_minus_y() {
        let geo = Geometry::seed();
        let mut s = TableState::at_rest_deg(0.0, 0.0);
        s.outer.rate = 1.0;
        let w = s.w_b(&geo);
        assert!((w - Vec3::new(0.0, -1.0, 0.0)).norm() < 1e-15);
        let mut s = TableState::at_rest_deg(0.0, 0.0);
        s.inner.rate = 1.0;
        assert!((s.w_b(&geo) - Vec3::new(1.0, 0.0, 0.0)).norm() < 1e-15);
    }

    #[test]
    fn dw_p_matches_finite_difference() {
        let geo = Geometry::seed();
        let state = |t: f64| TableState {
            outer: AxisMotion {
                angle: 0.3 + 0.5 * t + 0.1 * t * t,
                rate: 0.5 + 0.2 * t,
                accel: 0.2,
            },
            inner: AxisMotion {
                angle: -0.2 + 1.1 * t - 0.3 * t * t,
                rate: 1.1 - 0.6 * t,
                accel: -0.6,
            },
        };
        let (t, h) = (0.7, 1e-6);
        let fd = (state(t + h).w_p(&geo) - state(t - h).w_p(&geo)) / (2.0 * h);
        assert!((fd - state(t).dw_p(&geo)).norm() < 1e-8);
    }

    #[test]
    fn earth_rate_projection_at_level() {
        let geo = Geometry::seed();
        let w = TableState::at_rest_deg(0.0, 0.0).w_ib(&geo, &SITE);
        let lat = SITE.latitude_deg * DEG;
        let want = Vec3::new(0.0, lat.cos(), lat.sin()) * EARTH_RATE_RADPS;
        assert!((w - want).norm() < 1e-18);
    }

    #[test]
    fn centripetal_term_for_a_lever_arm() {
        // Spinning about the inner axis (X at level) at w: a point at rho = [0, 0, r]
        // feels -w^2 r along Z (towards the axis), on top of gravity.
        let geo = Geometry::seed();
        let mut s = TableState::at_rest_deg(0.0, 0.0);
        s.inner.rate = 2.0;
        let f = s.f_b(&geo, &SITE, &Vec3::new(0.0, 0.0, 0.1));
        assert!((f.z - (SITE.gravity_mps2 - 4.0 * 0.1)).abs() < 1e-12);
    }
}
