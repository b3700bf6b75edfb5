//! Any bytes: parsing, formatting and checking end in a result or in diagnostics that name
//! a line and a column, never in a panic. Run with `cargo fuzz run -s none parse_check`.
#![no_main]

use libfuzzer_sys::fuzz_target;
use ratecal_check::{CheckOptions, NoImports, check_text};

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    if let Ok(file) = ratecal_grammar::parse(&text) {
        // Formatting is idempotent on anything that parses.
        let once = ratecal_grammar::format(&file);
        let again = ratecal_grammar::parse(&once).expect("formatted text parses");
        assert_eq!(ratecal_grammar::format(&again), once);
    }
    if let Err(diags) = check_text("fuzz", &text, &NoImports, &CheckOptions::default()) {
        for d in &diags {
            assert!(d.line_col().is_some(), "{d:?}");
        }
    }
});
