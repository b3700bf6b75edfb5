//! Typst's errors as miette diagnostics: a template the laboratory edited that does not
//! compile is shown located in its text, every error at once, with Typst's hints.

use super::Template;
use super::world::CertWorld;
use ::typst::WorldExt;
use ::typst::diag::SourceDiagnostic;
use miette::{Diagnostic, NamedSource, SourceSpan};

/// The template could not typeset the certificate (or, rarely, the PDF could not be written).
#[derive(Debug, thiserror::Error, Diagnostic)]
#[error("{message}")]
#[diagnostic(code(certificate::template))]
pub struct TemplateError {
    message: String,
    #[source_code]
    src: Option<NamedSource<String>>,
    #[label("{label}")]
    span: Option<SourceSpan>,
    label: String,
    #[help]
    help: String,
    #[related]
    more: Vec<TemplateError>,
}

const HELP: &str = "the template is Typst (typst.app/docs); it reads json(\"/certificate.json\") \
                    (the keys of --format json); remove `template` from LAB.yaml to use the \
                    default one (docs/certificate.md)";

impl TemplateError {
    /// An error that is not the template's fault.
    pub(super) fn internal(message: String) -> TemplateError {
        TemplateError {
            message: format!("cannot typeset the certificate: {message}"),
            src: None,
            span: None,
            label: String::new(),
            help: "this is a bug in ratecal; please report it with the run folder".into(),
            more: Vec::new(),
        }
    }

    /// Every error Typst reported, the first one leading, each located in the template when
    /// its span lies there.
    pub(super) fn from_typst(
        world: &CertWorld,
        template: &Template,
        errors: &[SourceDiagnostic],
    ) -> TemplateError {
        let mut all: Vec<TemplateError> = errors.iter().map(|d| one(world, template, d)).collect();
        if all.is_empty() {
            return TemplateError::internal("Typst reported an error without a message".into());
        }
        let mut first = all.remove(0);
        first.more = all;
        first
    }

    /// The message of the first error (for tests and logs).
    pub fn message(&self) -> &str {
        &self.message
    }
}

fn one(world: &CertWorld, template: &Template, d: &SourceDiagnostic) -> TemplateError {
    let in_template = d.span.id() == Some(world.main_source().id());
    let range = in_template.then(|| world.range(d.span)).flatten();
    let hints: Vec<&str> = d.hints.iter().map(|h| h.v.as_str()).collect();
    let help = if hints.is_empty() {
        HELP.to_string()
    } else {
        format!("{}; {HELP}", hints.join("; "))
    };
    TemplateError {
        message: format!("the certificate template {}: {}", template.name, d.message),
        src: range
            .as_ref()
            .map(|_| NamedSource::new(template.name.clone(), template.text.clone())),
        span: range.map(|r| (r.start, r.end - r.start).into()),
        label: "here".into(),
        help,
        more: Vec::new(),
    }
}
