//! The PDF: the certificate's JSON typeset by Typst (used as a library) through a template,
//! the default one built in or the laboratory's own (`LAB.yaml` key `template`), exported as
//! PDF/A-2b with its fonts subset and embedded. The date of issue is the document's date
//! and its number its identifier, so the same content gives the same bytes.

mod diagnostics;
mod world;

pub use diagnostics::TemplateError;
pub use world::DATA_PATH;

use crate::model::Certificate;
use ::typst::foundations::{Datetime, Smart};
use ::typst_layout::PagedDocument;
use typst_pdf::{PdfOptions, PdfStandard, PdfStandards, Timestamp};
use world::CertWorld;

/// The default template's text (`certificate/templates/certificate.typ`).
pub const DEFAULT_TEMPLATE: &str = include_str!("../../../templates/certificate.typ");

/// A certificate template: its Typst text and the name diagnostics show.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Template {
    /// Where it came from (a file name, or `default certificate template`).
    pub name: String,
    /// The Typst source.
    pub text: String,
}

impl Default for Template {
    fn default() -> Self {
        Template {
            name: "default certificate template".into(),
            text: DEFAULT_TEMPLATE.into(),
        }
    }
}

/// A logo image's bytes and its file extension (`png`, `jpg`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LogoFile {
    /// The file's bytes.
    pub bytes: Vec<u8>,
    /// `png` or `jpg`.
    pub extension: &'static str,
}

/// `YYYY-MM-DD` as year, month, day (1970-01-01 when it is not one).
fn ymd(date: &str) -> (i32, u8, u8) {
    let mut it = date.splitn(3, '-').map(|p| p.parse::<i32>().ok());
    match (
        it.next().flatten(),
        it.next().flatten(),
        it.next().flatten(),
    ) {
        (Some(y), Some(m), Some(d)) if (1..=12).contains(&m) && (1..=31).contains(&d) => {
            (y, m as u8, d as u8)
        }
        _ => (1970, 1, 1),
    }
}

/// Typesets `c` through `template` into a PDF/A-2b document.
pub fn pdf(
    c: &Certificate,
    template: &Template,
    logo: Option<&LogoFile>,
) -> Result<Vec<u8>, Box<TemplateError>> {
    typeset(c, template, logo)
}

fn typeset(
    c: &Certificate,
    template: &Template,
    logo: Option<&LogoFile>,
) -> Result<Vec<u8>, Box<TemplateError>> {
    let data = serde_json::to_string(c).map_err(|e| TemplateError::internal(e.to_string()))?;
    let mut files = Vec::new();
    let mut inputs = Vec::new();
    if let Some(l) = logo {
        let path = format!("/logo.{}", l.extension);
        files.push((path.clone(), l.bytes.clone()));
        inputs.push(("logo", path));
    }
    let today = ymd(&c.identification.issue_date);
    let world = CertWorld::new(&template.text, data, files, inputs, today)
        .ok_or_else(|| TemplateError::internal("the template's world cannot be built".into()))?;
    let warned = ::typst::compile::<PagedDocument>(&world);
    let document = warned
        .output
        .map_err(|errors| TemplateError::from_typst(&world, template, &errors))?;
    let date = Datetime::from_ymd_hms(today.0, today.1, today.2, 0, 0, 0)
        .ok_or_else(|| TemplateError::internal("no date of issue".into()))?;
    let standards = PdfStandards::new(&[PdfStandard::A_2b])
        .map_err(|e| TemplateError::internal(format!("{e:?}")))?;
    let options = PdfOptions {
        ident: Smart::Custom(format!(
            "{}/{}",
            c.identification.archive_id,
            c.number_text()
        )),
        creator: Smart::Custom(Some("ratecal".into())),
        timestamp: Some(Timestamp::new_utc(date)),
        standards,
        ..PdfOptions::default()
    };
    typst_pdf::pdf(&document, &options)
        .map_err(|errors| Box::new(TemplateError::from_typst(&world, template, &errors)))
}

#[cfg(test)]
mod tests {
    use super::ymd;

    #[test]
    fn dates_that_are_not_dates_fall_back_to_the_epoch() {
        assert_eq!(ymd("2026-11-28"), (2026, 11, 28));
        assert_eq!(ymd("2026-13-01"), (1970, 1, 1));
        assert_eq!(ymd(""), (1970, 1, 1));
    }
}
