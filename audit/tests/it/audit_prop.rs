//! Property: a procedure and its own formatted text (and any re-layout of it) have no
//! semantic difference.

use proptest::prelude::*;
use ratecal_audit as audit;
use ratecal_check::{CheckOptions, NoImports, check_text};
use ratecal_plan::Plan;

fn plan(text: &str) -> Plan {
    match check_text("p.rcal", text, &NoImports, &CheckOptions::default()) {
        Ok(c) => c.plan,
        Err(d) => panic!(
            "does not check: {}\n{text}",
            d.iter().map(|d| d.render()).collect::<String>()
        ),
    }
}

fn base() -> String {
    std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../procedures/imu-2d-standard/1.0.0.rcal"
    ))
    .unwrap()
}

/// Re-lays a procedure out line by line: indentation, blank lines, trailing spaces and
/// comments. Strings never span lines in the language, so every line end is a token end.
fn relayout(text: &str, choices: &[(u8, u8, u8)]) -> String {
    let mut out = String::new();
    for (line, (indent, blank, comment)) in text.lines().zip(choices.iter().cycle()) {
        let body = line.trim_start();
        if *blank % 4 == 0 {
            out.push('\n');
        }
        out.push_str(&" ".repeat(*indent as usize % 7));
        out.push_str(body);
        if *comment % 5 == 0 && !body.is_empty() {
            out.push_str("   # note");
        } else if *comment % 5 == 1 {
            out.push_str("  ");
        }
        out.push('\n');
    }
    out
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    #[test]
    fn diff_with_own_formatted_text_is_empty(
        choices in prop::collection::vec((any::<u8>(), any::<u8>(), any::<u8>()), 1..40),
        resid_mg in 1u32..9,
        settle_s in 10u32..90,
    ) {
        // a family of procedures: the standard with other limits, laid out at random
        let text = base()
            .replace("accept accel.residual.std <= 0.002 g", &format!("accept accel.residual.std <= {resid_mg} mg"))
            .replace("at least 30 s", &format!("at least {settle_s} s"));
        let text = relayout(&text, &choices);
        let formatted = ratecal_grammar::canonical(&text).unwrap().text;
        let (p, f) = (plan(&text), plan(&formatted));
        let changes = audit::diff(&p, &f);
        prop_assert!(changes.is_empty(), "{changes:#?}");
        prop_assert!(audit::diff(&f, &plan(&ratecal_grammar::canonical(&formatted).unwrap().text)).is_empty());
    }
}
