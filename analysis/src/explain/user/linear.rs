//! Resolves a contribution's names (parameters, signals, constants, functions) and
//! classifies how it depends on the parameters, from the syntax tree: the joint fit needs a
//! sum of terms, each exactly one parameter times an expression of signals.

use super::expr::{Ex, Op, bin, fun, neg};
use super::signals::{CONSTANTS, FUNCTIONS, SignalDef};
use ratecal_grammar::Diagnostic;
use ratecal_grammar::ast::Span;
use ratecal_grammar::effect::{BinOp, Expr, ExprKind};
use std::collections::BTreeSet;

/// How an expression depends on the parameters.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(crate) enum Class {
    /// On none.
    Free,
    /// Every term proportional to exactly one parameter.
    Linear,
    /// Already reported.
    Bad,
}

/// What a contribution is checked against, and what the check found.
pub(crate) struct Cx<'a> {
    /// The effect's parameters and where each is declared.
    pub params: &'a [(String, Span)],
    pub signals: &'a [SignalDef],
    /// Parameters and signals read so far.
    pub used_params: BTreeSet<usize>,
    pub used_signals: BTreeSet<&'static str>,
    pub diags: Vec<Diagnostic>,
}

/// `did you mean `x`? ` when a name is close to a known one.
pub(crate) fn suggestion<'a>(name: &str, known: impl Iterator<Item = &'a str>) -> String {
    known
        .map(|k| (strsim::jaro_winkler(name, k), k))
        .filter(|(score, _)| *score > 0.8)
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, k)| format!("did you mean `{k}`? "))
        .unwrap_or_default()
}

fn not_linear(span: Span, label: &str, why: &str) -> Diagnostic {
    Diagnostic::error("effect::not_linear", format!("not linear in the parameters: {why}"))
        .label(span, label)
        .help("the joint fit is linear least squares: write the contribution as a sum of terms, each one parameter times an expression of signals")
}

/// Resolves an expression and classifies how it depends on the parameters.
pub(crate) fn lin(e: &Expr, cx: &mut Cx) -> (Ex, Class) {
    match &e.kind {
        ExprKind::Number(n) => match n.parse::<f64>() {
            Ok(v) if v.is_finite() => (Ex::Num(v), Class::Free),
            _ => {
                cx.diags.push(
                    Diagnostic::error(
                        "effect::bad_number",
                        format!("`{n}` is not a finite number"),
                    )
                    .label(e.span, "out of range")
                    .help("write a number between about -1e308 and 1e308"),
                );
                (Ex::Num(0.0), Class::Bad)
            }
        },
        ExprKind::Name(n) => name(n, e.span, cx),
        ExprKind::Neg(a) => {
            let (x, c) = lin(a, cx);
            (neg(x), c)
        }
        ExprKind::Call(f, args) => {
            let Some((_, which)) = FUNCTIONS.iter().find(|(k, _)| *k == f.node) else {
                let names: Vec<&str> = FUNCTIONS.iter().map(|f| f.0).collect();
                cx.diags.push(
                    Diagnostic::error(
                        "effect::unknown_function",
                        format!("unknown function `{}`", f.node),
                    )
                    .label(f.span, "not a function of the expression language")
                    .help(format!(
                        "{}the functions are {}",
                        suggestion(&f.node, names.iter().copied()),
                        names.join(", ")
                    )),
                );
                return (Ex::Num(0.0), Class::Bad);
            };
            if args.len() != 1 {
                cx.diags.push(
                    Diagnostic::error(
                        "effect::arity",
                        format!("`{}` takes one argument, not {}", f.node, args.len()),
                    )
                    .label(e.span, "here")
                    .help(format!("write `{}(x)`", f.node)),
                );
                return (Ex::Num(0.0), Class::Bad);
            }
            let (x, c) = lin(&args[0], cx);
            if c == Class::Linear {
                cx.diags.push(not_linear(
                    args[0].span,
                    "holds a parameter",
                    &format!("a parameter inside `{}`", f.node),
                ));
                return (x, Class::Bad);
            }
            (fun(*which, x), c)
        }
        ExprKind::Binary(op, a, b) => {
            let (x, ca) = lin(a, cx);
            let (y, cb) = lin(b, cx);
            if ca == Class::Bad || cb == Class::Bad {
                return (Ex::Num(0.0), Class::Bad);
            }
            use Class::{Free, Linear};
            let class = match (op, ca, cb) {
                (_, Free, Free) => Free,
                (BinOp::Add | BinOp::Sub, Linear, Linear) => Linear,
                (BinOp::Add | BinOp::Sub, _, _) => {
                    let free = if ca == Free { a.span } else { b.span };
                    cx.diags.push(
                        Diagnostic::error("effect::no_parameter", "this term holds no parameter")
                            .label(free, "added to terms that hold parameters")
                            .help("every term of a contribution is a parameter times signals; a fixed offset is not fitted (the biases are already in the model)"),
                    );
                    return (Ex::Num(0.0), Class::Bad);
                }
                (BinOp::Mul, Linear, Linear) => {
                    cx.diags.push(
                        not_linear(
                            e.span,
                            "a product of two parameter terms",
                            "parameters multiply each other",
                        )
                        .label(a.span, "holds a parameter")
                        .label(b.span, "holds a parameter"),
                    );
                    return (Ex::Num(0.0), Class::Bad);
                }
                (BinOp::Mul, _, _) => Linear,
                (BinOp::Div, Linear, Free) => Linear,
                (BinOp::Div, _, _) => {
                    cx.diags.push(not_linear(
                        b.span,
                        "holds a parameter",
                        "a parameter in a divisor",
                    ));
                    return (Ex::Num(0.0), Class::Bad);
                }
                (BinOp::Pow, _, _) => {
                    cx.diags.push(not_linear(
                        e.span,
                        "a power of a parameter term",
                        "a parameter in a power",
                    ));
                    return (Ex::Num(0.0), Class::Bad);
                }
            };
            let op = match op {
                BinOp::Add => Op::Add,
                BinOp::Sub => Op::Sub,
                BinOp::Mul => Op::Mul,
                BinOp::Div => Op::Div,
                BinOp::Pow => Op::Pow,
            };
            (bin(op, x, y), class)
        }
    }
}

fn name(n: &str, span: Span, cx: &mut Cx) -> (Ex, Class) {
    if let Some(k) = cx.params.iter().position(|(p, _)| p == n) {
        cx.used_params.insert(k);
        return (Ex::Param(k), Class::Linear);
    }
    if let Some((_, v)) = CONSTANTS.iter().find(|c| c.0 == n) {
        return (Ex::Num(*v), Class::Free);
    }
    if let Some(s) = cx.signals.iter().find(|s| s.name == n) {
        cx.used_signals.insert(s.name);
        return (Ex::Sig(s.get), Class::Free);
    }
    let known = cx
        .params
        .iter()
        .map(|p| p.0.as_str())
        .chain(cx.signals.iter().map(|s| s.name))
        .chain(CONSTANTS.iter().map(|c| c.0));
    let hint = suggestion(n, known);
    let (what, help) = if n.contains('.') {
        (
            "signal",
            format!(
                "{hint}signals are written `f_b.x`, `w_b.y`, `up_b.z`... (docs/user-effects.md)"
            ),
        )
    } else {
        (
            "parameter or signal",
            format!(
                "{hint}declare it with `param {n} unit \"...\" needs \"...\"`, or use a signal of docs/user-effects.md"
            ),
        )
    };
    cx.diags.push(
        Diagnostic::error("effect::unknown_name", format!("unknown {what} `{n}`"))
            .label(span, "not a parameter, signal or constant")
            .help(help),
    );
    (Ex::Num(0.0), Class::Bad)
}
