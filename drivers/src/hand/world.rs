//! The simulated operator's hand: a timeline of rests and moves of the unit, in body-frame
//! rotations (`C_LB(t) = C_LB0 R(u, phi(t)) R(v, delta(t))`: the move about `u`, the
//! tremor about `v`, which vanishes at both ends of a move).

use crate::OperatorAsk;
use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};
use rand_distr::StandardNormal;
use ratecal_physics::{Mat3, Vec3, rotation};
use std::f64::consts::PI;
use std::sync::{Arc, Mutex};
use tokio::time::Instant;

/// How long the operator takes to read a prompt and pick the unit up, s.
const REACTION_S: f64 = 1.5;
/// Tremor amplitude of a hand holding the unit, rad.
const TREMOR_RAD: f64 = 0.004;
/// Tremor frequency, Hz.
const TREMOR_HZ: f64 = 7.0;

/// One move: from attitude `c0` (`C_LB`) about body axis `u` by `angle` over
/// `[t0, t0 + dur]`, with a tremor about `v`.
#[derive(Debug, Clone, Copy)]
struct Move {
    t0: f64,
    dur: f64,
    c0: Mat3,
    u: Vec3,
    angle: f64,
    v: Vec3,
    uneven: f64,
}

/// The attitude and rates of the unit at an instant.
#[derive(Debug, Clone, Copy)]
pub struct HandState {
    /// `C_LB^T`: lab vectors into body axes.
    pub c_bl: Mat3,
    /// Body rate, rad/s.
    pub w_b: Vec3,
    /// Body angular acceleration, rad/s^2.
    pub dw_b: Vec3,
}

/// The simulated operator's timeline, shared by its table and its IMU.
#[derive(Debug)]
pub struct HandWorld {
    start: Instant,
    moves: Vec<Move>,
    /// Attitude at the end of the timeline (`C_LB`).
    last: Mat3,
    rng: ChaCha8Rng,
    /// Faces placed so far (the second one is put on the wrong face once).
    faces: usize,
    /// The face the operator was last asked for, to correct a mistake.
    asked: Option<(Vec3, f64)>,
}

/// The hand behind a mutex.
pub type SharedHand = Arc<Mutex<HandWorld>>;

/// The angle turned after `s` (0..1) of a move: uneven speed, at rest at both ends.
fn profile(s: f64, uneven: f64) -> (f64, f64, f64) {
    let s = s.clamp(0.0, 1.0);
    let p = s - (2.0 * PI * s).sin() / (2.0 * PI);
    let dp = 1.0 - (2.0 * PI * s).cos();
    let ddp = 2.0 * PI * (2.0 * PI * s).sin();
    // An uneven hand: a second harmonic that keeps the ends and the total.
    let q = uneven * (4.0 * PI * s).sin().powi(2) * (2.0 * PI * s).sin() / 4.0;
    let dq = uneven
        * ((4.0 * PI * s).sin().powi(2) * 2.0 * PI * (2.0 * PI * s).cos()
            + 2.0 * (4.0 * PI * s).sin() * (4.0 * PI * s).cos() * 4.0 * PI * (2.0 * PI * s).sin())
        / 4.0;
    (p + q, dp + dq, ddp)
}

fn unit(v: Vec3) -> Vec3 {
    let n = v.norm();
    if n < 1e-12 { Vec3::z() } else { v / n }
}

impl HandWorld {
    /// A hand holding nothing yet: the unit lies with +Z up, starting now on the tokio clock.
    pub fn new(seed: u64) -> Self {
        HandWorld {
            start: Instant::now(),
            moves: Vec::new(),
            last: Mat3::identity(),
            rng: ChaCha8Rng::seed_from_u64(seed ^ 0x4A4D_0000_0000_0001),
            faces: 0,
            asked: None,
        }
    }

    /// Seconds since the start on the tokio clock.
    pub fn now(&self) -> f64 {
        self.start.elapsed().as_secs_f64()
    }

    fn gauss(&mut self) -> f64 {
        self.rng.sample(StandardNormal)
    }

    fn random_axis(&mut self) -> Vec3 {
        unit(Vec3::new(self.gauss(), self.gauss(), self.gauss()))
    }

    /// The operator acts on a request made now.
    pub fn ask(&mut self, ask: OperatorAsk) {
        let now = self.now();
        let t0 = self.moves.last().map_or(0.0, |m| m.t0 + m.dur).max(now) + REACTION_S;
        match ask {
            OperatorAsk::Pose {
                up: Some(up),
                tolerance_deg,
            } => {
                let up = unit(Vec3::from(up));
                self.asked = Some((up, tolerance_deg));
                self.faces += 1;
                // Once, on the second face asked, the operator puts the wrong face up.
                let placed = if self.faces == 2 { -up } else { up };
                self.place(t0, placed, tolerance_deg);
            }
            OperatorAsk::Pose { up: None, .. } => {
                let (u, a) = (self.random_axis(), self.free_angle());
                self.turn(t0, u, a);
            }
            OperatorAsk::Turn {
                about: Some((axis, deg)),
            } => {
                self.turn(t0, unit(Vec3::from(axis)), deg.to_radians());
            }
            OperatorAsk::Turn { about: None } => {
                let (u, a) = (self.random_axis(), self.free_angle());
                self.turn(t0, u, a);
            }
            OperatorAsk::Refused => {
                if let Some((up, tol)) = self.asked {
                    self.place(t0, up, tol);
                }
            }
        }
    }

    fn free_angle(&mut self) -> f64 {
        let sign = if self.rng.random::<bool>() { 1.0 } else { -1.0 };
        (50.0 + 100.0 * self.rng.random::<f64>()).to_radians() * sign
    }

    /// Puts the unit down with `up` (body) near the lab's vertical, tilted by a few tenths
    /// of the tolerance, at a random heading.
    fn place(&mut self, t0: f64, up: Vec3, tolerance_deg: f64) {
        let tilt = (tolerance_deg * 0.3 * self.gauss().abs()).min(0.8 * tolerance_deg);
        let tilt_axis = unit(Vec3::new(self.gauss(), self.gauss(), 0.0));
        let heading = self.rng.random::<f64>() * 2.0 * PI;
        // C_LB with body `up` along lab Z: the shortest rotation of `up` onto Z.
        let z = Vec3::z();
        let c = up.cross(&z);
        let align = if c.norm() < 1e-9 {
            if up.z > 0.0 {
                Mat3::identity()
            } else {
                rotation(&Vec3::x(), PI)
            }
        } else {
            rotation(&unit(c), up.dot(&z).clamp(-1.0, 1.0).acos())
        };
        let target = rotation(&tilt_axis, tilt.to_radians()) * rotation(&z, heading) * align;
        // The body-frame rotation from here to there: R = C_LB^T C_LB'.
        let rel = self.last.transpose() * target;
        let (u, angle) = axis_angle(&rel);
        self.turn(t0, u, angle);
    }

    /// Appends a move about body axis `u` by `angle` (rad), with a tremor.
    fn turn(&mut self, t0: f64, u: Vec3, angle: f64) {
        let v = unit(u.cross(&self.random_axis()));
        let uneven = 0.5 + 0.4 * self.gauss().clamp(-1.0, 1.0);
        let dur = 1.5 + angle.abs() / PI * 2.0 + 0.5 * self.rng.random::<f64>();
        let m = Move {
            t0,
            dur,
            c0: self.last,
            u,
            angle,
            v,
            uneven,
        };
        self.last = m.c0 * rotation(&u, angle);
        self.moves.push(m);
    }

    /// The unit's attitude and rates at `t` (s on the world's clock).
    pub fn state(&self, t: f64, hint: &mut usize) -> HandState {
        while *hint > 0 && self.moves.get(*hint).is_some_and(|m| m.t0 > t) {
            *hint -= 1;
        }
        while *hint + 1 < self.moves.len() && self.moves[*hint + 1].t0 <= t {
            *hint += 1;
        }
        let Some(m) = self.moves.get(*hint).filter(|m| m.t0 <= t) else {
            let c = self.moves.first().map_or(self.last, |m| m.c0);
            return at_rest(c);
        };
        if t >= m.t0 + m.dur {
            return at_rest(m.c0 * rotation(&m.u, m.angle));
        }
        let s = (t - m.t0) / m.dur;
        let (p, dp, ddp) = profile(s, m.uneven);
        let phi = m.angle * p;
        let dphi = m.angle * dp / m.dur;
        let ddphi = m.angle * ddp / (m.dur * m.dur);
        // The tremor: an angle about v that is zero when the move starts and ends.
        let w = 2.0 * PI * TREMOR_HZ;
        let env = (PI * s).sin();
        let denv = PI * (PI * s).cos() / m.dur;
        let delta = TREMOR_RAD * env * (w * (t - m.t0)).sin();
        let ddelta =
            TREMOR_RAD * (denv * (w * (t - m.t0)).sin() + env * w * (w * (t - m.t0)).cos());
        let r_v = rotation(&m.v, delta);
        let c_lb = m.c0 * rotation(&m.u, phi) * r_v;
        // C_LB = C0 R(u, phi) R(v, delta): w_B = R(v, delta)^T u phi' + v delta'.
        let w_b = r_v.transpose() * m.u * dphi + m.v * ddelta;
        HandState {
            c_bl: c_lb.transpose(),
            w_b,
            dw_b: r_v.transpose() * m.u * ddphi,
        }
    }

    /// When the last move asked for ends, s (the unit is down and still after it).
    pub fn busy_until(&self) -> f64 {
        self.moves.last().map_or(0.0, |m| m.t0 + m.dur)
    }
}

fn at_rest(c_lb: Mat3) -> HandState {
    HandState {
        c_bl: c_lb.transpose(),
        w_b: Vec3::zeros(),
        dw_b: Vec3::zeros(),
    }
}

/// Axis and angle of a rotation matrix (angle in [0, pi]).
fn axis_angle(r: &Mat3) -> (Vec3, f64) {
    let c = ((r.trace() - 1.0) / 2.0).clamp(-1.0, 1.0);
    let angle = c.acos();
    let v = Vec3::new(
        r[(2, 1)] - r[(1, 2)],
        r[(0, 2)] - r[(2, 0)],
        r[(1, 0)] - r[(0, 1)],
    );
    if v.norm() > 1e-6 {
        return (v / v.norm(), angle);
    }
    if angle < 1e-6 {
        return (Vec3::z(), 0.0);
    }
    // Half a turn: the axis is the column of R + I with the largest norm.
    let m = r + Mat3::identity();
    let k = (0..3)
        .max_by(|a, b| m.column(*a).norm().total_cmp(&m.column(*b).norm()))
        .unwrap_or(0);
    (unit(m.column(k).into()), angle)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_placed_face_is_up_within_its_tolerance() {
        let mut w = HandWorld::new(3);
        w.ask(OperatorAsk::Pose {
            up: Some([0.0, -1.0, 0.0]),
            tolerance_deg: 5.0,
        });
        let s = w.state(1e6, &mut 0);
        let up_b = s.c_bl * Vec3::z();
        assert!(up_b.dot(&Vec3::new(0.0, -1.0, 0.0)) > 5f64.to_radians().cos());
    }

    #[test]
    fn the_rates_integrate_to_the_attitude() {
        let mut w = HandWorld::new(5);
        w.ask(OperatorAsk::Turn {
            about: Some(([1.0, 0.0, 0.0], 90.0)),
        });
        let (mut c, dt) = (Mat3::identity(), 1e-4);
        let mut hint = 0;
        let mut t = 0.0;
        while t < w.busy_until() + 0.1 {
            let s = w.state(t + dt / 2.0, &mut hint);
            c *= rotation(&unit(s.w_b), s.w_b.norm() * dt);
            t += dt;
        }
        let end = w.state(1e6, &mut 0).c_bl.transpose();
        assert!((c - end).norm() < 1e-5, "{}", (c - end).norm());
    }
}
