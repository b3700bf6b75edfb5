//! Template errors as located diagnostics: the template file, the line and span, what went
//! wrong, and a help line. Never a panic, never a blank report.

use miette::{Diagnostic, NamedSource, SourceSpan};

/// Syntax or runtime error inside a template, located in its source.
#[derive(Debug, thiserror::Error, Diagnostic)]
#[error("template error in {file}{}: {message}", line.map(|l| format!(" line {l}")).unwrap_or_default())]
#[diagnostic(code(render::template), help("{help}"))]
pub struct TemplateError {
    /// File the error is in (the lab's path, or `templates/<name> (bundled)`).
    pub file: String,
    /// 1-based line, when known.
    pub line: Option<usize>,
    /// What went wrong.
    pub message: String,
    /// Advice.
    pub help: String,
    /// Template source.
    #[source_code]
    pub src: NamedSource<String>,
    /// Where.
    #[label("{message}")]
    pub span: Option<SourceSpan>,
}

/// A template could not be compiled or rendered.
#[derive(Debug, thiserror::Error, Diagnostic)]
pub enum RenderError {
    /// Syntax or runtime error inside a template, located in its source.
    #[error(transparent)]
    #[diagnostic(transparent)]
    Template(Box<TemplateError>),
    /// The template asked for does not exist (bundled or overridden).
    #[error("no template named `{name}`")]
    #[diagnostic(
        code(render::no_template),
        help("available templates: {available}; a template directory overrides files by name")
    )]
    NoTemplate {
        /// Name asked for.
        name: String,
        /// Names known.
        available: String,
    },
    /// The template rendered to nothing but whitespace.
    #[error("template {file} produced an empty report")]
    #[diagnostic(
        code(render::empty),
        help("a report template must print something; check its `{{% if %}}` blocks")
    )]
    Empty {
        /// Template file.
        file: String,
    },
}

/// Maps a minijinja error to a located diagnostic. `lookup(name)` gives the file label and
/// source text of a template by name.
pub fn from_minijinja(
    err: &minijinja::Error,
    fallback: &str,
    lookup: impl Fn(&str) -> Option<(String, String)>,
) -> RenderError {
    let name = err.name().unwrap_or(fallback).to_string();
    let (file, text) = lookup(&name)
        .or_else(|| err.template_source().map(|s| (name.clone(), s.to_string())))
        .unwrap_or_else(|| (name.clone(), String::new()));
    let span = err
        .range()
        .filter(|r| r.end <= text.len() && r.start <= r.end)
        .map(|r| SourceSpan::from((r.start, (r.end - r.start).max(1))))
        .or_else(|| err.line().and_then(|l| line_span(&text, l)));
    let message = match err.detail() {
        Some(d) => format!("{}: {d}", err.kind()),
        None => err.kind().to_string(),
    };
    let help = match err.kind() {
        minijinja::ErrorKind::SyntaxError => {
            "check the tag syntax: {{ expr }}, {% if %}...{% endif %}, {% for %}...{% endfor %}"
        }
        minijinja::ErrorKind::UnknownFilter => {
            "report filters: measured, fmt_num, si, ppm, unit, cmp, verdict_label, value_of, expanded, as_written (see docs/report-templates.md)"
        }
        minijinja::ErrorKind::TemplateNotFound => "included templates must sit in the same directory",
        _ => "see docs/report-templates.md for the fields a report template can use",
    }
    .to_string();
    RenderError::Template(Box::new(TemplateError {
        file: file.clone(),
        line: err.line(),
        message,
        help,
        src: NamedSource::new(file, text),
        span,
    }))
}

fn line_span(text: &str, line: usize) -> Option<SourceSpan> {
    let mut start = 0;
    for (i, l) in text.split_inclusive('\n').enumerate() {
        if i + 1 == line {
            return Some(SourceSpan::from((start, l.trim_end().len().max(1))));
        }
        start += l.len();
    }
    None
}
