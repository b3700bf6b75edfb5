//! Any bytes as an effect file: loading ends in effects or in diagnostics that name a line
//! and a column, never in a panic. Run with `cargo fuzz run -s none effect_load`. (An
//! input that loads is leaked, as in explain: valid inputs are rare among random ones.)
#![no_main]

use libfuzzer_sys::fuzz_target;
use ratecal_analysis::explain::user;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data).into_owned();
    if let Err(diags) = user::load(&[("fuzz.effect".into(), text)]) {
        for d in &diags {
            assert!(d.line_col().is_some(), "{d:?}");
        }
    }
});
