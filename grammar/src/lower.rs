//! The only file that sees pest: parses text with the grammar and lowers the pairs to the
//! AST, or turns pest's error into a diagnostic saying what was expected.

use crate::ast::*;
use crate::diag::Diagnostic;
use crate::syntax::{self, Language};
use pest::Parser;
use pest::iterators::Pair;

#[derive(pest_derive::Parser)]
#[grammar = "procedure.pest"]
struct Grammar;

type P<'a> = Pair<'a, Rule>;

/// Parses a file (without attaching comments).
pub(crate) fn parse_file(text: &str) -> Result<File, Diagnostic> {
    let mut pairs =
        Grammar::parse(Rule::file, text).map_err(|e| syntax::error(e, text, &SYNTAX))?;
    let file = pairs
        .next()
        .ok_or_else(|| Diagnostic::error("syntax::empty", "empty parse"))?;
    let span = Span::new(0, text.len());
    let items = file
        .into_inner()
        .filter(|p| p.as_rule() == Rule::top_item)
        .map(|p| item(p, top_item))
        .collect();
    Ok(File {
        body: Block {
            items,
            end_comments: Vec::new(),
            span,
        },
    })
}

/// How this language words its syntax errors.
const SYNTAX: Language<Rule> = Language {
    code: "syntax::unexpected",
    help: "see docs/language.md for the form of each statement",
    rule_name,
    keyword,
};

/// The keyword that `rest` begins with, if any.
fn keyword(rest: &str) -> Option<&str> {
    let mut kw = Grammar::parse(Rule::reserved, rest).ok()?;
    kw.next().map(|kw| kw.as_str())
}

fn rule_name(r: Rule) -> Option<&'static str> {
    Some(match r {
        Rule::EOI => "end of file",
        Rule::ident | Rule::raw_ident => "a name",
        Rule::path => "a signal or quantity name",
        Rule::proc_name => "a procedure name",
        Rule::semver => "a version (1.0.0)",
        Rule::pattern => "a segment pattern",
        Rule::string | Rule::str_inner => "a quoted string",
        Rule::number | Rule::integer => "a number",
        Rule::unit => "a unit",
        Rule::quantity | Rule::value => "a value",
        Rule::list => "a list",
        Rule::tuple => "a tuple",
        Rule::cmp => "a comparison (<=, <, >=, >)",
        Rule::top_item => "`import`, `param` or `procedure`",
        Rule::proc_item => "a procedure entry (title, requires, step, accept, ...)",
        Rule::stmt => "a statement (move, spin, settle, acquire, for, fit, ...)",
        Rule::settle_item => "a settle condition",
        Rule::limit => "a limit (name <= value)",
        Rule::checked | Rule::call => "a quantity (`accel.bias.x`, `abs(gyro.scale.x)`)",
        Rule::within => "`within +-` and a value",
        Rule::accept_cmp => "a comparison (<=, <, >=, >)",
        Rule::env_item => "an environment condition",
        Rule::fit_opt => "a preprocessing option (outliers, lowpass)",
        Rule::condition => "a condition",
        Rule::block | Rule::settle_block | Rule::fit_block => "`{`",
        _ => return None,
    })
}

fn span(p: &P) -> Span {
    let s = p.as_span();
    Span::new(s.start(), s.end())
}

fn item<T>(p: P, f: fn(P) -> T) -> Item<T> {
    let sp = span(&p);
    Item {
        node: f(p),
        span: sp,
        comments: Vec::new(),
        trailing: None,
        blank_before: false,
    }
}

fn text(p: P) -> Spanned<String> {
    Spanned {
        span: span(&p),
        node: p.as_str().to_string(),
    }
}

fn string(p: P) -> Spanned<String> {
    let sp = span(&p);
    let raw = p.into_inner().next().map(|i| i.as_str()).unwrap_or("");
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

fn block<T>(p: P, want: Rule, f: fn(P) -> T) -> Block<T> {
    let sp = span(&p);
    let items = p
        .into_inner()
        .filter(|c| c.as_rule() == want)
        .map(|c| item(c, f))
        .collect();
    Block {
        items,
        end_comments: Vec::new(),
        span: sp,
    }
}

fn top_item(p: P) -> TopItem {
    let inner = first(p);
    match inner.as_rule() {
        Rule::import => TopItem::Import(string(first(inner))),
        Rule::param => TopItem::Param(param(inner)),
        _ => TopItem::Procedure(procedure(inner)),
    }
}

fn first(p: P) -> P {
    // The grammar guarantees at least one child wherever this is called.
    p.into_inner().next().expect("grammar guarantees a child")
}

fn param(p: P) -> Param {
    let mut it = p.into_inner();
    let name = text(it.next().expect("param name"));
    let value = value(it.next().expect("param value"));
    Param { name, value }
}

fn procedure(p: P) -> Procedure {
    let sp = span(&p);
    let mut it = p.into_inner();
    let name = text(it.next().expect("procedure name"));
    let version = text(it.next().expect("procedure version"));
    let items = it.map(|c| item(c, proc_item)).collect();
    Procedure {
        name,
        version,
        body: Block {
            items,
            end_comments: Vec::new(),
            span: sp,
        },
    }
}

fn proc_item(p: P) -> ProcItem {
    let inner = first(p);
    match inner.as_rule() {
        Rule::title => ProcItem::Title(string(first(inner))),
        Rule::imu_class => ProcItem::ImuClass(text(first(inner))),
        Rule::reference => ProcItem::Reference(string(first(inner))),
        Rule::meta => {
            let mut it = inner.into_inner();
            let k = text(it.next().expect("meta key"));
            ProcItem::Meta(k, string(it.next().expect("meta value")))
        }
        Rule::geometry => ProcItem::Geometry(text(first(inner))),
        Rule::param => ProcItem::Param(param(inner)),
        Rule::requires => {
            let sp = span(&inner);
            let mut it = inner.into_inner();
            let subject = text(it.next().expect("requires subject"));
            let items = it.map(|c| item(c, limit)).collect();
            ProcItem::Requires {
                subject,
                body: Block {
                    items,
                    end_comments: Vec::new(),
                    span: sp,
                },
            }
        }
        Rule::environment => ProcItem::Environment(block(inner, Rule::env_item, env_item)),
        Rule::abort => ProcItem::Abort(abort(inner)),
        Rule::step => ProcItem::Step(step(inner)),
        Rule::accept => ProcItem::Accept(accept(inner)),
        _ => ProcItem::Verify(verify(inner)),
    }
}

fn cmp(p: P) -> Spanned<Cmp> {
    let node = match p.as_str() {
        "<=" => Cmp::Le,
        "<" => Cmp::Lt,
        ">=" => Cmp::Ge,
        _ => Cmp::Gt,
    };
    Spanned {
        node,
        span: span(&p),
    }
}

fn limit(p: P) -> Limit {
    let mut it = p.into_inner();
    let name = text(it.next().expect("limit name"));
    let op = cmp(it.next().expect("limit op"));
    let value = value(it.next().expect("limit value"));
    Limit { name, op, value }
}

fn env_item(p: P) -> EnvItem {
    let mut it = p.into_inner();
    let name = text(it.next().expect("env name"));
    let b = it.next().expect("env bound");
    let rule = b.as_rule();
    let mut bi = b.into_inner();
    let mut next = || bi.next().expect("env part");
    let bound = match rule {
        Rule::env_cmp => EnvBound::Cmp(cmp(next()), value(next())),
        Rule::env_tol => EnvBound::Tol(value(next()), value(next())),
        _ => EnvBound::Range(value(next()), value(next())),
    };
    EnvItem { name, bound }
}

fn abort(p: P) -> Abort {
    abort_from(p.into_inner())
}

fn accept(p: P) -> Accept {
    accept_from(p.into_inner())
}

fn verify(p: P) -> Verify {
    let sp = span(&p);
    verify_from(p.into_inner(), sp)
}

fn angles(p: P) -> Vec<Angle> {
    p.into_inner()
        .map(|a| {
            let mut ai = a.into_inner();
            let axis = text(ai.next().expect("angle axis"));
            Angle {
                axis,
                value: value(ai.next().expect("angle value")),
            }
        })
        .collect()
}

fn step(p: P) -> Step {
    let mut it = p.into_inner();
    let name = text(it.next().expect("step name"));
    let mut title = None;
    let mut body = None;
    for c in it {
        match c.as_rule() {
            Rule::string => title = Some(string(c)),
            _ => body = Some(block(c, Rule::stmt, stmt)),
        }
    }
    let body = body.expect("step block");
    Step { name, title, body }
}

fn stmt(p: P) -> Stmt {
    let inner = first(p);
    let rule = inner.as_rule();
    let sp = span(&inner);
    let mut it = inner.into_inner();
    let mut next = || it.next().expect("statement part");
    match rule {
        Rule::move_to => Stmt::Move(angles(next())),
        Rule::spin => Stmt::Spin {
            axis: value(next()),
            rate: value(next()),
        },
        Rule::stop => Stmt::Stop(it.next().map(value)),
        Rule::oscillate => {
            let axis = value(next());
            let amplitude = value(next());
            let period = value(next());
            let rest: Vec<Value> = it.map(value).collect();
            let (center, duration) = match rest.len() {
                2 => (Some(rest[0].clone()), rest[1].clone()),
                _ => (None, rest[0].clone()),
            };
            Stmt::Oscillate {
                axis,
                amplitude,
                period,
                center,
                duration,
            }
        }
        Rule::hold => Stmt::Hold(value(next())),
        Rule::settle => {
            let c = next();
            match c.as_rule() {
                Rule::settle_for => Stmt::SettleFor(value(first(c))),
                _ => Stmt::Settle(block(c, Rule::settle_item, settle_item)),
            }
        }
        Rule::acquire => {
            let mut parts: Vec<P> = it.collect();
            let segment = string(parts.pop().expect("segment"));
            let rate = value(parts.pop().expect("rate"));
            let duration = value(parts.pop().expect("duration"));
            Stmt::Acquire {
                channels: parts.into_iter().map(text).collect(),
                duration,
                rate,
                segment,
            }
        }
        Rule::for_loop => {
            let vars_p = next();
            let tuple = vars_p.as_str().trim_start().starts_with('(');
            let vars = vars_p.into_inner().map(text).collect();
            let list = value(next());
            let body = block(next(), Rule::stmt, stmt);
            Stmt::For {
                vars,
                tuple,
                list,
                body,
            }
        }
        Rule::repeat => {
            let count = value(next());
            let mut var = None;
            let mut body = None;
            for c in it {
                match c.as_rule() {
                    Rule::ident => var = Some(text(c)),
                    _ => body = Some(block(c, Rule::stmt, stmt)),
                }
            }
            Stmt::Repeat {
                count,
                var,
                body: body.expect("repeat block"),
            }
        }
        Rule::fit => Stmt::Fit(fit(it, sp)),
        Rule::accept => Stmt::Accept(accept_from(it)),
        Rule::verify => Stmt::Verify(verify_from(it, sp)),
        Rule::abort => Stmt::Abort(abort_from(it)),
        Rule::place => place(it),
        Rule::turn => turn(it),
        _ => {
            let axis = text(next());
            Stmt::Remount {
                axis,
                message: it.next().map(string),
            }
        }
    }
}

fn place(mut it: pest::iterators::Pairs<Rule>) -> Stmt {
    let what = it.next().expect("place pose");
    let message = it.next().map(string);
    if what.as_rule() == Rule::free {
        return Stmt::Place {
            face: None,
            within: None,
            message,
        };
    }
    let mut parts = what.into_inner();
    let face = text(parts.next().expect("place face"));
    let within = parts.next().map(value);
    Stmt::Place {
        face: Some(face),
        within,
        message,
    }
}

fn turn(mut it: pest::iterators::Pairs<Rule>) -> Stmt {
    let what = it.next().expect("turn motion");
    let segment = string(it.next().expect("turn segment"));
    let about = (what.as_rule() == Rule::turn_about).then(|| {
        let mut parts = what.into_inner();
        let face = text(parts.next().expect("turn axis"));
        (face, value(parts.next().expect("turn angle")))
    });
    Stmt::Turn { about, segment }
}

// accept/verify/abort appear both in a procedure and in a step; both lower from the
// children of the rule.
fn accept_from(it: pest::iterators::Pairs<Rule>) -> Accept {
    let mut it = it;
    let checked = checked(it.next().expect("accept quantity"));
    let b = it.next().expect("accept bound");
    let rule = b.as_rule();
    let mut bi = b.into_inner();
    let bound = match rule {
        Rule::within => AcceptBound::Within(value(bi.next().expect("within value"))),
        _ => AcceptBound::Cmp(
            cmp(bi.next().expect("accept op")),
            value(bi.next().expect("accept value")),
        ),
    };
    let mut runs = None;
    let mut guarded = false;
    for c in it {
        match c.as_rule() {
            Rule::over_runs => runs = Some(text(first(c))),
            _ => guarded = true,
        }
    }
    Accept {
        checked,
        bound,
        runs,
        guarded,
    }
}

fn checked(p: P) -> Checked {
    let span = span(&p);
    let inner = first(p);
    match inner.as_rule() {
        Rule::call => {
            let mut ci = inner.into_inner();
            let func = text(ci.next().expect("call name"));
            let name = text(ci.next().expect("call argument"));
            Checked {
                func: Some(func),
                name,
                span,
            }
        }
        _ => Checked {
            func: None,
            name: text(inner),
            span,
        },
    }
}

fn verify_from(it: pest::iterators::Pairs<Rule>, sp: Span) -> Verify {
    let mut it = it;
    let point = first(it.next().expect("verify point"));
    let point = match point.as_rule() {
        Rule::rate_point => {
            let mut pi = point.into_inner();
            let axis = value(pi.next().expect("axis"));
            VerifyPoint::Rate {
                axis,
                rate: value(pi.next().expect("rate")),
            }
        }
        _ => VerifyPoint::Attitude(angles(point)),
    };
    let mut from = Vec::new();
    let mut items = Vec::new();
    for c in it {
        match c.as_rule() {
            Rule::from_list => from = c.into_inner().map(text).collect(),
            _ => items.push(item(c, limit)),
        }
    }
    Verify {
        point,
        from,
        limits: Block {
            items,
            end_comments: Vec::new(),
            span: sp,
        },
    }
}

fn abort_from(it: pest::iterators::Pairs<Rule>) -> Abort {
    let mut it = it;
    let c = first(it.next().expect("abort condition"));
    let rule = c.as_rule();
    let mut ci = c.into_inner();
    let mut next = || ci.next().expect("condition part");
    let cond = match rule {
        Rule::cond_outside => Cond::Outside(text(next()), value(next()), value(next())),
        Rule::cond_drifts => Cond::Drifts(text(next()), cmp(next()), value(next())),
        Rule::cond_abnormal => Cond::Abnormal(text(next())),
        _ => Cond::Cmp(text(next()), cmp(next()), value(next())),
    };
    let mut persist = None;
    let mut action = None;
    for c in it {
        match c.as_rule() {
            Rule::quantity => persist = Some(value(c)),
            _ => action = Some(text(first(c))),
        }
    }
    Abort {
        cond,
        persist,
        action,
    }
}

fn settle_item(p: P) -> SettleItem {
    let inner = first(p);
    let rule = inner.as_rule();
    if rule == Rule::limit {
        return SettleItem::Limit(limit(inner));
    }
    let mut it = inner.into_inner();
    let mut next = || it.next().expect("settle part");
    match rule {
        Rule::at_least => SettleItem::AtLeast(value(next())),
        Rule::timeout => {
            let v = value(next());
            SettleItem::Timeout(v, it.next().map(|a| text(first(a))))
        }
        _ => SettleItem::Fluctuation {
            signal: text(next()),
            op: cmp(next()),
            value: value(next()),
            window: value(next()),
        },
    }
}

fn fit(it: pest::iterators::Pairs<Rule>, _sp: Span) -> Fit {
    let mut sensor = None;
    let mut model = None;
    let mut axes = None;
    let mut with = Vec::new();
    let mut from = Vec::new();
    let mut using = None;
    let mut options = None;
    for c in it {
        match c.as_rule() {
            Rule::ident if sensor.is_none() => sensor = Some(text(c)),
            Rule::ident => model = Some(text(c)),
            Rule::fit_axes => axes = Some(c.into_inner().map(text).collect()),
            Rule::fit_with => with = c.into_inner().map(text).collect(),
            Rule::from_list => from = c.into_inner().map(text).collect(),
            Rule::pattern => using = Some(text(c)),
            _ => options = Some(block(c, Rule::fit_opt, fit_opt)),
        }
    }
    Fit {
        sensor: sensor.expect("fit sensor"),
        model,
        axes,
        with,
        from,
        using,
        options,
    }
}

fn fit_opt(p: P) -> FitOpt {
    let inner = first(p);
    let rule = inner.as_rule();
    let mut it = inner.into_inner();
    match rule {
        Rule::outliers_sigma => FitOpt::Sigma(text(it.next().expect("sigma"))),
        Rule::outliers_grubbs => FitOpt::Grubbs(it.next().map(text)),
        _ => {
            let order = text(it.next().expect("order"));
            FitOpt::Lowpass {
                order,
                cutoff: value(it.next().expect("cutoff")),
            }
        }
    }
}

fn value(p: P) -> Value {
    let inner = if p.as_rule() == Rule::value {
        first(p)
    } else {
        p
    };
    let sp = span(&inner);
    let kind = match inner.as_rule() {
        Rule::quantity => {
            let mut it = inner.into_inner();
            let number = it.next().expect("number").as_str().to_string();
            ValueKind::Quantity {
                number,
                unit: it.next().map(text),
            }
        }
        Rule::string => ValueKind::Str(string(inner).node),
        Rule::list => {
            let mut items = Vec::new();
            let mut unit = None;
            for c in inner.into_inner() {
                match c.as_rule() {
                    Rule::unit => unit = Some(text(c)),
                    _ => items.push(value(c)),
                }
            }
            ValueKind::List { items, unit }
        }
        Rule::tuple => ValueKind::Tuple(inner.into_inner().map(value).collect()),
        _ => ValueKind::Name(inner.as_str().to_string()),
    };
    Value { kind, span: sp }
}
