//! The spanned syntax tree of a procedure file. Every node that can carry an error has a
//! span; blocks keep the comments written in them so that the formatter can put them back.

use std::fmt;

/// A byte range in the source text (line and column are computed only when rendering).
#[derive(Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct Span {
    /// First byte.
    pub start: usize,
    /// One past the last byte.
    pub end: usize,
}

impl Span {
    /// A span from `start` to `end`.
    pub fn new(start: usize, end: usize) -> Self {
        Span { start, end }
    }

    /// The smallest span covering both.
    pub fn join(self, other: Span) -> Span {
        Span {
            start: self.start.min(other.start),
            end: self.end.max(other.end),
        }
    }

    /// Whether the byte offset lies inside.
    pub fn contains(self, pos: usize) -> bool {
        self.start <= pos && pos < self.end
    }

    /// Length in bytes.
    pub fn len(self) -> usize {
        self.end - self.start
    }

    /// Whether the span is empty.
    pub fn is_empty(self) -> bool {
        self.end == self.start
    }
}

impl fmt::Debug for Span {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "@{}..{}", self.start, self.end)
    }
}

impl From<Span> for miette::SourceSpan {
    fn from(s: Span) -> Self {
        (s.start, s.len()).into()
    }
}

/// A node with its span.
#[derive(Debug, Clone, PartialEq)]
pub struct Spanned<T> {
    /// The node.
    pub node: T,
    /// Where it was written.
    pub span: Span,
}

/// A name with its span.
pub type Ident = Spanned<String>;

/// A comment (`# text`): the text after `#`, trailing whitespace removed.
#[derive(Debug, Clone, PartialEq)]
pub struct Comment {
    /// Text after the `#`.
    pub text: String,
    /// Where it was written.
    pub span: Span,
}

/// One entry of a block, with the comments written before it and after it on its line.
#[derive(Debug, Clone, PartialEq)]
pub struct Item<T> {
    /// The entry.
    pub node: T,
    /// Where it was written.
    pub span: Span,
    /// Comments on the lines before it (and any written inside it outside nested blocks).
    pub comments: Vec<Comment>,
    /// A comment on the same line after it.
    pub trailing: Option<Comment>,
    /// Whether a blank line separated it from the previous entry.
    pub blank_before: bool,
}

/// A `{ ... }` block (or the whole file).
#[derive(Debug, Clone, PartialEq)]
pub struct Block<T> {
    /// Entries in order.
    pub items: Vec<Item<T>>,
    /// Comments after the last entry.
    pub end_comments: Vec<Comment>,
    /// From the opening to the closing brace (the whole text for a file).
    pub span: Span,
}

/// A whole file: imports, parameters and (in a procedure file) one procedure.
#[derive(Debug, Clone, PartialEq)]
pub struct File {
    /// Top-level entries.
    pub body: Block<TopItem>,
}

/// Top-level entry.
#[derive(Debug, Clone, PartialEq)]
pub enum TopItem {
    /// `import "lab-limits.rcal"`.
    Import(Spanned<String>),
    /// `param name = value`.
    Param(Param),
    /// `procedure name version x.y.z { ... }`.
    Procedure(Procedure),
}

/// `param name = value`.
#[derive(Debug, Clone, PartialEq)]
pub struct Param {
    /// Name.
    pub name: Ident,
    /// Value.
    pub value: Value,
}

/// A procedure.
#[derive(Debug, Clone, PartialEq)]
pub struct Procedure {
    /// Name (`imu-2d-standard`).
    pub name: Ident,
    /// Semantic version (`1.0.0`).
    pub version: Ident,
    /// Body.
    pub body: Block<ProcItem>,
}

/// An entry of a procedure body.
#[derive(Debug, Clone, PartialEq)]
pub enum ProcItem {
    /// `title "..."`.
    Title(Spanned<String>),
    /// `imu class tactical`.
    ImuClass(Ident),
    /// `reference "..."`.
    Reference(Spanned<String>),
    /// `meta key "value"`.
    Meta(Ident, Spanned<String>),
    /// `geometry vertical_outer`.
    Geometry(Ident),
    /// `param name = value`.
    Param(Param),
    /// `requires table { ... }`.
    Requires {
        /// `table`, `imu`, `daq`...
        subject: Ident,
        /// Limits.
        body: Block<Limit>,
    },
    /// `environment { ... }`.
    Environment(Block<EnvItem>),
    /// `abort when ...`.
    Abort(Abort),
    /// `step name "title" { ... }`.
    Step(Step),
    /// `accept ...`.
    Accept(Accept),
    /// `verify at ... { ... }`.
    Verify(Verify),
}

/// Comparison operator.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Cmp {
    /// `<=`
    Le,
    /// `<`
    Lt,
    /// `>=`
    Ge,
    /// `>`
    Gt,
}

impl Cmp {
    /// The operator as written.
    pub fn as_str(self) -> &'static str {
        match self {
            Cmp::Le => "<=",
            Cmp::Lt => "<",
            Cmp::Ge => ">=",
            Cmp::Gt => ">",
        }
    }
}

/// `name <= value` (requirements, settle conditions, acceptance and verification limits).
#[derive(Debug, Clone, PartialEq)]
pub struct Limit {
    /// Dotted name.
    pub name: Ident,
    /// Operator.
    pub op: Spanned<Cmp>,
    /// Limit.
    pub value: Value,
}

/// An environment precondition.
#[derive(Debug, Clone, PartialEq)]
pub struct EnvItem {
    /// `temperature`, `humidity`...
    pub name: Ident,
    /// The allowed band.
    pub bound: EnvBound,
}

/// How an environment band is written.
#[derive(Debug, Clone, PartialEq)]
pub enum EnvBound {
    /// `<= 0.5 degC/h`.
    Cmp(Spanned<Cmp>, Value),
    /// `20 degC +- 2 degC`.
    Tol(Value, Value),
    /// `40 % .. 60 %`.
    Range(Value, Value),
}

/// `abort when <condition> [for <time>] [-> action]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Abort {
    /// Condition.
    pub cond: Cond,
    /// Persistence.
    pub persist: Option<Value>,
    /// `abort` (default) or `warn`.
    pub action: Option<Ident>,
}

/// Abort conditions.
#[derive(Debug, Clone, PartialEq)]
pub enum Cond {
    /// `signal > value`.
    Cmp(Ident, Spanned<Cmp>, Value),
    /// `signal outside lo .. hi`.
    Outside(Ident, Value, Value),
    /// `signal drifts > value`.
    Drifts(Ident, Spanned<Cmp>, Value),
    /// `signal abnormal`.
    Abnormal(Ident),
}

/// `accept quantity <= limit [over N runs] [guarded]`, `accept abs(quantity) <= limit`,
/// `accept quantity within +-limit`.
#[derive(Debug, Clone, PartialEq)]
pub struct Accept {
    /// What is checked.
    pub checked: Checked,
    /// The bound it must meet.
    pub bound: AcceptBound,
    /// `over N runs`.
    pub runs: Option<Spanned<String>>,
    /// Guard-banded decision rule.
    pub guarded: bool,
}

/// The quantity an acceptance check is on: a dotted name, or a function of one
/// (`abs(gyro.scale.x)`, `norm(accel.bias)`).
#[derive(Debug, Clone, PartialEq)]
pub struct Checked {
    /// The function applied, if any (`abs`, `norm`).
    pub func: Option<Ident>,
    /// The dotted name it applies to.
    pub name: Ident,
    /// The whole expression.
    pub span: Span,
}

impl Checked {
    /// The expression as written, without spaces (`abs(gyro.scale.x)`).
    pub fn text(&self) -> String {
        match &self.func {
            Some(f) => format!("{}({})", f.node, self.name.node),
            None => self.name.node.clone(),
        }
    }
}

/// The bound of an acceptance check.
#[derive(Debug, Clone, PartialEq)]
pub enum AcceptBound {
    /// `<= 80 mg`.
    Cmp(Spanned<Cmp>, Value),
    /// `within +-1 mrad` (or `±1 mrad`): both sides.
    Within(Value),
}

/// `verify at <point> [from segments] { limits }`.
#[derive(Debug, Clone, PartialEq)]
pub struct Verify {
    /// The point.
    pub point: VerifyPoint,
    /// Segments that record it.
    pub from: Vec<Spanned<String>>,
    /// Limits.
    pub limits: Block<Limit>,
}

/// A verification point.
#[derive(Debug, Clone, PartialEq)]
pub enum VerifyPoint {
    /// `pitch 45 deg, roll 30 deg`.
    Attitude(Vec<Angle>),
    /// `outer rate 75 deg/s`.
    Rate {
        /// Axis.
        axis: Value,
        /// Rate.
        rate: Value,
    },
}

/// `pitch 45 deg` inside an attitude.
#[derive(Debug, Clone, PartialEq)]
pub struct Angle {
    /// `pitch`, `roll`, `outer` or `inner`.
    pub axis: Ident,
    /// Angle.
    pub value: Value,
}

/// `step name "title" { ... }`.
#[derive(Debug, Clone, PartialEq)]
pub struct Step {
    /// Name.
    pub name: Ident,
    /// Title.
    pub title: Option<Spanned<String>>,
    /// Statements.
    pub body: Block<Stmt>,
}

/// A statement of a step.
#[derive(Debug, Clone, PartialEq)]
pub enum Stmt {
    /// `move to pitch 0 deg, roll 0 deg`.
    Move(Vec<Angle>),
    /// `spin outer at 100 deg/s`.
    Spin {
        /// Axis.
        axis: Value,
        /// Rate.
        rate: Value,
    },
    /// `stop [axis]`.
    Stop(Option<Value>),
    /// `oscillate outer amplitude 90 deg period 5 s [center 0 deg] for 60 s`.
    Oscillate {
        /// Axis.
        axis: Value,
        /// Amplitude.
        amplitude: Value,
        /// Period.
        period: Value,
        /// Centre angle.
        center: Option<Value>,
        /// Duration.
        duration: Value,
    },
    /// `hold for 10 s`.
    Hold(Value),
    /// `settle for 30 s`.
    SettleFor(Value),
    /// `settle { ... }`.
    Settle(Block<SettleItem>),
    /// `acquire accel, gyro for 10 s at 100 Hz as "segment"`.
    Acquire {
        /// Channels.
        channels: Vec<Ident>,
        /// Duration.
        duration: Value,
        /// Sample rate.
        rate: Value,
        /// Segment name template.
        segment: Spanned<String>,
    },
    /// `for x in list { ... }` or `for (a, b) in list { ... }`.
    For {
        /// Loop variables.
        vars: Vec<Ident>,
        /// Whether the variables were written as a tuple.
        tuple: bool,
        /// The list (literal or parameter).
        list: Value,
        /// Body.
        body: Block<Stmt>,
    },
    /// `repeat N [as i] { ... }`.
    Repeat {
        /// Count.
        count: Value,
        /// Index variable.
        var: Option<Ident>,
        /// Body.
        body: Block<Stmt>,
    },
    /// `fit ...`.
    Fit(Fit),
    /// `accept ...`.
    Accept(Accept),
    /// `verify ...`.
    Verify(Verify),
    /// `abort when ...` scoped to the step.
    Abort(Abort),
    /// `remount z up "message"`.
    Remount {
        /// Body axis brought up.
        axis: Ident,
        /// What the operator is told.
        message: Option<Spanned<String>>,
    },
    /// `place +x up [within 5 deg] ["message"]` or `place free ["message"]` (manual station).
    Place {
        /// The body axis brought up (`+x`, or a loop variable); `None`: a free pose.
        face: Option<Ident>,
        /// How far the pose may be from the face (an angle).
        within: Option<Value>,
        /// What the operator is told.
        message: Option<Spanned<String>>,
    },
    /// `turn about +x by 360 deg as "turn/x"` or `turn free as "turn/1"` (manual station).
    Turn {
        /// The body axis turned about (`+x`, or a loop variable) and the angle; `None`: free.
        about: Option<(Ident, Value)>,
        /// Segment name template of the turn.
        segment: Spanned<String>,
    },
}

/// An entry of a settle block.
#[derive(Debug, Clone, PartialEq)]
pub enum SettleItem {
    /// `at least 30 s`.
    AtLeast(Value),
    /// `timeout 120 s [-> abort]`.
    Timeout(Value, Option<Ident>),
    /// `accel fluctuation <= 0.001 g over 5 s`.
    Fluctuation {
        /// Signal.
        signal: Ident,
        /// Operator.
        op: Spanned<Cmp>,
        /// Limit.
        value: Value,
        /// Window.
        window: Value,
    },
    /// `table.attitude_error <= 5 arcsec`.
    Limit(Limit),
}

/// `fit <sensor> [<model>] [(axes)] [with <effects>] from <patterns> [using <name>] [{ preprocessing }]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Fit {
    /// `accel`, `gyro`, `size_effect`...
    pub sensor: Ident,
    /// `bias_scale`, `bias`, `scale`...
    pub model: Option<Ident>,
    /// Declared axes.
    pub axes: Option<Vec<Ident>>,
    /// `with lever_arm, time_offset`: catalogue effects added to the model.
    pub with: Vec<Ident>,
    /// Segment patterns.
    pub from: Vec<Spanned<String>>,
    /// `using gyro_bias`.
    pub using: Option<Spanned<String>>,
    /// Preprocessing.
    pub options: Option<Block<FitOpt>>,
}

/// Preprocessing options of a fit.
#[derive(Debug, Clone, PartialEq)]
pub enum FitOpt {
    /// `outliers 3 sigma`.
    Sigma(Spanned<String>),
    /// `outliers grubbs [alpha 0.05]`.
    Grubbs(Option<Spanned<String>>),
    /// `lowpass butterworth order 4 cutoff 10 Hz`.
    Lowpass {
        /// Filter order.
        order: Spanned<String>,
        /// Cutoff frequency.
        cutoff: Value,
    },
}

/// A value: quantity, string, name, list or tuple.
#[derive(Debug, Clone, PartialEq)]
pub struct Value {
    /// What it is.
    pub kind: ValueKind,
    /// Where it was written.
    pub span: Span,
}

/// Kinds of values.
#[derive(Debug, Clone, PartialEq)]
pub enum ValueKind {
    /// `0.002 g`, `3` (the number as written).
    Quantity {
        /// Number as written.
        number: String,
        /// Unit as written.
        unit: Option<Ident>,
    },
    /// `"text"` (unescaped).
    Str(String),
    /// A name: a loop variable, a parameter or a symbol (`outer`, `x`).
    Name(String),
    /// `[a, b, c] unit` (the unit applies to bare numbers).
    List {
        /// Elements.
        items: Vec<Value>,
        /// Unit for bare numbers.
        unit: Option<Ident>,
    },
    /// `(a, b, c)`.
    Tuple(Vec<Value>),
}
