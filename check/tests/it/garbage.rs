//! Garbage in never panics: any input ends in a plan or in diagnostics that name a line
//! and a column. (The same property is the `fuzz/` target's, for longer runs.)

use proptest::prelude::*;
use ratecal_check::{CheckOptions, NoImports, check_text};

fn assert_graceful(text: &str) {
    if let Ok(file) = ratecal_grammar::parse(text) {
        let once = ratecal_grammar::format(&file);
        let again = ratecal_grammar::parse(&once).expect("formatted text parses");
        assert_eq!(
            ratecal_grammar::format(&again),
            once,
            "formatting is not idempotent"
        );
    }
    if let Err(diags) = check_text("input", text, &NoImports, &CheckOptions::default()) {
        assert!(!diags.is_empty());
        for d in &diags {
            assert!(
                d.line_col().is_some(),
                "no position: {d:?}\ninput: {text:?}"
            );
            let _ = d.render();
        }
    }
}

const STANDARD: &str = include_str!("../../../procedures/imu-2d-standard/1.0.0.rcal");

fn tokens() -> impl Strategy<Value = String> {
    let words = vec![
        "procedure",
        "p",
        "version",
        "1.0.0",
        "{",
        "}",
        "step",
        "s",
        "move",
        "to",
        "pitch",
        "roll",
        "outer",
        "inner",
        "0",
        "-90",
        "1e400",
        "deg",
        "s",
        "g",
        "deg/s",
        ",",
        "(",
        ")",
        "[",
        "]",
        "for",
        "in",
        "repeat",
        "as",
        "acquire",
        "gyro",
        "accel",
        "at",
        "Hz",
        "\"x/{n}\"",
        "\"{\"",
        "fit",
        "from",
        "x/*",
        "settle",
        "at least",
        "abort",
        "when",
        "table.attitude_error",
        ">",
        "<=",
        "verify",
        "accept",
        "remount",
        "up",
        "place",
        "turn",
        "about",
        "by",
        "free",
        "+x",
        "-z",
        "oscillate",
        "amplitude",
        "period",
        "#",
        "\n",
        ";",
        "param",
        "import",
        "\"f\"",
        "n",
        "%",
        "..",
        "+-",
        "->",
        "stop",
        "spin",
        "hold",
    ];
    prop::collection::vec(prop::sample::select(words), 0..80).prop_map(|w| w.join(" "))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn random_bytes(bytes in prop::collection::vec(any::<u8>(), 0..400)) {
        assert_graceful(&String::from_utf8_lossy(&bytes));
    }

    #[test]
    fn random_tokens(text in tokens()) {
        assert_graceful(&text);
    }

    #[test]
    fn mutated_standard(cut in 0usize..STANDARD.len(), len in 0usize..40, insert in "[ -~\n]{0,12}") {
        let mut text = STANDARD.to_string();
        let start = (0..=cut).rev().find(|&i| text.is_char_boundary(i)).unwrap_or(0);
        let end = (start + len).min(text.len());
        let end = (end..=text.len()).find(|&i| text.is_char_boundary(i)).unwrap_or(text.len());
        text.replace_range(start..end, &insert);
        assert_graceful(&text);
    }
}
