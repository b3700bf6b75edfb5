//! The only file of the effect language that sees pest: parses with `effect.pest` and
//! lowers the pairs to the effect AST, or turns pest's error into a located diagnostic.

use super::{
    BinOp, Contribution, EffectDef, EffectFile, EffectItem, Expr, ExprKind, MAX_EXPR_DEPTH,
    ParamDecl,
};
use crate::ast::{Span, Spanned};
use crate::diag::Diagnostic;
use crate::syntax::{self, Language};
use pest::Parser;
use pest::iterators::Pair;

#[derive(pest_derive::Parser)]
#[grammar = "effect/effect.pest"]
struct Grammar;

type P<'a> = Pair<'a, Rule>;

/// Parses a file.
pub(crate) fn parse_file(text: &str) -> Result<EffectFile, Diagnostic> {
    let mut pairs =
        Grammar::parse(Rule::file, text).map_err(|e| syntax::error(e, text, &SYNTAX))?;
    let file = pairs
        .next()
        .ok_or_else(|| Diagnostic::error("effect::syntax", "empty parse"))?;
    let mut deep = None;
    let effects = file
        .into_inner()
        .filter(|p| p.as_rule() == Rule::effect)
        .map(|p| effect(p, &mut deep))
        .collect();
    match deep {
        Some(at) => Err(Diagnostic::error(
            "effect::too_deep",
            format!("an expression nests deeper than {MAX_EXPR_DEPTH} levels"),
        )
        .label(Span::new(at.start, at.start), "too deep from here")
        .help("a long sum nests one level per term: split it over several contributions to the same channel (they add up)")),
        None => Ok(EffectFile { effects }),
    }
}

/// How this language words its syntax errors.
const SYNTAX: Language<Rule> = Language {
    code: "effect::syntax",
    help: "an effect file holds `effect <name> { explanation \"...\" param <name> unit \"...\" needs \"...\" <channel> += <expression> }`; see docs/user-effects.md",
    rule_name,
    keyword,
};

/// The keyword that `rest` begins with, if any.
fn keyword(rest: &str) -> Option<&str> {
    let mut kw = Grammar::parse(Rule::keyword, rest).ok()?;
    kw.next().map(|kw| kw.as_str())
}

fn rule_name(r: Rule) -> Option<&'static str> {
    Some(match r {
        Rule::EOI => "end of file",
        Rule::effect => "`effect`",
        Rule::ident => "a name",
        Rule::name => "a parameter or signal",
        Rule::string => "a quoted string",
        Rule::number => "a number",
        Rule::explanation => "`explanation`",
        Rule::follows => "`follows`",
        Rule::param => "`param`",
        Rule::needs => "`needs`",
        Rule::contribution => "a contribution (`ax += ...`)",
        Rule::add_op | Rule::mul_op => "an operator",
        Rule::neg => "`-`",
        Rule::expr | Rule::term | Rule::factor | Rule::power | Rule::exponent => "an expression",
        Rule::paren => "`(`",
        Rule::call => "a function call",
        _ => return None,
    })
}

fn span(p: &P) -> Span {
    let s = p.as_span();
    Span::new(s.start(), s.end())
}

fn text(p: P) -> Spanned<String> {
    Spanned {
        span: span(&p),
        node: p.as_str().to_string(),
    }
}

fn string(p: P) -> Spanned<String> {
    let sp = span(&p);
    let raw = p.into_inner().next().map_or("", |i| i.as_str());
    let mut out = String::with_capacity(raw.len());
    let mut chars = raw.chars();
    while let Some(c) = chars.next() {
        if c == '\\' {
            match chars.next() {
                Some('n') => out.push('\n'),
                Some('t') => out.push('\t'),
                Some(o) => out.push(o),
                None => {}
            }
        } else {
            out.push(c);
        }
    }
    Spanned {
        node: out,
        span: sp,
    }
}

fn effect(p: P, deep: &mut Option<Span>) -> EffectDef {
    let sp = span(&p);
    let mut inner = p.into_inner();
    let name = inner.next().map(text).unwrap_or_else(|| Spanned {
        node: String::new(),
        span: sp,
    });
    let items = inner.filter_map(|i| item(i, deep)).collect();
    EffectDef {
        name,
        items,
        span: sp,
    }
}

fn item(p: P, deep: &mut Option<Span>) -> Option<EffectItem> {
    let sp = span(&p);
    let rule = p.as_rule();
    let mut inner = p.into_inner();
    Some(match rule {
        Rule::explanation => EffectItem::Explanation(string(inner.next()?)),
        Rule::follows => EffectItem::Follows(string(inner.next()?)),
        Rule::param => EffectItem::Param(ParamDecl {
            name: text(inner.next()?),
            unit: string(inner.next()?),
            needs: inner.next().and_then(|n| n.into_inner().next()).map(string),
            span: sp,
        }),
        Rule::contribution => {
            let channel = text(inner.next()?);
            let mut cx = Lower::default();
            let (expr, _) = expr(inner.next()?, &mut cx);
            if let Some(at) = cx.too_deep {
                *deep = deep.or(Some(at));
            }
            EffectItem::Contribution(Contribution {
                channel,
                expr,
                span: sp,
            })
        }
        _ => return None,
    })
}

fn binop(p: &P) -> BinOp {
    match p.as_str() {
        "+" => BinOp::Add,
        "-" => BinOp::Sub,
        "*" => BinOp::Mul,
        _ => BinOp::Div,
    }
}

/// An expression and the depth of its tree.
type D = (Expr, usize);

/// Lowering state: where an expression first grew deeper than [`MAX_EXPR_DEPTH`]. Trees
/// never grow past it (the rest of the expression is dropped), so nothing downstream, the
/// drop glue included, recurses deeper.
#[derive(Default)]
struct Lower {
    too_deep: Option<Span>,
}

impl Lower {
    fn node(&mut self, kind: ExprKind, span: Span, depth: usize) -> D {
        if depth > MAX_EXPR_DEPTH {
            self.too_deep.get_or_insert(span);
            return (zero(span), 1);
        }
        (Expr { kind, span }, depth)
    }
}

fn zero(span: Span) -> Expr {
    Expr {
        kind: ExprKind::Number("0".into()),
        span,
    }
}

/// `expr` and `term`: a left-associative chain, folded without recursion.
fn chain(p: P, cx: &mut Lower, operand: fn(P, &mut Lower) -> D) -> D {
    let sp = span(&p);
    let mut inner = p.into_inner();
    let Some(first) = inner.next() else {
        return (zero(sp), 1);
    };
    let (mut acc, mut depth) = operand(first, cx);
    while let (Some(op), Some(rhs)) = (inner.next(), inner.next()) {
        let (rhs, d) = operand(rhs, cx);
        let s = acc.span.join(rhs.span);
        let kind = ExprKind::Binary(binop(&op), Box::new(acc), Box::new(rhs));
        (acc, depth) = cx.node(kind, s, depth.max(d) + 1);
        if cx.too_deep.is_some() {
            break;
        }
    }
    (acc, depth)
}

fn expr(p: P, cx: &mut Lower) -> D {
    chain(p, cx, term)
}

fn term(p: P, cx: &mut Lower) -> D {
    chain(p, cx, factor)
}

/// `factor` and `exponent`: an optional `-` before a power or an atom.
fn signed(p: P, cx: &mut Lower, operand: fn(P, &mut Lower) -> D) -> D {
    let sp = span(&p);
    let mut inner = p.into_inner().peekable();
    let negated = inner.peek().is_some_and(|n| n.as_rule() == Rule::neg);
    if negated {
        inner.next();
    }
    let Some(x) = inner.next() else {
        return (zero(sp), 1);
    };
    let (x, d) = operand(x, cx);
    if negated {
        cx.node(ExprKind::Neg(Box::new(x)), sp, d + 1)
    } else {
        (x, d)
    }
}

fn factor(p: P, cx: &mut Lower) -> D {
    signed(p, cx, power)
}

fn power(p: P, cx: &mut Lower) -> D {
    let sp = span(&p);
    let mut inner = p.into_inner();
    let Some(base) = inner.next() else {
        return (zero(sp), 1);
    };
    let (base, db) = atom(base, cx);
    match inner.next() {
        Some(e) => {
            let (e, de) = signed(e, cx, atom);
            let kind = ExprKind::Binary(BinOp::Pow, Box::new(base), Box::new(e));
            cx.node(kind, sp, db.max(de) + 1)
        }
        None => (base, db),
    }
}

fn atom(p: P, cx: &mut Lower) -> D {
    let sp = span(&p);
    match p.as_rule() {
        Rule::number => (node(ExprKind::Number(p.as_str().to_string()), sp), 1),
        Rule::name => (node(ExprKind::Name(p.as_str().to_string()), sp), 1),
        Rule::paren => match p.into_inner().next() {
            Some(e) => {
                let (mut e, d) = expr(e, cx);
                e.span = sp;
                (e, d)
            }
            None => (zero(sp), 1),
        },
        Rule::call => {
            let mut inner = p.into_inner();
            let f = inner.next().map(text).unwrap_or_else(|| Spanned {
                node: String::new(),
                span: sp,
            });
            let mut depth = 1;
            let mut args = Vec::new();
            for a in inner {
                let (a, d) = expr(a, cx);
                depth = depth.max(d + 1);
                args.push(a);
            }
            cx.node(ExprKind::Call(f, args), sp, depth)
        }
        _ => (zero(sp), 1),
    }
}

fn node(kind: ExprKind, span: Span) -> Expr {
    Expr { kind, span }
}
