//! Candidate-effect files (`*.effect`): the spanned syntax tree and its parser. An engineer
//! writes an effect the registry lacks (its explanation, parameters with units, and what it
//! adds to the output channels as an expression over kinematic signals); the engine checks
//! the names and the linearity and tries it in `ratecal explain` (docs/user-effects.md).
//!
//! ```
//! let text = "effect k2 {\n  explanation \"second-order accelerometer nonlinearity\"\n  \
//!             param kx unit \"ug/g^2\" needs \"gravity along +-X\"\n  \
//!             ax += kx * 1e-6 * f_b.x^2 / g\n}\n";
//! let file = ratecal_grammar::effect::parse(text).unwrap();
//! assert_eq!(file.effects[0].name.node, "k2");
//! ```

mod lower;

use crate::ast::{Ident, Span, Spanned};
use crate::diag::Diagnostic;

/// Deepest parenthesis nesting an expression may use.
pub const MAX_DEPTH: usize = 32;

/// Deepest expression tree (a sum of n terms nests n levels).
pub const MAX_EXPR_DEPTH: usize = 256;

/// A whole effect file.
#[derive(Debug, Clone, PartialEq)]
pub struct EffectFile {
    /// The effects, in file order.
    pub effects: Vec<EffectDef>,
}

/// `effect name { ... }`.
#[derive(Debug, Clone, PartialEq)]
pub struct EffectDef {
    /// The effect's id.
    pub name: Ident,
    /// Its entries, in file order.
    pub items: Vec<EffectItem>,
    /// The whole block.
    pub span: Span,
}

/// An entry of an effect block.
#[derive(Debug, Clone, PartialEq)]
pub enum EffectItem {
    /// `explanation "..."`.
    Explanation(Spanned<String>),
    /// `follows "..."`: what a residual it explains correlates with.
    Follows(Spanned<String>),
    /// `param name unit "..." [needs "..."]`.
    Param(ParamDecl),
    /// `ax += expression`.
    Contribution(Contribution),
}

/// A parameter declaration.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamDecl {
    /// Name (results key).
    pub name: Ident,
    /// Unit as reported.
    pub unit: Spanned<String>,
    /// The motion that excites it.
    pub needs: Option<Spanned<String>>,
    /// The whole declaration.
    pub span: Span,
}

/// What the effect adds to one output channel.
#[derive(Debug, Clone, PartialEq)]
pub struct Contribution {
    /// The channel as written (`ax` ... `gz`).
    pub channel: Ident,
    /// The expression.
    pub expr: Expr,
    /// The whole statement.
    pub span: Span,
}

/// An expression node with its span.
#[derive(Debug, Clone, PartialEq)]
pub struct Expr {
    /// What it is.
    pub kind: ExprKind,
    /// Where it was written.
    pub span: Span,
}

/// Expression nodes.
#[derive(Debug, Clone, PartialEq)]
pub enum ExprKind {
    /// A number as written (the checker parses and bounds it).
    Number(String),
    /// A parameter, a constant or a signal (`w_b.x`).
    Name(String),
    /// `-a`.
    Neg(Box<Expr>),
    /// `a op b`.
    Binary(BinOp, Box<Expr>, Box<Expr>),
    /// `f(a, ...)`.
    Call(Ident, Vec<Expr>),
}

/// Binary operators.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BinOp {
    /// `+`
    Add,
    /// `-`
    Sub,
    /// `*`
    Mul,
    /// `/`
    Div,
    /// `^`
    Pow,
}

/// Parses an effect file. The diagnostic has no source attached: callers add theirs.
pub fn parse(text: &str) -> Result<EffectFile, Diagnostic> {
    if let Some(at) = too_deep(text) {
        return Err(Diagnostic::error(
            "effect::too_deep",
            format!("parentheses nested deeper than {MAX_DEPTH}"),
        )
        .label(Span::new(at, at + 1), "too deep")
        .help("split the expression into simpler terms"));
    }
    lower::parse_file(text)
}

/// The offset of the first `(` that opens nesting deeper than [`MAX_DEPTH`], outside
/// strings and comments: the parser recurses once per level.
fn too_deep(text: &str) -> Option<usize> {
    let (mut depth, mut in_str, mut in_comment, mut escape) = (0usize, false, false, false);
    for (i, b) in text.bytes().enumerate() {
        if in_comment {
            in_comment = b != b'\n';
        } else if in_str {
            if escape {
                escape = false;
            } else if b == b'\\' {
                escape = true;
            } else if b == b'"' || b == b'\n' {
                in_str = false;
            }
        } else {
            match b {
                b'#' => in_comment = true,
                b'"' => in_str = true,
                b'(' => {
                    depth += 1;
                    if depth > MAX_DEPTH {
                        return Some(i);
                    }
                }
                b')' => depth = depth.saturating_sub(1),
                _ => {}
            }
        }
    }
    None
}

#[cfg(test)]
mod tests;
