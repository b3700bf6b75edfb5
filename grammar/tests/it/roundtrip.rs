//! Property tests: formatting preserves meaning (parse(fmt(x)) == parse(x), spans aside)
//! and is idempotent, on procedures built from random statements, random spacing,
//! random `;` separators and random comments.

use proptest::prelude::*;

/// The AST with spans removed (spans print as `@start..end` in Debug).
fn shape(text: &str) -> String {
    let file = ratecal_grammar::parse(text).unwrap_or_else(|e| panic!("{e:?}\n{text}"));
    let dbg = format!("{:?}", file.body.items);
    let mut out = String::with_capacity(dbg.len());
    let mut chars = dbg.chars().peekable();
    while let Some(c) = chars.next() {
        if c == '@' && chars.peek().is_some_and(|d| d.is_ascii_digit()) {
            while chars
                .peek()
                .is_some_and(|d| d.is_ascii_digit() || *d == '.')
            {
                chars.next();
            }
        } else {
            out.push(c);
        }
    }
    out
}

fn num() -> impl Strategy<Value = String> {
    prop_oneof![
        (0u32..400).prop_map(|n| n.to_string()),
        (-400i32..400).prop_map(|n| n.to_string()),
        (0u32..1000, 1u32..999).prop_map(|(a, b)| format!("{a}.{b}")),
    ]
}

fn unit() -> impl Strategy<Value = &'static str> {
    prop::sample::select(vec![
        "deg", "s", "min", "deg/s", "g", "Hz", "arcsec", "%", "degC", "m/s^2",
    ])
}

fn statement() -> impl Strategy<Value = String> {
    prop_oneof![
        (num(), num()).prop_map(|(a, b)| format!("move to pitch {a} deg, roll {b} deg")),
        (num(), unit()).prop_map(|(a, u)| format!("spin outer at {a} {u}")),
        Just("stop".to_string()),
        Just("stop inner".to_string()),
        num().prop_map(|a| format!("hold for {a} s")),
        (num(), num()).prop_map(|(a, b)| format!("settle {{ at least {a} s ; accel fluctuation <= {b} g over 5 s timeout 60 s -> abort }}")),
        (num(), num()).prop_map(|(a, b)| format!("acquire accel, gyro for {a} s at {b} Hz as \"seg/{{n}}\"")),
        num().prop_map(|a| format!("abort when table.attitude_error > {a} arcsec for 1 s")),
        num().prop_map(|a| format!("accept gyro.residual.std <= {a} deg/s")),
        num().prop_map(|a| format!("accept abs( gyro.scale.x ) <= {a} ppm guarded")),
        num().prop_map(|a| format!("accept accel.misalignment.xy within ± {a} mrad")),
        num().prop_map(|a| format!("accept norm(accel.bias) within +-{a} mg")),
        Just("fit accel bias_scale from a/*, b using c { outliers 3 sigma lowpass butterworth order 4 cutoff 10 Hz }".to_string()),
        Just("remount x up \"turn \\\"it\\\"\"".to_string()),
        num().prop_map(|a| format!("oscillate outer amplitude {a} deg period 5 s for 60 s")),
        num().prop_map(|a| format!("place -y up within {a} deg \"on its side\"")),
        Just("place free".to_string()),
        Just("place top up".to_string()),
        num().prop_map(|a| format!("turn about +z by {a} deg as \"turn/{{k}}\"")),
        Just("turn free as \"t\"".to_string()),
    ]
}

fn body(depth: u32) -> BoxedStrategy<Vec<String>> {
    let leaf = prop::collection::vec(statement(), 0..5);
    if depth == 0 {
        return leaf.boxed();
    }
    let nested = (
        prop::collection::vec(statement(), 0..3),
        prop::collection::vec(num(), 1..12),
        body(depth - 1),
        prop::bool::ANY,
    )
        .prop_map(|(mut before, list, inner, rep)| {
            let head = if rep {
                "repeat 3 as i".to_string()
            } else {
                format!("for n in [{}] deg", list.join(", "))
            };
            before.push(format!("{head} {{ {} }}", inner.join("\n")));
            before
        });
    prop_oneof![leaf, nested].boxed()
}

/// Joins tokens of a text with random whitespace, `;` and comments at line ends.
fn scramble(text: &str, seps: &[u8]) -> String {
    let mut out = String::new();
    for (k, line) in text.lines().enumerate() {
        out.push_str(line);
        let s = seps.get(k).copied().unwrap_or(0);
        match s % 6 {
            0 => out.push('\n'),
            1 => out.push_str("\n\n"),
            2 => out.push_str(" # note\n"),
            3 => out.push_str("\n   # a comment on its own line\n"),
            4 => out.push_str(" ;\n\t"),
            _ => out.push_str("\n  \n  "),
        }
    }
    out
}

fn procedure() -> impl Strategy<Value = String> {
    (prop::collection::vec(body(2), 1..4), prop::collection::vec(any::<u8>(), 0..200)).prop_map(|(steps, seps)| {
        let mut text = String::from("# header\nimport \"lab.rcal\"\nparam p = [(1, 2 deg), (3, 4 deg)]\nprocedure p-1 version 1.0.0-rc.1 {\ntitle \"T\"\nrequires table {\nposition_accuracy <= 10 arcsec\n}\nenvironment {\ntemperature 20 degC +- 2 degC\nhumidity 40 % .. 60 %\n}\n");
        for (i, b) in steps.iter().enumerate() {
            text.push_str(&format!("step s{i} \"Step {i}\" {{\n{}\n}}\n", b.join("\n")));
        }
        text.push_str("verify at pitch 45 deg, roll 30 deg from v/a { accel.error <= 0.01 g }\naccept repeatability.cv <= 1 % over 3 runs\n}\n# end\n");
        scramble(&text, &seps)
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    #[test]
    fn format_preserves_meaning_and_is_idempotent(text in procedure()) {
        let once = ratecal_grammar::format(&ratecal_grammar::parse(&text).unwrap_or_else(|e| panic!("{e:?}\n{text}")));
        prop_assert_eq!(shape(&once), shape(&text), "meaning changed:\n{}\n---\n{}", text, once);
        let twice = ratecal_grammar::format(&ratecal_grammar::parse(&once).expect("formatted text parses"));
        prop_assert_eq!(&twice, &once);
    }
}

#[test]
fn comments_are_kept_where_they_belong() {
    let text = "# top\nprocedure p version 1.0.0 { # after brace\n  step s {\n    hold for 1 s # trailing\n    # before stop\n    stop\n    # end of step\n  }\n}\n";
    let out = ratecal_grammar::format(&ratecal_grammar::parse(text).unwrap());
    assert_eq!(
        out,
        "# top\nprocedure p version 1.0.0 {\n  # after brace\n  step s {\n    hold for 1 s # trailing\n    # before stop\n    stop\n    # end of step\n  }\n}\n"
    );
}
