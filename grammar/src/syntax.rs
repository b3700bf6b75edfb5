//! Syntax errors of both languages (procedures, user effects): pest's error turned into a
//! diagnostic that says what was expected, in the language's own words.

use crate::ast::Span;
use crate::diag::Diagnostic;
use pest::RuleType;
use pest::error::{Error, ErrorVariant, InputLocation};

/// What a language says about its syntax errors.
pub(crate) struct Language<R> {
    /// The diagnostic's code.
    pub(crate) code: &'static str,
    /// The help when no keyword stands where the error is.
    pub(crate) help: &'static str,
    /// What a rule is, in an engineer's words (`None`: a rule the message leaves out).
    pub(crate) rule_name: fn(R) -> Option<&'static str>,
    /// The keyword that `rest` begins with, if any.
    pub(crate) keyword: fn(&str) -> Option<&str>,
}

/// The diagnostic of a parse of `text` that failed with `e`.
pub(crate) fn error<R: RuleType>(e: Error<R>, text: &str, language: &Language<R>) -> Diagnostic {
    let pos = match e.location {
        InputLocation::Pos(p) => p,
        InputLocation::Span((s, _)) => s,
    };
    let mut expected: Vec<&str> = match &e.variant {
        ErrorVariant::ParsingError { positives, .. } => positives
            .iter()
            .filter_map(|r| (language.rule_name)(*r))
            .collect(),
        ErrorVariant::CustomError { .. } => Vec::new(),
    };
    expected.sort_unstable();
    expected.dedup();
    let what = match expected.split_last() {
        None => "unexpected input".to_string(),
        Some((only, [])) => format!("expected {only}"),
        Some((last, rest)) => format!("expected {} or {last}", rest.join(", ")),
    };
    // A keyword where a name was expected: say so.
    let help = match text.get(pos..).and_then(language.keyword) {
        Some(kw) => format!("`{kw}` is a keyword and cannot be used as a name; pick another name"),
        None => language.help.to_string(),
    };
    Diagnostic::error(language.code, format!("syntax error: {what}"))
        .label(Span::new(pos, pos), what)
        .help(help)
}
