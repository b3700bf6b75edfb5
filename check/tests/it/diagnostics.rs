//! Diagnostics point at the faulty token, say one thing per cause, and suggest from the
//! namespace the name belongs to (issue 39, item 4).

use ratecal_check::{CheckOptions, NoImports, check_text};
use ratecal_grammar::Diagnostic;

fn refused(text: &str) -> Vec<Diagnostic> {
    let d = check_text("p.rcal", text, &NoImports, &CheckOptions::default()).expect_err("refused");
    d.into_iter().filter(Diagnostic::is_error).collect()
}

const RATES: &str = include_str!("../fixtures/err_unit_in_list.rcal");

#[test]
fn a_unit_error_after_a_list_is_one_error_on_the_unit() {
    let errors = refused(RATES);
    let codes: Vec<&str> = errors.iter().map(|d| d.code).collect();
    assert_eq!(codes, ["check::unknown_unit"], "{errors:#?}");
    let d = &errors[0];
    let at = RATES.find("deg/sec").expect("the unit");
    let (span, _) = &d.labels[0];
    assert_eq!(
        &RATES[span.start..span.end],
        "deg/sec",
        "the caret lands on the unit, not on `-150`"
    );
    assert_eq!(span.start, at);
    assert!(d.help.as_deref().unwrap_or("").contains("deg/s"), "{d:?}");
}

#[test]
fn a_misspelt_parameter_is_matched_against_parameters() {
    let text = include_str!("../fixtures/err_accept_parameter_typo.rcal");
    let errors = refused(text);
    let bais = errors
        .iter()
        .find(|d| d.message.contains("accel.bais.x"))
        .expect("the misspelt parameter is refused");
    let help = bais.help.as_deref().unwrap_or("");
    assert!(help.contains("`accel.bias.x`"), "{help}");
    assert!(!help.contains("residual"), "{help}");
    // A misspelt computed quantity is still matched against those.
    let sdt = errors
        .iter()
        .find(|d| d.message.contains("accel.residual.sdt"))
        .expect("the misspelt quantity is refused");
    assert!(
        sdt.help
            .as_deref()
            .unwrap_or("")
            .contains("`accel.residual.std`"),
        "{sdt:?}"
    );
}
