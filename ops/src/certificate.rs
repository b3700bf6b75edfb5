//! `ratecal certificate`: the seal verified, the certificate issued
//! (`ratecal_certificate::issue`) and rendered in the format asked for.

use ratecal_certificate::issue::{Request, issue};
use std::path::{Path, PathBuf};

pub use ratecal_certificate::issue::Format;

/// Issues the certificate in `format`, to `out` or standard output; the exit code of
/// spec/cli.md. With `out`, the document is written aside before its number is recorded and
/// renamed into place after: it appears only together with its recorded number.
pub fn certificate(args: &Request, format: Format, out: Option<&Path>) -> u8 {
    // A run of an unreleased procedure is no calibration: refused before anything else.
    if let Some(draft) = ratecal_folder::RunFolder::new(&args.run_dir)
        .manifest_quiet()
        .and_then(|m| m.run)
        .and_then(|r| r.draft_procedure)
    {
        errln!(
            "{:?}",
            miette::miette!(
                code = "certificate::draft_procedure",
                help = "release the procedure (`ratecal release FOLDER@VERSION --signer NAME --key KEY`) and run it again",
                "{}: {draft}; no certificate for a draft procedure",
                args.run_dir.display()
            )
        );
        return 1;
    }
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
    let Some(rt) = runtime() else { return 1 };
    let aside = out.map(aside_of);
    let mut deliver = |_: &ratecal_certificate::Certificate, bytes: &[u8]| match &aside {
        Some(a) => {
            write_synced(a, bytes).map_err(|e| miette::miette!("cannot write {}: {e}", a.display()))
        }
        None => Ok(()),
    };
    let issued = match rt.block_on(issue(args, format, &mut deliver)) {
        Ok(i) => i,
        Err(e) => {
            if let Some(a) = &aside {
                let _ = std::fs::remove_file(a);
            }
            errln!("{e:?}");
            return 1;
        }
    };
    let c = &issued.certificate;
    let what = format!(
        "certificate No. {}{}{}",
        c.number_text(),
        if c.draft { " (DRAFT)" } else { "" },
        if c.specimen {
            " (DRY RUN - SPECIMEN)"
        } else {
            ""
        }
    );
    match (out, &aside) {
        (Some(path), Some(a)) => {
            if let Err(e) = std::fs::rename(a, path) {
                let _ = std::fs::remove_file(a);
                errln!("cannot write {}: {e}", path.display());
                return 1;
            }
            errln!(
                "{what}{} written to {}",
                if issued.reissue { " (reissued)" } else { "" },
                path.display()
            );
        }
        _ => crate::console::bytes(&issued.bytes),
    }
    0
}

/// `ratecal certificate verify FILE.pdf [--archive A]`: 0 when the archive issued exactly
/// this PDF, 1 when not (never issued, or altered) or when the file or the archive
/// cannot be read.
pub fn verify(pdf: &Path, archive: Option<&str>) -> u8 {
    let bytes = match std::fs::read(pdf) {
        Ok(b) => b,
        Err(e) => {
            errln!(
                "{:?}",
                miette::miette!(
                    code = "certificate::io",
                    help = "give the PDF file `ratecal certificate` wrote",
                    "cannot read {}: {e}",
                    pdf.display()
                )
            );
            return 1;
        }
    };
    let Some(rt) = runtime() else { return 1 };
    match rt.block_on(ratecal_certificate::verify(&bytes, archive)) {
        Ok(Some((c, replaced))) => {
            outln!(
                "{}: certificate No. {} of run {} issued {}{}, unaltered{}",
                pdf.display(),
                c.number,
                c.run_id,
                c.issued,
                c.replaces
                    .as_ref()
                    .map(|r| format!(" (amends {r})"))
                    .unwrap_or_default(),
                replaced
                    .map(|r| format!("; replaced by certificate No. {r}"))
                    .unwrap_or_default()
            );
            0
        }
        Ok(None) => {
            errln!(
                "{:?}",
                miette::miette!(
                    code = "certificate::not_issued",
                    help = "only a PDF byte for byte as `ratecal certificate` wrote it verifies: \
                            ask the laboratory for the certificate, or check --archive",
                    "{} is not a certificate this archive issued, or it was altered",
                    pdf.display()
                )
            );
            1
        }
        Err(e) => {
            errln!("{e:?}");
            1
        }
    }
}

fn runtime() -> Option<tokio::runtime::Runtime> {
    match tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
    {
        Ok(rt) => Some(rt),
        Err(e) => {
            errln!("{:?}", miette::miette!("cannot start the runtime: {e}"));
            None
        }
    }
}

/// Where the document is written before it is renamed to `path`.
fn aside_of(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "certificate".into());
    path.with_file_name(format!(".{name}.partial"))
}

/// Writes `bytes` to `path` (never through a link planted there) and syncs it.
fn write_synced(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    use std::io::Write;
    let mut f = ratecal_recording::commit::open_nofollow(path, true, false)?;
    f.write_all(bytes)?;
    f.sync_all()
}
