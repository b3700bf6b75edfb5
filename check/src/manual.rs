//! The manual station's statements: `place` (a fixture face or a free, hand-held pose) and
//! `turn` (a hand turn, recorded as a `turn` segment). The operator is the actuator, so a
//! procedure either moves a rate table or asks the operator, never both; a pose or a turn
//! is followed by a `settle` that watches the IMU, so that the step begins at rest.

use super::Ck;
use super::values::{Val, suggest};
use ratecal_grammar::Diagnostic;
use ratecal_grammar::ast::{Ident, Span, Spanned, Value};
use ratecal_plan::{Action, Dim, HandTurn, Pose, Settle};

/// Time an operator is assumed to need to place the unit, s.
const PLACE_S: f64 = 10.0;
/// Time an operator is assumed to need for a hand turn, s.
const TURN_S: f64 = 5.0;
/// Largest tolerance a fixture face may state, deg (beyond it, `place free`).
const MAX_TOLERANCE_DEG: f64 = 30.0;

/// What the walk knows of manual and rate-table statements.
#[derive(Debug, Default, Clone)]
pub(crate) struct ManualWalk {
    /// The first `place` or `turn`.
    pub first_manual: Option<Span>,
    /// The first statement that moves a rate table.
    pub first_table: Option<Span>,
    /// A `place` or `turn` still waiting for its `settle` on the IMU.
    pub awaiting_rest: Option<(Span, &'static str)>,
}

impl Ck<'_> {
    fn manual_station(&self) -> Option<bool> {
        self.station.as_ref().map(|s| s.manual)
    }

    /// A statement that moves a rate table (`move`, `spin`, `stop`, `oscillate`).
    pub(crate) fn table_statement(&mut self, span: Span) {
        if self.manual_station() == Some(true) {
            self.err(
                Diagnostic::error(
                    "check::manual_station",
                    "a manual station has no rate table to move",
                )
                .label(span, "needs a rate table")
                .help("ask the operator instead (`place +x up within 5 deg`, `turn about +x by 360 deg as \"turn/x\"`), or run on a rate-table station"),
            );
            return;
        }
        if self.manual_station().is_none()
            && self.walk.manual.first_table.is_none()
            && let Some(first) = self.walk.manual.first_manual
        {
            self.mixed(span, first);
        }
        self.walk.manual.first_table.get_or_insert(span);
    }

    fn mixed(&mut self, span: Span, other: Span) {
        self.err(
            Diagnostic::error(
                "check::manual_station",
                "a procedure either moves a rate table or asks the operator, not both",
            )
            .label(span, "this")
            .label(other, "and this")
            .help("split it into two procedures: one for a rate-table station, one for a manual station"),
        );
    }

    /// A `place` or `turn`: the station must be manual.
    fn manual_statement(&mut self, span: Span, what: &'static str) {
        if self.manual_station() == Some(false) {
            self.err(
                Diagnostic::error(
                    "check::manual_station",
                    format!("`{what}` asks the operator: it needs a manual station"),
                )
                .label(span, "on a rate-table station")
                .help("run it with a station whose `table.driver` is `manual` (drivers/stations/manual.yaml), or move the table with `move to pitch .., roll ..`"),
            );
        } else if self.manual_station().is_none()
            && self.walk.manual.first_manual.is_none()
            && let Some(first) = self.walk.manual.first_table
        {
            self.mixed(span, first);
        }
        self.walk.manual.first_manual.get_or_insert(span);
        self.rest_missing();
        self.walk.manual.awaiting_rest = Some((span, what));
    }

    /// An acquisition, a pose or a turn while the last pose or turn has not settled.
    pub(crate) fn rest_missing(&mut self) {
        if let Some((at, what)) = self.walk.manual.awaiting_rest.take() {
            self.err(
                Diagnostic::error(
                    "check::no_rest",
                    format!("`{what}` is not followed by a `settle` on the IMU"),
                )
                .label(at, "the unit may still be moving after this")
                .help("add `settle { gyro fluctuation <= .. over .. ; accel fluctuation <= .. over .. ; timeout .. }`: the step begins when the IMU shows rest"),
            );
        }
    }

    /// A settle: it ends a pose or a turn when it watches the IMU.
    pub(crate) fn settled(&mut self, st: &Settle) {
        if !st.stable.is_empty() {
            self.walk.manual.awaiting_rest = None;
        }
    }

    /// A body axis as written (`+x`, `-z`, `x`) or bound to a loop variable.
    fn face(&mut self, f: &Ident) -> Option<String> {
        let bound = self
            .scopes
            .iter()
            .rev()
            .flat_map(|s| s.iter())
            .find(|(n, _)| *n == f.node)
            .map(|(_, v)| v.v.clone());
        let name = match bound {
            Some(Val::Sym(s)) | Some(Val::Str(s)) => s,
            _ => f.node.clone(),
        };
        let n = name.trim();
        let signed = if n.starts_with(['+', '-']) {
            n.to_string()
        } else {
            format!("+{n}")
        };
        const FACES: [&str; 6] = ["+x", "-x", "+y", "-y", "+z", "-z"];
        if FACES.contains(&signed.as_str()) {
            return Some(signed);
        }
        self.err(
            Diagnostic::error("check::unknown_name", format!("unknown body axis `{n}`"))
                .label(f.span, "not a body axis")
                .help(suggest(n, &FACES)),
        );
        None
    }

    /// `place <face> up [within <angle>]` or `place free`.
    pub(crate) fn place(
        &mut self,
        face: Option<&Ident>,
        within: Option<&Value>,
        message: Option<&Spanned<String>>,
        span: Span,
    ) -> Option<Action> {
        self.manual_statement(span, "place");
        self.walk.time_s += PLACE_S;
        let Some(face) = face else {
            let message = message.map_or_else(
                || {
                    "Hold the unit in a new pose, different from the last ones, then keep it still"
                        .into()
                },
                |m| m.node.clone(),
            );
            return Some(Action::Place(Pose {
                up: None,
                tolerance_deg: None,
                message,
            }));
        };
        let up = self.face(face);
        let tol = match within {
            Some(v) => Some(self.face_tolerance(v)?),
            None => None,
        };
        let up = up?;
        let message = message.map_or_else(
            || {
                format!(
                    "Place the unit with {} up on the fixture, then keep it still",
                    up.to_uppercase()
                )
            },
            |m| m.node.clone(),
        );
        Some(Action::Place(Pose {
            up: Some(up),
            tolerance_deg: Some(tol.unwrap_or(5.0)),
            message,
        }))
    }

    fn face_tolerance(&mut self, v: &Value) -> Option<f64> {
        let q = self.quantity(v, Dim::Angle, "a pose tolerance")?;
        if q.value <= 0.0 || q.value > MAX_TOLERANCE_DEG {
            self.err(
                Diagnostic::error(
                    "check::bad_number",
                    format!("a face's tolerance must be in (0, {MAX_TOLERANCE_DEG}] deg"),
                )
                .label(v.span, "out of range")
                .help("a fixture's face is known within a few degrees; for a hand-held pose write `place free`"),
            );
            return None;
        }
        Some(q.value)
    }

    /// `turn about <face> by <angle> as "<segment>"` or `turn free as "<segment>"`.
    pub(crate) fn turn(
        &mut self,
        about: Option<&(Ident, Value)>,
        segment: &Spanned<String>,
        span: Span,
    ) -> Option<Action> {
        self.manual_statement(span, "turn");
        self.walk.time_s += TURN_S;
        let Some(id) = self.segment_id(&segment.node, segment.span) else {
            self.walk.incomplete = true;
            return None;
        };
        self.register_segment(&id, segment.span);
        let Some((face, angle)) = about else {
            return Some(Action::Turn(HandTurn {
                segment: id,
                axis: None,
                angle_deg: None,
                message: "Turn the unit freely to a new pose, then put it down and keep it still"
                    .into(),
            }));
        };
        let axis = self.face(face);
        let angle = self.quantity(angle, Dim::Angle, "a turn angle")?;
        let axis = axis?;
        Some(Action::Turn(HandTurn {
            segment: id,
            message: format!(
                "Turn the unit by {} about {}, then put it down and keep it still",
                turns(angle.value),
                axis.to_uppercase()
            ),
            axis: Some(axis),
            angle_deg: Some(angle.value),
        }))
    }
}

/// An angle for people: `one full turn`, `half a turn`, `90 deg`.
fn turns(deg: f64) -> String {
    match deg.abs() {
        a if (a - 360.0).abs() < 1e-9 => "one full turn".into(),
        a if (a - 180.0).abs() < 1e-9 => "half a turn".into(),
        a if (a % 360.0).abs() < 1e-9 => format!("{} full turns", a / 360.0),
        _ => format!("{deg} deg"),
    }
}
