//! The table's motion in closed form: a [`Plan`] (static attitudes, constant rates) becomes a
//! timeline of phases in which each axis's angle, rate and acceleration are explicit
//! functions of time: holds, cosine moves between angles, cosine ramps between rates, and
//! constant spins.

use std::f64::consts::PI;

/// A table axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Axis {
    /// The outer axis (pitch on the seed station).
    Outer,
    /// The inner axis (roll on the seed station).
    Inner,
}

impl Axis {
    /// The manifest's name of the axis.
    pub fn name(self) -> &'static str {
        match self {
            Axis::Outer => "outer",
            Axis::Inner => "inner",
        }
    }
}

/// One step of a plan.
#[derive(Debug, Clone, PartialEq)]
pub enum Step {
    /// Move to an attitude (outer angle `pitch_deg`, inner angle `roll_deg`, nearest the
    /// current angles modulo 360), wait `settle_s`, record a static segment of `dwell_s`.
    Static {
        /// Segment id.
        id: String,
        /// Outer angle, deg.
        pitch_deg: f64,
        /// Inner angle, deg.
        roll_deg: f64,
        /// Wait before the segment, s.
        settle_s: f64,
        /// Segment length, s.
        dwell_s: f64,
    },
    /// Ramp `axis` to `rate_dps`, wait `settle_s`, record a rate segment of `dwell_s`.
    Rate {
        /// Segment id.
        id: String,
        /// The spinning axis.
        axis: Axis,
        /// Commanded rate, deg/s.
        rate_dps: f64,
        /// Wait at the rate before the segment, s.
        settle_s: f64,
        /// Segment length, s.
        dwell_s: f64,
    },
    /// Ramp `axis` to rest, then move it to the nearest whole turn.
    Stop(Axis),
    /// Stay as is (at rest or spinning) for this many seconds, no segment.
    Hold(f64),
}

/// What the table does: a list of steps and how it moves between them.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// Steps, in order.
    pub steps: Vec<Step>,
    /// Rest at zero before the first step, s.
    pub lead_s: f64,
    /// Rest after the last step, s.
    pub tail_s: f64,
    /// Peak rate of a cosine move between angles, deg/s.
    pub move_rate_dps: f64,
    /// Peak angular acceleration of a cosine ramp between rates, deg/s^2.
    pub ramp_accel_dps2: f64,
    /// Settling time the builder methods use, s.
    pub settle_s: f64,
}

impl Default for Plan {
    fn default() -> Self {
        Plan {
            steps: Vec::new(),
            lead_s: 20.0,
            tail_s: 5.0,
            move_rate_dps: 30.0,
            ramp_accel_dps2: 30.0,
            settle_s: 10.0,
        }
    }
}

impl Plan {
    /// An empty plan with the default motion limits.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a static segment `id` at (`pitch_deg`, `roll_deg`) lasting `dwell_s`.
    pub fn at(mut self, id: &str, pitch_deg: f64, roll_deg: f64, dwell_s: f64) -> Self {
        self.steps.push(Step::Static {
            id: id.into(),
            pitch_deg,
            roll_deg,
            settle_s: self.settle_s,
            dwell_s,
        });
        self
    }

    /// Adds a rate segment `id` about `axis` at `rate_dps` lasting `dwell_s`.
    pub fn spin(mut self, id: &str, axis: Axis, rate_dps: f64, dwell_s: f64) -> Self {
        self.steps.push(Step::Rate {
            id: id.into(),
            axis,
            rate_dps,
            settle_s: self.settle_s,
            dwell_s,
        });
        self
    }

    /// Stops `axis` and brings it to the nearest whole turn.
    pub fn stop(mut self, axis: Axis) -> Self {
        self.steps.push(Step::Stop(axis));
        self
    }

    /// The standard two-dimensional procedure's shape (`../shared/examples/open-null`):
    /// six static attitudes of 10 s, a static gyro-bias block of `gyro_bias_s`, rate points
    /// -100, -50, 0, +50, +100 deg/s about the outer then the inner axis, 10 s each.
    pub fn standard(gyro_bias_s: f64) -> Self {
        let mut plan = Plan::new();
        let attitudes = [
            (0.0, 0.0),
            (0.0, 180.0),
            (90.0, 0.0),
            (-90.0, 0.0),
            (0.0, 90.0),
            (0.0, -90.0),
        ];
        for (n, (pitch, roll)) in attitudes.into_iter().enumerate() {
            plan = plan.at(&format!("accel_static/{}", n + 1), pitch, roll, 10.0);
        }
        plan = plan.at("gyro_bias", 0.0, 0.0, gyro_bias_s);
        for axis in [Axis::Outer, Axis::Inner] {
            for rate in [-100, -50, 0, 50, 100] {
                let id = format!("gyro_scale/{}/{rate:+}", axis.name());
                plan = plan.spin(&id, axis, f64::from(rate), 10.0);
            }
            plan = plan.stop(axis);
        }
        plan
    }
}

/// One axis's motion over a phase, in closed form of the time `tau` since the phase began.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Piece {
    /// At rest at this angle, deg.
    Rest(f64),
    /// `a0 + (a1 - a0) (1 - cos(pi tau / T)) / 2`, deg.
    Move { a0: f64, a1: f64 },
    /// Rate `w0 + (w1 - w0) (1 - cos(pi tau / T)) / 2`, deg/s, from angle `a0`.
    Ramp { a0: f64, w0: f64, w1: f64 },
    /// Constant rate `w` from angle `a0`.
    Spin { a0: f64, w: f64 },
}

impl Piece {
    /// (angle deg, rate deg/s, acceleration deg/s^2) at `tau` into a phase of length `len`.
    fn eval(self, tau: f64, len: f64) -> [f64; 3] {
        let s = PI * tau / len;
        match self {
            Piece::Rest(a) => [a, 0.0, 0.0],
            Piece::Move { a0, a1 } => {
                let d = a1 - a0;
                [
                    a0 + d * (1.0 - s.cos()) / 2.0,
                    d * PI / (2.0 * len) * s.sin(),
                    d * PI * PI / (2.0 * len * len) * s.cos(),
                ]
            }
            Piece::Ramp { a0, w0, w1 } => {
                let dw = w1 - w0;
                [
                    a0 + w0 * tau + dw * (tau / 2.0 - len / (2.0 * PI) * s.sin()),
                    w0 + dw * (1.0 - s.cos()) / 2.0,
                    dw * PI / (2.0 * len) * s.sin(),
                ]
            }
            Piece::Spin { a0, w } => [a0 + w * tau, w, 0.0],
        }
    }
}

#[derive(Debug, Clone, Copy)]
struct Phase {
    t0: f64,
    len: f64,
    axes: [Piece; 2],
}

/// A recorded segment: what the manifest says about it.
#[derive(Debug, Clone, PartialEq)]
pub struct SegmentSpec {
    /// Segment id.
    pub id: String,
    /// Start, table time, s.
    pub t_start: f64,
    /// End, table time, s.
    pub t_end: f64,
    /// Static attitude (pitch, roll), deg, for a static segment.
    pub attitude_deg: Option<(f64, f64)>,
    /// (axis, rate deg/s) for a rate segment.
    pub rate: Option<(Axis, f64)>,
}

/// Both axes' state at one instant: `[outer, inner]` of (angle deg, rate deg/s,
/// acceleration deg/s^2).
pub type AxesState = [[f64; 3]; 2];

/// A plan laid out in time.
#[derive(Debug, Clone)]
pub struct Timeline {
    phases: Vec<Phase>,
    /// The recorded segments, in time order.
    pub segments: Vec<SegmentSpec>,
    /// The end of the motion (and of both streams), table time, s.
    pub duration_s: f64,
}

impl Timeline {
    /// Lays `plan` out in time, starting at rest at zero.
    pub fn new(plan: &Plan) -> Timeline {
        let mut b = Builder {
            phases: Vec::new(),
            t: 0.0,
            angle: [0.0; 2],
            rate: [0.0; 2],
        };
        let mut segments = Vec::new();
        b.hold(plan.lead_s);
        for step in &plan.steps {
            match step {
                Step::Static {
                    id,
                    pitch_deg,
                    roll_deg,
                    settle_s,
                    dwell_s,
                } => {
                    for i in 0..2 {
                        b.ramp(i, 0.0, plan.ramp_accel_dps2);
                    }
                    let target = [
                        nearest_turn(*pitch_deg, b.angle[0]),
                        nearest_turn(*roll_deg, b.angle[1]),
                    ];
                    b.move_to(target, plan.move_rate_dps);
                    b.settle(*settle_s);
                    segments.push(SegmentSpec {
                        id: id.clone(),
                        t_start: b.t,
                        t_end: b.t + dwell_s,
                        attitude_deg: Some((*pitch_deg, *roll_deg)),
                        rate: None,
                    });
                    b.hold(*dwell_s);
                }
                Step::Rate {
                    id,
                    axis,
                    rate_dps,
                    settle_s,
                    dwell_s,
                } => {
                    b.ramp(*axis as usize, *rate_dps, plan.ramp_accel_dps2);
                    b.settle(*settle_s);
                    segments.push(SegmentSpec {
                        id: id.clone(),
                        t_start: b.t,
                        t_end: b.t + dwell_s,
                        attitude_deg: None,
                        rate: Some((*axis, *rate_dps)),
                    });
                    b.hold(*dwell_s);
                }
                Step::Stop(axis) => {
                    let i = *axis as usize;
                    b.ramp(i, 0.0, plan.ramp_accel_dps2);
                    let mut target = b.angle;
                    target[i] = nearest_turn(0.0, b.angle[i]);
                    b.move_to(target, plan.move_rate_dps);
                }
                Step::Hold(s) => b.hold(*s),
            }
        }
        for i in 0..2 {
            b.ramp(i, 0.0, plan.ramp_accel_dps2);
        }
        b.hold(plan.tail_s);
        Timeline {
            phases: b.phases,
            segments,
            duration_s: b.t,
        }
    }

    /// Both axes' angle, rate and acceleration at table time `t` (held at the ends).
    pub fn state(&self, t: f64) -> AxesState {
        let k = self.phases.partition_point(|p| p.t0 <= t).max(1) - 1;
        let p = &self.phases[k];
        let tau = (t - p.t0).clamp(0.0, p.len);
        [p.axes[0].eval(tau, p.len), p.axes[1].eval(tau, p.len)]
    }
}

/// The angle equivalent to `target` (modulo 360) nearest `current`.
fn nearest_turn(target: f64, current: f64) -> f64 {
    target + 360.0 * ((current - target) / 360.0).round()
}

struct Builder {
    phases: Vec<Phase>,
    t: f64,
    angle: [f64; 2],
    rate: [f64; 2],
}

impl Builder {
    fn current(&self, i: usize) -> Piece {
        if self.rate[i] == 0.0 {
            Piece::Rest(self.angle[i])
        } else {
            Piece::Spin {
                a0: self.angle[i],
                w: self.rate[i],
            }
        }
    }

    fn push(&mut self, len: f64, axes: [Piece; 2]) {
        if len <= 0.0 {
            return;
        }
        let p = Phase {
            t0: self.t,
            len,
            axes,
        };
        for (i, piece) in axes.iter().enumerate() {
            let [a, w, _] = piece.eval(len, len);
            self.angle[i] = a;
            // A ramp ends at exactly its rate (cos(pi) leaves ~1e-16 otherwise).
            self.rate[i] = match piece {
                Piece::Ramp { w1, .. } | Piece::Spin { w: w1, .. } => *w1,
                Piece::Rest(_) | Piece::Move { .. } => 0.0,
            };
            debug_assert!((self.rate[i] - w).abs() < 1e-9);
        }
        self.phases.push(p);
        self.t += len;
    }

    /// Continue as is for `len` s.
    fn hold(&mut self, len: f64) {
        self.push(len, [self.current(0), self.current(1)]);
    }

    /// Continue as is for at least `len` s, until a time on the half second, so that
    /// segments start at readable times.
    fn settle(&mut self, len: f64) {
        let end = ((self.t + len) * 2.0).ceil() / 2.0;
        self.hold(end - self.t);
    }

    /// Cosine ramp of axis `i`'s rate to `w1` at peak acceleration `accel`.
    fn ramp(&mut self, i: usize, w1: f64, accel: f64) {
        let w0 = self.rate[i];
        if w0 == w1 {
            return;
        }
        let len = PI * (w1 - w0).abs() / (2.0 * accel);
        let mut axes = [self.current(0), self.current(1)];
        axes[i] = Piece::Ramp {
            a0: self.angle[i],
            w0,
            w1,
        };
        self.push(len, axes);
    }

    /// Cosine move of both (resting) axes to `target` at peak rate `rate`.
    fn move_to(&mut self, target: [f64; 2], rate: f64) {
        let d = (0..2)
            .map(|i| (target[i] - self.angle[i]).abs())
            .fold(0.0, f64::max);
        if d == 0.0 {
            return;
        }
        let len = PI * d / (2.0 * rate);
        let axes = [0, 1].map(|i| Piece::Move {
            a0: self.angle[i],
            a1: target[i],
        });
        self.push(len, axes);
        self.angle = target;
    }
}
