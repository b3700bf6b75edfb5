//! One table axis's motion as a list of analytic phases, queryable at any time.
//!
//! The commanded trajectory is piecewise: constant angular acceleration (moves, rate ramps,
//! holds) or a sinusoid with a smooth start. The axis follows it through a second-order
//! servo loop: the tracking error `e` obeys `e'' + 2 zeta wn e' + wn^2 e = -cmd''` within a
//! constant-acceleration phase (the lag while accelerating, the damped overshoot after a
//! move) and decays freely during an oscillation (feed-forward). Each phase stores the
//! error state at its start, so angle, rate and acceleration are continuous and exact at
//! any instant: the IMU can be sampled at `t - tau` without integrating anything.

/// Below this homogeneous error (deg) a phase counts as settled and the error is exactly
/// its steady value, so holds are bit-for-bit constant (the IMU caches their outputs).
const SETTLED_DEG: f64 = 1e-10;

/// The commanded trajectory within a phase (deg, deg/s, deg/s^2).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Cmd {
    /// `theta0 + omega0 s + alpha s^2 / 2`.
    Poly {
        theta0: f64,
        omega0: f64,
        alpha: f64,
    },
    /// `center + amp r(s) sin(w s)`, `r` rising smoothly from 0 to 1 over `ramp` s.
    Osc {
        center: f64,
        amp: f64,
        w: f64,
        ramp: f64,
    },
}

impl Cmd {
    fn eval(&self, s: f64) -> [f64; 3] {
        match *self {
            Cmd::Poly {
                theta0,
                omega0,
                alpha,
            } => [
                theta0 + omega0 * s + 0.5 * alpha * s * s,
                omega0 + alpha * s,
                alpha,
            ],
            Cmd::Osc {
                center,
                amp,
                w,
                ramp,
            } => {
                let (sn, cs) = (w * s).sin_cos();
                let (r, r1, r2) = if s < ramp {
                    let k = std::f64::consts::PI / ramp;
                    let (ks, kc) = (k * s).sin_cos();
                    (0.5 * (1.0 - kc), 0.5 * k * ks, 0.5 * k * k * kc)
                } else {
                    (1.0, 0.0, 0.0)
                };
                [
                    center + amp * r * sn,
                    amp * (r1 * sn + r * w * cs),
                    amp * (r2 * sn + 2.0 * r1 * w * cs - r * w * w * sn),
                ]
            }
        }
    }

    /// The forcing of the error equation: the part of `-cmd''` that the acceleration
    /// feed-forward leaves over (an oscillation is fully fed forward).
    fn forcing(&self, feedforward: f64) -> f64 {
        match *self {
            Cmd::Poly { alpha, .. } => -alpha * (1.0 - feedforward),
            Cmd::Osc { .. } => 0.0,
        }
    }
}

/// Second-order servo loop: natural frequency (rad/s) and damping ratio.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Servo {
    /// Natural frequency, rad/s.
    pub wn: f64,
    /// Damping ratio.
    pub zeta: f64,
    /// Fraction of the commanded acceleration fed forward (0..1): the rest drives the
    /// tracking error.
    pub feedforward: f64,
}

impl Servo {
    /// Homogeneous response from `(x0, v0)` after `s` seconds: `(x, x')`.
    fn free(&self, x0: f64, v0: f64, s: f64) -> (f64, f64) {
        let (wn, z) = (self.wn, self.zeta);
        if z < 1.0 {
            let sig = z * wn;
            let wd = wn * (1.0 - z * z).sqrt();
            let b = (v0 + sig * x0) / wd;
            let (sn, cs) = (wd * s).sin_cos();
            let e = (-sig * s).exp();
            (
                e * (x0 * cs + b * sn),
                e * (v0 * cs - (sig * b + x0 * wd) * sn),
            )
        } else if z == 1.0 {
            let e = (-wn * s).exp();
            let c = v0 + wn * x0;
            (e * (x0 + c * s), e * (c - wn * (x0 + c * s)))
        } else {
            let q = (z * z - 1.0).sqrt();
            let (r1, r2) = (-wn * (z - q), -wn * (z + q));
            let c1 = (v0 - r2 * x0) / (r1 - r2);
            let c2 = x0 - c1;
            let (e1, e2) = ((r1 * s).exp(), (r2 * s).exp());
            (c1 * e1 + c2 * e2, r1 * c1 * e1 + r2 * c2 * e2)
        }
    }

    /// How much lower than the table's limit to plan the commanded acceleration so that
    /// the true acceleration stays within it: after a step `D` in the commanded
    /// acceleration the true one peaks at `D (1 + overshoot)` (the loop's zero), and the
    /// worst step is a reversal from `+a` to `-a`.
    pub fn accel_derating(&self) -> f64 {
        let w2 = self.wn * self.wn;
        let horizon = 20.0 / self.decay();
        let peak = (0..=4000)
            .map(|k| {
                let (x, v) = self.free(1.0 / w2, 0.0, horizon * k as f64 / 4000.0);
                1.0 - w2 * x - 2.0 * self.zeta * self.wn * v
            })
            .fold(1.0, f64::max);
        let overshoot = (1.0 - self.feedforward) * (peak - 1.0);
        1.0 + 2.0 * overshoot
    }

    /// Slowest decay rate, 1/s (halved when critically damped, for its `s e^{-wn s}` term).
    fn decay(&self) -> f64 {
        if self.zeta < 1.0 {
            self.zeta * self.wn
        } else if self.zeta == 1.0 {
            0.5 * self.wn
        } else {
            self.wn * (self.zeta - (self.zeta * self.zeta - 1.0).sqrt())
        }
    }
}

#[derive(Debug, Clone, Copy)]
struct Phase {
    t0: f64,
    cmd: Cmd,
    /// Steady error of the phase, `forcing / wn^2`.
    e_p: f64,
    /// Homogeneous error state at `t0`.
    x0: f64,
    v0: f64,
    /// From this time on the homogeneous error is negligible.
    t_settled: f64,
}

/// Angle (deg), rate (deg/s) and angular acceleration (deg/s^2) of an axis.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct AxisKinematics {
    /// Angle, deg.
    pub angle: f64,
    /// Rate, deg/s.
    pub rate: f64,
    /// Angular acceleration, deg/s^2.
    pub accel: f64,
}

/// One axis's motion history: phases in time order; the last one lasts for ever.
#[derive(Debug, Clone)]
pub struct AxisProfile {
    phases: Vec<Phase>,
    servo: Servo,
    /// Rate limit, deg/s.
    pub max_rate: f64,
    /// Acceleration limit, deg/s^2.
    pub max_accel: f64,
}

impl AxisProfile {
    /// An axis at rest at `angle` (deg) since long before t = 0.
    pub fn at_rest(angle: f64, servo: Servo, max_rate: f64, max_accel: f64) -> Self {
        let cmd = Cmd::Poly {
            theta0: angle,
            omega0: 0.0,
            alpha: 0.0,
        };
        let phase = Phase {
            t0: -1e6,
            cmd,
            e_p: 0.0,
            x0: 0.0,
            v0: 0.0,
            t_settled: -1e6,
        };
        AxisProfile {
            phases: vec![phase],
            servo,
            max_rate,
            max_accel,
        }
    }

    fn index(&self, t: f64, hint: &mut usize) -> usize {
        let n = self.phases.len();
        let mut i = (*hint).min(n - 1);
        if self.phases[i].t0 > t {
            i = self.phases.partition_point(|p| p.t0 <= t).saturating_sub(1);
        } else {
            while i + 1 < n && self.phases[i + 1].t0 <= t {
                i += 1;
            }
        }
        *hint = i;
        i
    }

    /// True motion at `t`; `hint` is the caller's cursor (any value is correct, a recent
    /// one is fast).
    pub fn eval(&self, t: f64, hint: &mut usize) -> AxisKinematics {
        let p = &self.phases[self.index(t, hint)];
        let s = t - p.t0;
        let [a, r, acc] = p.cmd.eval(s);
        if t >= p.t_settled {
            return AxisKinematics {
                angle: a + p.e_p,
                rate: r,
                accel: acc,
            };
        }
        let (x, v) = self.servo.free(p.x0, p.v0, s);
        let w2 = self.servo.wn * self.servo.wn;
        let xa = -w2 * x - 2.0 * self.servo.zeta * self.servo.wn * v;
        AxisKinematics {
            angle: a + p.e_p + x,
            rate: r + v,
            accel: acc + xa,
        }
    }

    /// Commanded angle and rate at `t`, and the error state `(e, e')`.
    fn state(&self, t: f64) -> ([f64; 3], f64, f64) {
        let p = &self.phases[self.index(t, &mut 0)];
        let s = t - p.t0;
        let c = p.cmd.eval(s);
        if t >= p.t_settled {
            return (c, p.e_p, 0.0);
        }
        let (x, v) = self.servo.free(p.x0, p.v0, s);
        (c, p.e_p + x, v)
    }

    /// Drops every phase starting at or after `t`.
    fn truncate(&mut self, t: f64) {
        let keep = self.phases.partition_point(|p| p.t0 < t).max(1);
        self.phases.truncate(keep);
    }

    /// Appends a phase starting at `t0`, carrying the error state over.
    fn push(&mut self, t0: f64, cmd: Cmd) {
        let (_, e, de) = self.state(t0);
        let w2 = self.servo.wn * self.servo.wn;
        let e_p = cmd.forcing(self.servo.feedforward) / w2;
        let (x0, v0) = (e - e_p, de);
        let size =
            x0.abs() + (v0.abs() + self.servo.decay() * x0.abs()) / self.servo.decay().max(1e-9);
        let t_settled = if size <= SETTLED_DEG {
            t0
        } else {
            t0 + (size / SETTLED_DEG).ln() / self.servo.decay()
        };
        self.phases.push(Phase {
            t0,
            cmd,
            e_p,
            x0,
            v0,
            t_settled,
        });
    }

    /// Commanded angle and rate at `t` (where a new plan starts from).
    pub fn commanded(&self, t: f64) -> (f64, f64) {
        let (c, _, _) = self.state(t);
        (c[0], c[1])
    }

    /// Accelerates (or brakes) from the commanded state at `t` to `rate`, then holds it.
    pub fn ramp_to_rate(&mut self, t: f64, rate: f64) {
        let (th, w) = self.commanded(t);
        self.truncate(t);
        let a = self.max_accel;
        let dur = (rate - w).abs() / a;
        let mut t1 = t;
        let mut th1 = th;
        if dur > 0.0 {
            self.push(
                t,
                Cmd::Poly {
                    theta0: th,
                    omega0: w,
                    alpha: (rate - w).signum() * a,
                },
            );
            t1 = t + dur;
            th1 = th + 0.5 * (w + rate) * dur;
        }
        self.push(
            t1,
            Cmd::Poly {
                theta0: th1,
                omega0: rate,
                alpha: 0.0,
            },
        );
    }

    /// An acceleration- and rate-limited move from the commanded state at `t` to `target`
    /// (deg), ending at rest. Returns when the commanded motion ends.
    pub fn move_to(&mut self, t: f64, target: f64) -> f64 {
        let (mut th, mut w) = self.commanded(t);
        self.truncate(t);
        let (a, vmax) = (self.max_accel, self.max_rate);
        let mut t = t;
        let mut d = target - th;
        if w != 0.0 && (w * d < 0.0 || w * w / (2.0 * a) > d.abs()) {
            // Moving away, or too fast to stop in time: brake to rest first.
            let dur = w.abs() / a;
            self.push(
                t,
                Cmd::Poly {
                    theta0: th,
                    omega0: w,
                    alpha: -w.signum() * a,
                },
            );
            th += 0.5 * w * dur;
            t += dur;
            w = 0.0;
            d = target - th;
        }
        let (sg, dist, v0) = (d.signum(), d.abs(), w.abs());
        let vp = ((2.0 * a * dist + v0 * v0) / 2.0).sqrt().min(vmax).max(v0);
        let t_acc = (vp - v0) / a;
        let d_acc = (vp * vp - v0 * v0) / (2.0 * a);
        let d_dec = vp * vp / (2.0 * a);
        let t_cruise = if vp > 0.0 {
            ((dist - d_acc - d_dec) / vp).max(0.0)
        } else {
            0.0
        };
        if dist > 0.0 {
            if t_acc > 0.0 {
                self.push(
                    t,
                    Cmd::Poly {
                        theta0: th,
                        omega0: sg * v0,
                        alpha: sg * a,
                    },
                );
            }
            if t_cruise > 0.0 {
                self.push(
                    t + t_acc,
                    Cmd::Poly {
                        theta0: th + sg * d_acc,
                        omega0: sg * vp,
                        alpha: 0.0,
                    },
                );
            }
            let t_dec = t + t_acc + t_cruise;
            self.push(
                t_dec,
                Cmd::Poly {
                    theta0: target - sg * d_dec,
                    omega0: sg * vp,
                    alpha: -sg * a,
                },
            );
            t = t_dec + vp / a;
        }
        self.push(
            t,
            Cmd::Poly {
                theta0: target,
                omega0: 0.0,
                alpha: 0.0,
            },
        );
        t
    }

    /// Moves to `center` if needed, then sways `center + amp sin(2 pi s / period)` with an
    /// envelope that rises smoothly over one period.
    pub fn oscillate(&mut self, t: f64, center: f64, amp: f64, period: f64) {
        let (th, w) = self.commanded(t);
        let start = if th == center && w == 0.0 {
            self.truncate(t);
            t
        } else {
            self.move_to(t, center)
        };
        let w = 2.0 * std::f64::consts::PI / period;
        self.push(
            start,
            Cmd::Osc {
                center,
                amp,
                w,
                ramp: period,
            },
        );
    }
}

#[cfg(test)]
mod tests;
