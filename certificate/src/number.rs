//! The number bound to its content (issue 37): a draft and a dry run's specimen take no
//! number; a run's certificate keeps its number only for the content issued under it (the
//! same customer, order, template and JSON give the same number and the same PDF bytes);
//! other content is refused unless amended, with a reason; a new number is taken in the
//! transaction that records the document's hashes, so a process that dies first burns none.

use crate::issue::Request;
use crate::{Certificate, render};
use ratecal_archive::{Archive, Content};
use ratecal_recording::commit::crash_point;
use ratecal_recording::sha256_hex;

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

/// A certificate issued: its data and the bytes of the format asked for.
#[derive(Debug, Clone)]
pub struct Issued {
    /// The certificate.
    pub certificate: Certificate,
    /// The document in the format asked for.
    pub bytes: Vec<u8>,
    /// True when the number was issued before (the same content, reissued).
    pub reissue: bool,
}

/// A certificate built without its number, and how it is typeset.
pub(crate) struct Doc {
    pub base: Certificate,
    pub template: render::Template,
    pub logo: Option<render::Logo>,
    pub format: Format,
}

impl Doc {
    fn with(
        &self,
        number: &str,
        replaces: Option<String>,
        reason: Option<String>,
        issued: &str,
    ) -> Certificate {
        let mut c = self.base.clone();
        c.number = Some(number.into());
        c.replaces = replaces;
        c.amend_reason = reason;
        c.identification.issue_date = issued.chars().take(10).collect();
        c
    }

    fn pdf(&self, c: &Certificate) -> miette::Result<Vec<u8>> {
        render::pdf(c, &self.template, self.logo.as_ref().map(|l| l.file()))
            .map_err(|e| miette::Report::new(*e))
    }

    /// SHA-256 of the template's text and the logo's bytes.
    fn template_sha256(&self) -> String {
        let mut bytes = self.template.text.as_bytes().to_vec();
        if let Some(l) = &self.logo {
            bytes.extend_from_slice(&l.file().bytes);
        }
        sha256_hex(&bytes)
    }

    fn bytes(&self, c: &Certificate, pdf: Option<&[u8]>) -> miette::Result<Vec<u8>> {
        Ok(match self.format {
            Format::Json => json(c),
            Format::Md => render::markdown(c).into_bytes(),
            Format::Html => render::html(c).into_bytes(),
            Format::Pdf => match pdf {
                Some(p) => p.to_vec(),
                None => self.pdf(c)?,
            },
        })
    }
}

/// The certificate as `--format json` writes it (the bytes its recorded hash is of).
pub fn json(c: &Certificate) -> Vec<u8> {
    let mut s = serde_json::to_string_pretty(c).unwrap_or_default();
    s.push('\n');
    s.into_bytes()
}

fn refused(message: String, help: String) -> miette::Report {
    miette::miette!(code = "certificate::refused", help = help, "{message}")
}

pub(crate) async fn issue(
    archive: &Archive,
    args: &Request,
    run_id: &str,
    doc: &Doc,
    deliver: &mut dyn FnMut(&Certificate, &[u8]) -> miette::Result<()>,
) -> miette::Result<Issued> {
    let reason = args
        .reason
        .as_deref()
        .map(str::trim)
        .filter(|r| !r.is_empty());
    if args.reason.is_some() && !args.amend {
        return Err(refused(
            "--reason is given without --amend".into(),
            "an amendment is `--amend --reason \"...\"`; a first issue or a reissue takes \
             no reason"
                .into(),
        ));
    }
    // A draft or a specimen: no number, nothing recorded.
    if doc.base.draft || doc.base.specimen {
        if args.amend {
            return Err(refused(
                format!(
                    "a {} takes no number, so it amends none",
                    if doc.base.draft { "draft" } else { "dry run" }
                ),
                "approve the run first (`ratecal approve`); a dry run is never certified".into(),
            ));
        }
        let mut c = doc.base.clone();
        c.identification.issue_date = ratecal_recording::rfc3339(std::time::SystemTime::now())
            .chars()
            .take(10)
            .collect();
        let bytes = doc.bytes(&c, None)?;
        deliver(&c, &bytes)?;
        return Ok(Issued {
            certificate: c,
            bytes,
            reissue: false,
        });
    }
    if args.amend && reason.is_none() {
        return Err(refused(
            "an amendment needs its reason".into(),
            "give it: `--amend --reason \"...\"` (printed beside the number it replaces)".into(),
        ));
    }
    let template_sha256 = doc.template_sha256();
    loop {
        let newest = archive.newest_certificate(run_id).await?;
        if args.amend && newest.is_none() {
            return Err(refused(
                format!("run {run_id} has no certificate to amend"),
                "issue its first certificate without --amend".into(),
            ));
        }
        if !args.amend
            && let Some(rec) = newest
        {
            // A reissue: the content must be the one issued under the number.
            let c = doc.with(
                &rec.number,
                rec.replaces.clone(),
                rec.reason.clone(),
                &rec.issued,
            );
            let json = json(&c);
            let json_sha256 = sha256_hex(&json);
            let mut differs = Vec::new();
            if rec.json_sha256.is_some() {
                if rec.customer != args.customer {
                    differs.push(format!(
                        "customer {} (issued: {})",
                        quoted(&args.customer),
                        quoted(&rec.customer)
                    ));
                }
                if rec.order_ref != args.order {
                    differs.push(format!(
                        "order {} (issued: {})",
                        quoted(&args.order),
                        quoted(&rec.order_ref)
                    ));
                }
                if rec.template_sha256.as_deref() != Some(template_sha256.as_str()) {
                    differs.push("the template or logo".into());
                }
                if differs.is_empty() && rec.json_sha256.as_deref() != Some(json_sha256.as_str()) {
                    differs.push("the certificate's data (JSON)".into());
                }
            }
            let pdf = doc.pdf(&c)?;
            let pdf_sha256 = sha256_hex(&pdf);
            if differs.is_empty()
                && rec.pdf_sha256.is_some()
                && rec.pdf_sha256.as_deref() != Some(pdf_sha256.as_str())
            {
                differs.push("the typeset PDF".into());
            }
            if !differs.is_empty() {
                return Err(refused(
                    format!(
                        "certificate No. {} was issued for this run with other content: {}",
                        rec.number,
                        differs.join(", ")
                    ),
                    "a number stays bound to what was issued under it: reissue it with the \
                     same options, or issue an amendment that replaces it: `--amend \
                     --reason \"...\"`"
                        .into(),
                ));
            }
            if rec.json_sha256.is_none() {
                // Issued before the archive recorded content: bound to it now.
                let content = Content {
                    customer: args.customer.clone(),
                    order: args.order.clone(),
                    template_sha256: template_sha256.clone(),
                    pdf_sha256,
                    json_sha256,
                    reason: None,
                };
                archive.bind_certificate(&rec.number, &content).await?;
            }
            let bytes = doc.bytes(&c, Some(&pdf))?;
            deliver(&c, &bytes)?;
            return Ok(Issued {
                certificate: c,
                bytes,
                reissue: true,
            });
        }
        let now = ratecal_recording::rfc3339(std::time::SystemTime::now());
        let year: i32 = now[..4].parse().unwrap_or(1970);
        let Some(reservation) = archive
            .reserve(
                run_id,
                &doc.base.lab.certificate_prefix,
                year,
                args.amend,
                &now,
            )
            .await?
        else {
            // Another process issued this run's first certificate meanwhile: compare.
            continue;
        };
        let c = doc.with(
            &reservation.number,
            reservation.replaces.clone(),
            reason.map(String::from),
            &reservation.issued,
        );
        let json = json(&c);
        let pdf = doc.pdf(&c)?;
        let bytes = doc.bytes(&c, Some(&pdf))?;
        crash_point("certificate-before-deliver");
        deliver(&c, &bytes)?;
        crash_point("certificate-before-record");
        reservation
            .record(&Content {
                customer: args.customer.clone(),
                order: args.order.clone(),
                template_sha256,
                pdf_sha256: sha256_hex(&pdf),
                json_sha256: sha256_hex(&json),
                reason: reason.map(String::from),
            })
            .await?;
        return Ok(Issued {
            certificate: c,
            bytes,
            reissue: false,
        });
    }
}

fn quoted(v: &Option<String>) -> String {
    match v {
        Some(s) => format!("`{s}`"),
        None => "not stated".into(),
    }
}

/// What the archive recorded of a PDF (`ratecal certificate verify`): the certificate whose
/// PDF has exactly these bytes and the number that replaced it, or `None` when it issued no
/// such PDF (never issued, or altered since).
pub async fn verify(
    pdf: &[u8],
    archive: Option<&str>,
) -> miette::Result<Option<(ratecal_archive::Issued, Option<String>)>> {
    let loc = ratecal_archive::Location::resolve(archive, None);
    let archive = Archive::open_existing(&loc).await?;
    let found = archive.certificate_of_pdf(&sha256_hex(pdf)).await?;
    archive.close().await;
    Ok(found)
}
