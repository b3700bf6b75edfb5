//! `ratecal certificate`: the seal verified, the certificate issued
//! (`ratecal_certificate::issue`) and rendered in the format asked for.

use ratecal_certificate::issue::{Request, issue, lab_logo};
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
        Format::Pdf => {
            match render::pdf(&certificate, lab_logo(&args.lab, &certificate.lab).as_ref()) {
                Ok(b) => b,
                Err(e) => {
                    errln!(
                        "{:?}",
                        miette::miette!(
                            code = "certificate::pdf",
                            "cannot typeset the certificate: {e}"
                        )
                    );
                    return 1;
                }
            }
        }
    };
    match out {
        Some(path) => {
            if let Err(e) = std::fs::write(path, &bytes) {
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
