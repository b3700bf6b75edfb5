use super::*;

/// The expression as a fully parenthesised string, for checking precedence.
fn show(e: &Expr) -> String {
    match &e.kind {
        ExprKind::Number(n) => n.clone(),
        ExprKind::Name(n) => n.clone(),
        ExprKind::Neg(a) => format!("(-{})", show(a)),
        ExprKind::Binary(op, a, b) => {
            let o = match op {
                BinOp::Add => "+",
                BinOp::Sub => "-",
                BinOp::Mul => "*",
                BinOp::Div => "/",
                BinOp::Pow => "^",
            };
            format!("({} {o} {})", show(a), show(b))
        }
        ExprKind::Call(f, args) => {
            let a: Vec<String> = args.iter().map(show).collect();
            format!("{}({})", f.node, a.join(", "))
        }
    }
}

fn one(expr: &str) -> String {
    let text = format!("effect e {{ ax += {expr} }}");
    let f = parse(&text).unwrap_or_else(|d| panic!("{d:?}"));
    match &f.effects[0].items[0] {
        EffectItem::Contribution(c) => show(&c.expr),
        other => panic!("{other:?}"),
    }
}

#[test]
fn precedence_and_associativity() {
    assert_eq!(one("a - b - c"), "((a - b) - c)");
    assert_eq!(one("a / b * c"), "((a / b) * c)");
    assert_eq!(one("a + b * c ^ 2"), "(a + (b * (c ^ 2)))");
    assert_eq!(one("-x^2"), "(-(x ^ 2))");
    assert_eq!(one("2 * -w_b.x"), "(2 * (-w_b.x))");
    assert_eq!(one("x^-1"), "(x ^ (-1))");
    assert_eq!(
        one("(a + b) * sin(t_s / 60, 2)"),
        "((a + b) * sin((t_s / 60), 2))"
    );
    assert_eq!(one("1.5e-3 * .5 * 2."), "((1.5e-3 * .5) * 2.)");
}

#[test]
fn items_keep_their_spans() {
    let text = "# lab effect\neffect k2 {\n  explanation \"a \\\"quoted\\\" word\"\n  param kx unit \"ug/g^2\" needs \"gravity along X\"\n  ax += kx * f_b.x^2\n}\n";
    let f = parse(text).unwrap();
    let e = &f.effects[0];
    assert_eq!(&text[e.name.span.start..e.name.span.end], "k2");
    assert_eq!(e.items.len(), 3);
    let EffectItem::Explanation(x) = &e.items[0] else {
        panic!()
    };
    assert_eq!(x.node, "a \"quoted\" word");
    let EffectItem::Param(p) = &e.items[1] else {
        panic!()
    };
    assert_eq!(
        (p.name.node.as_str(), p.unit.node.as_str()),
        ("kx", "ug/g^2")
    );
    assert_eq!(
        p.needs.as_ref().map(|n| n.node.as_str()),
        Some("gravity along X")
    );
    let EffectItem::Contribution(c) = &e.items[2] else {
        panic!()
    };
    assert_eq!(&text[c.expr.span.start..c.expr.span.end], "kx * f_b.x^2");
}

#[test]
fn syntax_errors_point_at_the_place() {
    let text = "effect e {\n  ax += 2 * * x\n}\n";
    let d = parse(text).unwrap_err();
    assert_eq!(d.code, "effect::syntax");
    assert_eq!(d.labels[0].0.start, text.find("* x").unwrap());
    let d = parse("effect param { }").unwrap_err();
    assert!(d.help.unwrap().contains("`param` is a keyword"));
}

#[test]
fn deep_nesting_is_refused_before_parsing() {
    let deep = format!(
        "effect e {{ ax += {}p{} }}",
        "(".repeat(5000),
        ")".repeat(5000)
    );
    let d = parse(&deep).unwrap_err();
    assert_eq!(d.code, "effect::too_deep");
    // Parentheses in strings and comments do not count.
    let fine = format!(
        "# {}\neffect e {{ explanation \"{}\" ax += ((p)) }}",
        "(".repeat(100),
        "(".repeat(100)
    );
    assert!(parse(&fine).is_ok());
}
