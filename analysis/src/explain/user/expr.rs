//! A checked expression: names resolved to parameters, signals and constants. Its
//! regressors are derived symbolically: the checker has shown the expression to be a sum
//! of terms each proportional to exactly one parameter, so its derivative with respect to
//! a parameter is that parameter's regressor, an expression over signals alone.

use super::signals::Fun;
use ratecal_physics::effects::Signals;

/// Arithmetic operators.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Op {
    Add,
    Sub,
    Mul,
    Div,
    Pow,
}

impl Op {
    fn apply(self, a: f64, b: f64) -> f64 {
        match self {
            Op::Add => a + b,
            Op::Sub => a - b,
            Op::Mul => a * b,
            Op::Div => a / b,
            Op::Pow => a.powf(b),
        }
    }
}

/// A resolved expression.
#[derive(Clone)]
pub(crate) enum Ex {
    Num(f64),
    /// A signal, read by its accessor.
    Sig(fn(&Signals) -> f64),
    /// A parameter of the effect (index).
    Param(usize),
    Neg(Box<Ex>),
    Bin(Op, Box<Ex>, Box<Ex>),
    Fun(Fun, Box<Ex>),
}

impl std::fmt::Debug for Ex {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Ex::Num(v) => write!(f, "{v}"),
            Ex::Sig(_) => write!(f, "signal"),
            Ex::Param(k) => write!(f, "p{k}"),
            Ex::Neg(a) => write!(f, "(-{a:?})"),
            Ex::Bin(op, a, b) => write!(f, "({a:?} {op:?} {b:?})"),
            Ex::Fun(fun, a) => write!(f, "{fun:?}({a:?})"),
        }
    }
}

/// `-a`, folded when `a` is a number.
pub(crate) fn neg(a: Ex) -> Ex {
    match a {
        Ex::Num(v) => Ex::Num(-v),
        a => Ex::Neg(Box::new(a)),
    }
}

/// `a op b`, folded when both are numbers; multiplying by one is dropped.
pub(crate) fn bin(op: Op, a: Ex, b: Ex) -> Ex {
    match (op, a, b) {
        (op, Ex::Num(x), Ex::Num(y)) => Ex::Num(op.apply(x, y)),
        (Op::Mul, Ex::Num(1.0), b) => b,
        (Op::Mul | Op::Div, a, Ex::Num(1.0)) => a,
        (op, a, b) => Ex::Bin(op, Box::new(a), Box::new(b)),
    }
}

/// `f(a)`, folded when `a` is a number.
pub(crate) fn fun(f: Fun, a: Ex) -> Ex {
    match a {
        Ex::Num(x) => Ex::Num(f.apply(x)),
        a => Ex::Fun(f, Box::new(a)),
    }
}

impl Ex {
    /// Its value at one instant; parameters count as zero (regressors hold none).
    pub(crate) fn eval(&self, s: &Signals) -> f64 {
        match self {
            Ex::Num(v) => *v,
            Ex::Sig(get) => get(s),
            Ex::Param(_) => 0.0,
            Ex::Neg(a) => -a.eval(s),
            Ex::Bin(op, a, b) => op.apply(a.eval(s), b.eval(s)),
            Ex::Fun(f, a) => f.apply(a.eval(s)),
        }
    }

    /// The derivative with respect to parameter `k`; `None` where it does not depend on
    /// it. Valid for expressions the checker accepted (linear in the parameters): powers
    /// and functions hold no parameter there, a divisor neither.
    pub(crate) fn d(&self, k: usize) -> Option<Ex> {
        match self {
            Ex::Num(_) | Ex::Sig(_) | Ex::Fun(..) => None,
            Ex::Param(j) => (*j == k).then_some(Ex::Num(1.0)),
            Ex::Neg(a) => a.d(k).map(neg),
            Ex::Bin(op @ (Op::Add | Op::Sub), a, b) => match (a.d(k), b.d(k)) {
                (Some(x), Some(y)) => Some(bin(*op, x, y)),
                (Some(x), None) => Some(x),
                (None, Some(y)) if *op == Op::Sub => Some(neg(y)),
                (None, y) => y,
            },
            Ex::Bin(Op::Mul, a, b) => match (a.d(k), b.d(k)) {
                (Some(x), Some(y)) => Some(bin(
                    Op::Add,
                    bin(Op::Mul, x, (**b).clone()),
                    bin(Op::Mul, (**a).clone(), y),
                )),
                (Some(x), None) => Some(bin(Op::Mul, x, (**b).clone())),
                (None, Some(y)) => Some(bin(Op::Mul, (**a).clone(), y)),
                (None, None) => None,
            },
            Ex::Bin(Op::Div, a, b) => a.d(k).map(|x| bin(Op::Div, x, (**b).clone())),
            Ex::Bin(Op::Pow, ..) => None,
        }
    }
}
