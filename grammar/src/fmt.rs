//! The canonical layout: two-space indentation, one entry per line, blocks always open on
//! the entry's line and close on their own, numbers and units as written, comments kept,
//! at most one blank line where the author left one. Long lists go one element per line.

use crate::ast::*;

const INDENT: &str = "  ";
/// Lists longer than this (rendered inline) are written one element per line.
const LIST_WIDTH: usize = 72;

/// Renders a file in canonical layout.
pub fn format_file(file: &File) -> String {
    let mut w = Writer {
        out: String::new(),
        depth: 0,
    };
    w.block_items(&file.body, top_item);
    w.out
}

/// Renders one abort rule canonically (journals, reports, plans).
pub fn format_abort(a: &Abort) -> String {
    abort(a)
}

/// Renders one value canonically.
pub fn format_value(v: &Value) -> String {
    value(v, 0)
}

struct Writer {
    out: String,
    depth: usize,
}

impl Writer {
    /// Writes a line (or several: every line of `s` gets the current indentation).
    fn line(&mut self, s: &str) {
        for l in s.split('\n') {
            for _ in 0..self.depth {
                self.out.push_str(INDENT);
            }
            self.out.push_str(l);
            self.out.push('\n');
        }
    }

    fn comment(&mut self, c: &Comment) {
        self.line(&format!("#{}", c.text));
    }

    /// Writes the entries of a block; `f` renders one entry and returns its text, which
    /// may span lines (nested blocks are rendered by `f` through `self`).
    fn block_items<T>(&mut self, b: &Block<T>, f: fn(&mut Writer, &T)) {
        for (k, item) in b.items.iter().enumerate() {
            if k > 0 && item.blank_before {
                self.out.push('\n');
            }
            for c in &item.comments {
                self.comment(c);
            }
            f(self, &item.node);
            if let Some(t) = &item.trailing {
                // The entry's last line is the one just written: put the comment there.
                self.out.pop();
                self.out.push_str(&format!(" #{}\n", t.text));
            }
        }
        for c in &b.end_comments {
            self.comment(c);
        }
    }

    fn braced<T>(&mut self, head: &str, b: &Block<T>, f: fn(&mut Writer, &T)) {
        self.line(&format!("{head} {{"));
        self.depth += 1;
        self.block_items(b, f);
        self.depth -= 1;
        self.line("}");
    }
}

fn top_item(w: &mut Writer, t: &TopItem) {
    match t {
        TopItem::Import(s) => w.line(&format!("import {}", string(&s.node))),
        TopItem::Param(p) => w.line(&param(p)),
        TopItem::Procedure(p) => {
            let head = format!("procedure {} version {}", p.name.node, p.version.node);
            w.braced(&head, &p.body, proc_item);
        }
    }
}

fn param(p: &Param) -> String {
    format!("param {} = {}", p.name.node, value(&p.value, 0))
}

fn proc_item(w: &mut Writer, p: &ProcItem) {
    match p {
        ProcItem::Title(s) => w.line(&format!("title {}", string(&s.node))),
        ProcItem::ImuClass(c) => w.line(&format!("imu class {}", c.node)),
        ProcItem::Reference(s) => w.line(&format!("reference {}", string(&s.node))),
        ProcItem::Meta(k, v) => w.line(&format!("meta {} {}", k.node, string(&v.node))),
        ProcItem::Geometry(g) => w.line(&format!("geometry {}", g.node)),
        ProcItem::Param(p) => w.line(&param(p)),
        ProcItem::Requires { subject, body } => {
            w.braced(&format!("requires {}", subject.node), body, |w, l| {
                w.line(&limit(l))
            })
        }
        ProcItem::Environment(b) => w.braced("environment", b, env_item),
        ProcItem::Abort(a) => w.line(&abort(a)),
        ProcItem::Step(s) => step(w, s),
        ProcItem::Accept(a) => w.line(&accept(a)),
        ProcItem::Verify(v) => verify(w, v),
    }
}

fn limit(l: &Limit) -> String {
    format!(
        "{} {} {}",
        l.name.node,
        l.op.node.as_str(),
        value(&l.value, 0)
    )
}

fn env_item(w: &mut Writer, e: &EnvItem) {
    let bound = match &e.bound {
        EnvBound::Cmp(op, v) => format!("{} {}", op.node.as_str(), value(v, 0)),
        EnvBound::Tol(a, b) => format!("{} +- {}", value(a, 0), value(b, 0)),
        EnvBound::Range(a, b) => format!("{} .. {}", value(a, 0), value(b, 0)),
    };
    w.line(&format!("{} {}", e.name.node, bound));
}

fn abort(a: &Abort) -> String {
    let cond = match &a.cond {
        Cond::Cmp(s, op, v) => format!("{} {} {}", s.node, op.node.as_str(), value(v, 0)),
        Cond::Outside(s, lo, hi) => {
            format!("{} outside {} .. {}", s.node, value(lo, 0), value(hi, 0))
        }
        Cond::Drifts(s, op, v) => format!("{} drifts {} {}", s.node, op.node.as_str(), value(v, 0)),
        Cond::Abnormal(s) => format!("{} abnormal", s.node),
    };
    let mut out = format!("abort when {cond}");
    if let Some(p) = &a.persist {
        out.push_str(&format!(" for {}", value(p, 0)));
    }
    if let Some(act) = &a.action {
        out.push_str(&format!(" -> {}", act.node));
    }
    out
}

fn accept(a: &Accept) -> String {
    let mut out = match &a.bound {
        AcceptBound::Cmp(op, v) => format!(
            "accept {} {} {}",
            a.checked.text(),
            op.node.as_str(),
            value(v, 0)
        ),
        AcceptBound::Within(v) => format!("accept {} within +-{}", a.checked.text(), value(v, 0)),
    };
    if let Some(n) = &a.runs {
        out.push_str(&format!(" over {} runs", n.node));
    }
    if a.guarded {
        out.push_str(" guarded");
    }
    out
}

fn angles(a: &[Angle]) -> String {
    a.iter()
        .map(|a| format!("{} {}", a.axis.node, value(&a.value, 0)))
        .collect::<Vec<_>>()
        .join(", ")
}

fn verify(w: &mut Writer, v: &Verify) {
    let point = match &v.point {
        VerifyPoint::Attitude(a) => angles(a),
        VerifyPoint::Rate { axis, rate } => format!("{} rate {}", value(axis, 0), value(rate, 0)),
    };
    let mut head = format!("verify at {point}");
    if !v.from.is_empty() {
        let pats: Vec<&str> = v.from.iter().map(|p| p.node.as_str()).collect();
        head.push_str(&format!(" from {}", pats.join(", ")));
    }
    w.braced(&head, &v.limits, |w, l| w.line(&limit(l)));
}

fn step(w: &mut Writer, s: &Step) {
    let mut head = format!("step {}", s.name.node);
    if let Some(t) = &s.title {
        head.push_str(&format!(" {}", string(&t.node)));
    }
    w.braced(&head, &s.body, stmt);
}

fn stmt(w: &mut Writer, s: &Stmt) {
    match s {
        Stmt::Move(a) => w.line(&format!("move to {}", angles(a))),
        Stmt::Spin { axis, rate } => {
            w.line(&format!("spin {} at {}", value(axis, 0), value(rate, 0)))
        }
        Stmt::Stop(None) => w.line("stop"),
        Stmt::Stop(Some(a)) => w.line(&format!("stop {}", value(a, 0))),
        Stmt::Oscillate {
            axis,
            amplitude,
            period,
            center,
            duration,
        } => {
            let mut l = format!(
                "oscillate {} amplitude {} period {}",
                value(axis, 0),
                value(amplitude, 0),
                value(period, 0)
            );
            if let Some(c) = center {
                l.push_str(&format!(" center {}", value(c, 0)));
            }
            l.push_str(&format!(" for {}", value(duration, 0)));
            w.line(&l);
        }
        Stmt::Hold(v) => w.line(&format!("hold for {}", value(v, 0))),
        Stmt::SettleFor(v) => w.line(&format!("settle for {}", value(v, 0))),
        Stmt::Settle(b) => w.braced("settle", b, settle_item),
        Stmt::Acquire {
            channels,
            duration,
            rate,
            segment,
        } => {
            let ch: Vec<&str> = channels.iter().map(|c| c.node.as_str()).collect();
            w.line(&format!(
                "acquire {} for {} at {} as {}",
                ch.join(", "),
                value(duration, 0),
                value(rate, 0),
                string(&segment.node)
            ));
        }
        Stmt::For {
            vars,
            tuple,
            list,
            body,
        } => {
            let names: Vec<&str> = vars.iter().map(|v| v.node.as_str()).collect();
            let vars = if *tuple || names.len() != 1 {
                format!("({})", names.join(", "))
            } else {
                names[0].to_string()
            };
            let head = format!("for {vars} in {}", value(list, 0));
            w.braced(&head, body, stmt);
        }
        Stmt::Repeat { count, var, body } => {
            let mut head = format!("repeat {}", value(count, 0));
            if let Some(v) = var {
                head.push_str(&format!(" as {}", v.node));
            }
            w.braced(&head, body, stmt);
        }
        Stmt::Fit(f) => fit(w, f),
        Stmt::Accept(a) => w.line(&accept(a)),
        Stmt::Verify(v) => verify(w, v),
        Stmt::Abort(a) => w.line(&abort(a)),
        Stmt::Remount { axis, message } => {
            let mut l = format!("remount {} up", axis.node);
            if let Some(m) = message {
                l.push_str(&format!(" {}", string(&m.node)));
            }
            w.line(&l);
        }
        Stmt::Place {
            face,
            within,
            message,
        } => {
            let mut l = match face {
                Some(f) => format!("place {} up", f.node),
                None => "place free".to_string(),
            };
            if let Some(v) = within {
                l.push_str(&format!(" within {}", value(v, 0)));
            }
            if let Some(m) = message {
                l.push_str(&format!(" {}", string(&m.node)));
            }
            w.line(&l);
        }
        Stmt::Turn { about, segment } => {
            let what = match about {
                Some((f, a)) => format!("about {} by {}", f.node, value(a, 0)),
                None => "free".to_string(),
            };
            w.line(&format!("turn {what} as {}", string(&segment.node)));
        }
    }
}

fn settle_item(w: &mut Writer, s: &SettleItem) {
    let l = match s {
        SettleItem::AtLeast(v) => format!("at least {}", value(v, 0)),
        SettleItem::Timeout(v, None) => format!("timeout {}", value(v, 0)),
        SettleItem::Timeout(v, Some(a)) => format!("timeout {} -> {}", value(v, 0), a.node),
        SettleItem::Fluctuation {
            signal,
            op,
            value: v,
            window,
        } => format!(
            "{} fluctuation {} {} over {}",
            signal.node,
            op.node.as_str(),
            value(v, 0),
            value(window, 0)
        ),
        SettleItem::Limit(l) => limit(l),
    };
    w.line(&l);
}

fn fit(w: &mut Writer, f: &Fit) {
    let mut head = format!("fit {}", f.sensor.node);
    if let Some(m) = &f.model {
        head.push_str(&format!(" {}", m.node));
    }
    if let Some(axes) = &f.axes {
        let a: Vec<&str> = axes.iter().map(|a| a.node.as_str()).collect();
        head.push_str(&format!(" ({})", a.join(", ")));
    }
    if !f.with.is_empty() {
        let w: Vec<&str> = f.with.iter().map(|e| e.node.as_str()).collect();
        head.push_str(&format!(" with {}", w.join(", ")));
    }
    let pats: Vec<&str> = f.from.iter().map(|p| p.node.as_str()).collect();
    head.push_str(&format!(" from {}", pats.join(", ")));
    if let Some(u) = &f.using {
        head.push_str(&format!(" using {}", u.node));
    }
    match &f.options {
        Some(b) => w.braced(&head, b, fit_opt),
        None => w.line(&head),
    }
}

fn fit_opt(w: &mut Writer, o: &FitOpt) {
    let l = match o {
        FitOpt::Sigma(n) => format!("outliers {} sigma", n.node),
        FitOpt::Grubbs(None) => "outliers grubbs".to_string(),
        FitOpt::Grubbs(Some(a)) => format!("outliers grubbs alpha {}", a.node),
        FitOpt::Lowpass { order, cutoff } => {
            format!(
                "lowpass butterworth order {} cutoff {}",
                order.node,
                value(cutoff, 0)
            )
        }
    };
    w.line(&l);
}

fn string(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\t' => out.push_str("\\t"),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// Renders a value; `depth` is the indentation of the line it starts on (for long lists).
fn value(v: &Value, depth: usize) -> String {
    match &v.kind {
        ValueKind::Quantity {
            number,
            unit: Some(u),
        } => format!("{number} {}", u.node),
        ValueKind::Quantity { number, unit: None } => number.clone(),
        ValueKind::Str(s) => string(s),
        ValueKind::Name(n) => n.clone(),
        ValueKind::Tuple(items) => {
            let parts: Vec<String> = items.iter().map(|i| value(i, 0)).collect();
            format!("({})", parts.join(", "))
        }
        ValueKind::List { items, unit } => {
            let parts: Vec<String> = items.iter().map(|i| value(i, depth + 1)).collect();
            let unit = unit
                .as_ref()
                .map(|u| format!(" {}", u.node))
                .unwrap_or_default();
            let inline = format!("[{}]", parts.join(", "));
            if inline.len() <= LIST_WIDTH {
                return format!("{inline}{unit}");
            }
            let pad = INDENT.repeat(depth + 1);
            let close = INDENT.repeat(depth);
            let body: Vec<String> = parts.iter().map(|p| format!("{pad}{p},")).collect();
            format!("[\n{}\n{close}]{unit}", body.join("\n"))
        }
    }
}
