//! The laboratory's authorised signers (`LAB.yaml` key `signers`): an approved run's
//! certificate is issued only when the key that approved it is one of theirs. `approve`
//! needs no laboratory file; the check is here, when a certificate is issued.

use crate::ApprovalBlock;
use crate::model::Lab;
use miette::{Diagnostic, NamedSource, SourceSpan};
use std::path::Path;

/// A refusal located in `LAB.yaml`.
#[derive(Debug, thiserror::Error, Diagnostic)]
#[error("{message}")]
#[diagnostic(code(certificate::signer))]
struct Refused {
    message: String,
    #[source_code]
    src: NamedSource<String>,
    #[label("{label}")]
    span: SourceSpan,
    label: String,
    #[help]
    help: String,
}

/// The signer of `lab` whose public key made `approval`, or the refusal: `LAB.yaml` lists
/// no signers, a signer's key file cannot be read, or none of them has the approval's key
/// (named by its fingerprint).
pub(crate) fn authorised<'a>(
    lab_file: &Path,
    lab_text: &str,
    lab: &'a Lab,
    approval: &ApprovalBlock,
) -> miette::Result<&'a crate::model::Signer> {
    let name = lab_file.display().to_string();
    let src = || NamedSource::new(name.clone(), lab_text.to_string());
    let example = "signers: [{name: A. Metrologist, role: Head of laboratory, public_key: \
                   keys/lab.pub}] (the .pub file `ratecal key new` wrote, its path relative to \
                   the laboratory file)";
    if lab.signers.is_empty() {
        return Err(Refused {
            message: format!(
                "{name} lists no authorised signers: the approval by {} ({}), key {}, cannot \
                 be checked",
                approval.signer, approval.role, approval.key_fingerprint
            ),
            src: src(),
            span: (0, 0).into(),
            label: "no `signers` in this file".into(),
            help: format!("add the laboratory's authorised signers: {example}"),
        }
        .into());
    }
    let base = lab_file.parent().unwrap_or(Path::new("."));
    for s in &lab.signers {
        let key = ratecal_folder::keys::verifying_key(&base.join(&s.public_key)).map_err(|e| {
            Refused {
                message: format!("the public key of signer {} cannot be read", s.name),
                span: value_span(lab_text, &s.public_key),
                src: src(),
                label: format!("{e}"),
                help: "`public_key` is the path, relative to the laboratory file, of the .pub \
                       file `ratecal key new DIR` wrote"
                    .into(),
            }
        })?;
        if ratecal_folder::seal::key_fingerprint(&key) == approval.key_fingerprint {
            return Ok(s);
        }
    }
    Err(Refused {
        message: format!(
            "the run was approved by {} ({}) with key {}, which is not the key of a signer \
             {name} lists",
            approval.signer, approval.role, approval.key_fingerprint
        ),
        span: value_span(lab_text, "signers"),
        src: src(),
        label: "the authorised signers".into(),
        help: "approve the run again with the key of a listed signer (`ratecal approve RUN \
               --key ...`), or, if the approver is authorised, add their public key: "
            .to_string()
            + example,
    }
    .into())
}

/// The span of the first occurrence of `what` in `text` (empty at 0 when absent).
fn value_span(text: &str, what: &str) -> SourceSpan {
    text.find(what)
        .map_or((0, 0).into(), |at| (at, what.len()).into())
}
