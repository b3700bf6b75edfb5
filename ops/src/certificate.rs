//! `ratecal certificate`: the seal verified, the certificate issued
//! (`ratecal_certificate::issue`) and rendered in the format asked for.

use ratecal_certificate::issue::{Request, issue, lab_logo, lab_template};
use ratecal_certificate::render;
use std::path::Path;

/// The certificate's format.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// PDF (a typeset document, fonts embedded).
    Pdf,
    /// Self-contained HTML.
    Html,
    /// Markdown.
    Md,
    /// The certificate's data (`docs/certificate.md`).
    Json,
}

/// Issues the certificate in `format`, to `out` or standard output; the exit code of
/// spec/cli.md.
pub fn certificate(args: &Request, format: Format, out: Option<&Path>) -> u8 {
    // An output never replaces an input: refused before a number is taken.
    if let Some(path) = out
        && let Err(e) =
            ratecal_folder::outputs::refuse_inputs(path, "--out", &[args.run_dir.as_path()])
    {
        errln!("{e:?}");
        return 1;
    }
    if let Err(e) = ratecal_folder::verify::require_intact(&args.run_dir, "certificate") {
        errln!("{e:?}");
        return 4;
    }
    let rt = match tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
    {
        Ok(rt) => rt,
        Err(e) => {
            errln!("{:?}", miette::miette!("cannot start the runtime: {e}"));
            return 1;
        }
    };
    let certificate = match rt.block_on(issue(args)) {
        Ok(c) => c,
        Err(e) => {
            errln!("{e:?}");
            return 1;
        }
    };
    let bytes = match format {
        Format::Json => {
            { serde_json::to_string_pretty(&certificate).expect("a certificate serializes") + "\n" }
                .into_bytes()
        }
        Format::Md => render::markdown(&certificate).into_bytes(),
        Format::Html => render::html(&certificate).into_bytes(),
        Format::Pdf => match typeset(args, &certificate) {
            Ok(b) => b,
            Err(e) => {
                errln!("{e:?}");
                return 1;
            }
        },
    };
    match out {
        Some(path) => {
            if let Err(e) = write_aside(path, &bytes) {
                errln!("cannot write {}: {e}", path.display());
                return 1;
            }
            errln!(
                "certificate No. {}{} written to {}",
                certificate.number,
                if certificate.draft { " (DRAFT)" } else { "" },
                path.display()
            );
        }
        None => {
            crate::console::bytes(&bytes);
        }
    }
    0
}

/// The PDF, through the laboratory's template or the default one.
fn typeset(
    args: &Request,
    certificate: &ratecal_certificate::Certificate,
) -> miette::Result<Vec<u8>> {
    let template = lab_template(&args.lab, &certificate.lab)?;
    let logo = lab_logo(&args.lab, &certificate.lab);
    render::pdf(certificate, &template, logo.as_ref().map(|l| l.file()))
        .map_err(|e| miette::Report::new(*e))
}

/// Writes `bytes` beside `path` and renames it into place: a reader never sees half a
/// certificate, and a failure leaves no file at `path`.
fn write_aside(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "certificate".into());
    let aside = path.with_file_name(format!(".{name}.partial"));
    ratecal_recording::commit::write_nofollow(&aside, bytes)?;
    std::fs::rename(&aside, path).inspect_err(|_| {
        let _ = std::fs::remove_file(&aside);
    })
}
