//! A manual station: the operator is asked for a pose or a turn (through the run's
//! [`Progress`](crate::Progress) hooks, and the table driver's `ask`, which a simulated
//! operator acts on), and the next `settle` waits for the unit to move, then for the IMU's
//! rest; a pose whose gravity is not on the face asked for is refused and asked again.
//! A turn is recorded as a `turn` segment from the end of the last pose to the moment the
//! settle that follows it finds rest, its window included: the settle judges rest on 0.1 s
//! block means under a fluctuation limit, so the tail of the motion may lie inside that
//! window, and a turn cut at the window's start loses it (the gyro fit integrates the
//! turn's samples). Static segments carry the attitude the operator was asked for
//! (`nominal` with its tolerance, or `unknown`).

use super::{Exec, Res};
use crate::JournalEvent;
use crate::command::substitute;
use ratecal_drivers::OperatorAsk;
use ratecal_plan::{Action, HandTurn, Node, Pose, Settle};
use ratecal_recording::{Attitude, Segment, SegmentKind};

/// How recent the motion that shows the unit was picked up must be, s.
const MOTION_WINDOW_S: f64 = 0.5;

/// What the interpreter remembers of the operator's last request.
#[derive(Debug, Clone, Default)]
pub(super) struct Manual {
    /// The pose asked for last (its attitude goes to the static segments after it).
    pose: Option<Pose>,
    /// A face to check when the unit comes to rest.
    check: Option<Pose>,
    /// A turn waiting for the rest that ends it: id, axis, angle, start.
    turn: Option<(String, Option<String>, Option<f64>, f64)>,
    /// The unit must be seen moving before its rest counts.
    pub(super) need_motion: bool,
    /// End of the last static segment, s.
    last_rest_end: Option<f64>,
}

/// The first action of `nodes` that `pick` keeps, in the order they run.
fn first<'a, T>(nodes: &'a [Node], pick: &impl Fn(&'a Action) -> Option<T>) -> Option<T> {
    nodes.iter().find_map(|n| match n {
        Node::Do(a) => pick(a),
        Node::Repeat { count, body, .. } => (*count > 0).then(|| first(body, pick)).flatten(),
    })
}

/// A signed body axis (`+x`, `-z`) as a unit vector.
pub(super) fn axis_vector(name: &str) -> Option<[f64; 3]> {
    let (sign, n) = match name.strip_prefix('-') {
        Some(n) => (-1.0, n),
        None => (1.0, name.trim_start_matches('+')),
    };
    let k = ["x", "y", "z"].iter().position(|a| *a == n)?;
    let mut v = [0.0; 3];
    v[k] = sign;
    Some(v)
}

/// The face (`+x`...) nearest to gravity's direction in a mean accelerometer vector, and
/// the angle between them, deg.
fn nearest_face(f: [f64; 3]) -> (String, f64) {
    let norm = f.iter().map(|x| x * x).sum::<f64>().sqrt().max(1e-12);
    let k = (0..3)
        .max_by(|a, b| f[*a].abs().total_cmp(&f[*b].abs()))
        .unwrap_or(2);
    let sign = if f[k] >= 0.0 { "+" } else { "-" };
    let angle = (f[k].abs() / norm).clamp(-1.0, 1.0).acos().to_degrees();
    (format!("{sign}{}", ["x", "y", "z"][k]), angle)
}

impl Exec<'_> {
    pub(super) async fn place(&mut self, p: &Pose) -> Res {
        self.progress.message(&p.message);
        let ask = OperatorAsk::Pose {
            up: p.up.as_deref().and_then(axis_vector),
            tolerance_deg: p.tolerance_deg.unwrap_or(0.0),
        };
        self.ask(ask).await?;
        self.manual.pose = Some(p.clone());
        self.manual.check = p.up.is_some().then(|| p.clone());
        self.manual.need_motion = true;
        Ok(())
    }

    pub(super) async fn turn(&mut self, t: &HandTurn, vars: &[(String, u64)]) -> Res {
        self.progress.message(&t.message);
        let about = t.axis.as_deref().and_then(axis_vector).zip(t.angle_deg);
        self.ask(OperatorAsk::Turn { about }).await?;
        let start = self.manual.last_rest_end.unwrap_or_else(|| self.now());
        let id = substitute(&t.segment, vars);
        self.manual.turn = Some((id, t.axis.clone(), t.angle_deg, start));
        if t.axis.is_none() {
            // A free turn ends in a pose nobody knows.
            self.manual.pose = Some(Pose {
                up: None,
                tolerance_deg: None,
                message: String::new(),
            });
            self.manual.check = None;
        }
        self.manual.need_motion = true;
        Ok(())
    }

    /// A resumed run on a manual station: the interruption left the unit anywhere. Unless
    /// the step begins by asking for a pose, the operator is asked for the last pose the
    /// earlier steps recorded (`opts.last_pose`) and the step waits for rest (its first
    /// `settle`), so that its first turn or acquisition starts from that pose. A hand-held
    /// pose cannot be placed again: the operator puts the unit down anywhere, and the turn
    /// that follows joins no recorded pose (the analysis leaves it out: the resume is in
    /// the manifest).
    pub(super) async fn resume_pose(&mut self, body: &[Node]) -> Res {
        let Some(last) = self.opts.last_pose.clone().filter(|_| self.operator) else {
            return Ok(());
        };
        let up = last
            .up
            .clone()
            .filter(|_| last.attitude() == Attitude::Nominal);
        let placed_first = first(body, &|a| match a {
            Action::Place(_) => Some(true),
            Action::Turn(_) | Action::Acquire(_) => Some(false),
            _ => None,
        });
        let settle = first(body, &|a| match a {
            Action::Settle(s) => Some(s.clone()),
            _ => None,
        });
        let (Some(false), Some(settle)) = (placed_first, settle) else {
            return Ok(());
        };
        let message = match &up {
            Some(face) => format!(
                "Resuming after the interruption: place the unit with {} up on the fixture again (its last pose, {}), then keep it still",
                face.to_uppercase(),
                last.id
            ),
            None => format!(
                "Resuming after the interruption: the last pose ({}, held by hand) cannot be placed again; put the unit down and keep it still (the next turn starts from there and is left out of the gyro fit)",
                last.id
            ),
        };
        let tolerance_deg = up.as_ref().and(last.tolerance_deg);
        self.place(&Pose {
            up,
            tolerance_deg,
            message,
        })
        .await?;
        self.settle(&settle).await
    }

    async fn ask(&mut self, ask: OperatorAsk) -> Res {
        self.journal(JournalEvent::Command {
            command: format!("operator: {ask:?}"),
        });
        match self.table.ask(ask).await {
            Ok(()) => Ok(()),
            Err(e) => Err(self.driver_abort("table", &e)),
        }
    }

    /// Whether the operator was asked something that a settle must wait for.
    pub(super) fn awaiting_operator(&self) -> bool {
        self.manual.need_motion || self.manual.turn.is_some() || self.manual.check.is_some()
    }

    /// Whether the IMU shows motion now (any stability condition of `s` broken over the
    /// last half second).
    pub(super) fn moving(&self, s: &Settle, now: f64) -> bool {
        s.stable.iter().any(|st| {
            self.live
                .peak_to_peak(st.signal, now - MOTION_WINDOW_S, now)
                .is_some_and(|p| p.iter().any(|v| v.is_nan() || *v > st.max_fluctuation))
        }) || s.stable.is_empty()
    }

    /// The unit is at rest: checks the pose (refusing it, and asking again, when gravity
    /// is on another face) and closes the turn that led here. `false`: refused.
    pub(super) async fn at_rest(&mut self, s: &Settle, now: f64) -> Result<bool, super::Stop> {
        let window = s.stable.iter().map(|st| st.window_s).fold(0.0, f64::max);
        if let Some(p) = self.manual.check.clone()
            && let Some(up) = p.up.as_deref()
            && let Some(f) = self.live.accel_mean(now - window, now)
        {
            let want = axis_vector(up).unwrap_or([0.0, 0.0, 1.0]);
            let norm = f.iter().map(|x| x * x).sum::<f64>().sqrt().max(1e-12);
            let cos = (0..3).map(|k| f[k] * want[k]).sum::<f64>() / norm;
            let off = cos.clamp(-1.0, 1.0).acos().to_degrees();
            let tol = p.tolerance_deg.unwrap_or(5.0);
            if off > tol {
                let (face, _) = nearest_face(f);
                let text = format!(
                    "refused: gravity is on {} ({off:.1} deg from {} up, more than {tol} deg); place the unit with {} up again",
                    face.to_uppercase(),
                    up.to_uppercase(),
                    up.to_uppercase()
                );
                self.journal(JournalEvent::Warning {
                    rule: "pose".into(),
                    values: text.clone(),
                });
                self.progress.message(&text);
                self.ask(OperatorAsk::Refused).await?;
                self.manual.need_motion = true;
                return Ok(false);
            }
        }
        self.manual.check = None;
        if let Some((id, axis, angle, start)) = self.manual.turn.take() {
            // Up to the rest found now, not the start of its window: the window may still
            // hold the end of the motion (see the module's comment).
            let end = now.max(start);
            let mut seg = Segment::new(id.clone(), SegmentKind::Turn, start, end);
            seg.axis = axis;
            seg.angle_deg = angle;
            if let Err(e) = self.sink.segment(seg) {
                return Err(self.abort("recording error".into(), e.to_string()));
            }
            self.segments += 1;
            self.journal(JournalEvent::AcquireEnd {
                segment: id,
                t_start: start,
                t_end: end,
            });
        }
        Ok(true)
    }

    /// A static segment of a manual station carries the attitude asked for.
    pub(super) fn manual_segment(&mut self, seg: &mut Segment) {
        if !self.operator {
            return;
        }
        self.manual.last_rest_end = Some(seg.t_end);
        seg.pitch_deg = None;
        seg.roll_deg = None;
        match self
            .manual
            .pose
            .as_ref()
            .and_then(|p| p.up.clone().zip(p.tolerance_deg))
        {
            Some((up, tol)) => {
                seg.up = Some(up);
                seg.attitude = Some(Attitude::Nominal);
                seg.tolerance_deg = Some(tol);
            }
            None => seg.attitude = Some(Attitude::Unknown),
        }
    }

    /// Waits until the IMU shows the unit moving (the operator picked it up).
    pub(super) async fn await_motion(&mut self, s: &Settle, since: f64) -> Res {
        loop {
            let now = self.now();
            if self.moving(s, now) {
                self.manual.need_motion = false;
                return Ok(());
            }
            if s.timeout_s.is_some_and(|to| now - since >= to) {
                let unmet = "the unit was never picked up".to_string();
                return self.settle_timeout(s, now - since, unmet);
            }
            self.tick(None).await?;
        }
    }
}
