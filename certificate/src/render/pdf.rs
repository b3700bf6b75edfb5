//! The certificate as PDF, typeset by genpdf (line breaking, tables, page decorations) on
//! printpdf, in DejaVu Sans embedded whole (with its ToUnicode map: the text can be selected
//! and searched). The header on every page names the laboratory, the number and "page N of
//! M", and says DRAFT for an unapproved run; M comes from a first typesetting pass.

use super::doc::{Block, blocks, header};
use crate::model::Certificate;
use genpdf::elements::{Break, FrameCellDecorator, LinearLayout, Paragraph, TableLayout};
use genpdf::fonts::{FontData, FontFamily};
use genpdf::style::{Color, Style};
use genpdf::{Document, Element, SimplePageDecorator};
use std::cell::Cell;
use std::rc::Rc;

/// Why a PDF could not be typeset.
#[derive(Debug)]
pub struct PdfError(String);

impl std::fmt::Display for PdfError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for PdfError {}

fn err(e: impl std::fmt::Display) -> PdfError {
    PdfError(e.to_string())
}

fn fonts() -> Result<FontFamily<FontData>, PdfError> {
    let regular = FontData::new(dejavu::sans::regular().to_vec(), None).map_err(err)?;
    let bold = FontData::new(dejavu::sans::bold().to_vec(), None).map_err(err)?;
    // Italic is never used: the regular face stands in (genpdf wants all four).
    Ok(FontFamily {
        regular: regular.clone(),
        bold: bold.clone(),
        italic: regular,
        bold_italic: bold,
    })
}

/// Typesets the certificate: two passes, the first to count the pages.
pub fn pdf(c: &Certificate) -> Result<Vec<u8>, PdfError> {
    let pages = Rc::new(Cell::new(0usize));
    typeset(c, None, pages.clone())?;
    typeset(c, Some(pages.get()), pages)
}

fn typeset(
    c: &Certificate,
    total: Option<usize>,
    seen: Rc<Cell<usize>>,
) -> Result<Vec<u8>, PdfError> {
    let mut doc = Document::new(fonts()?);
    doc.set_title(format!("Certificate No. {}", c.number));
    doc.set_font_size(9);
    doc.set_line_spacing(1.2);
    doc.set_paper_size(genpdf::PaperSize::A4);
    let lines = header(c);
    let draft = c.draft;
    let mut deco = SimplePageDecorator::new();
    deco.set_margins(15);
    deco.set_header(move |page| {
        seen.set(seen.get().max(page));
        let mut l = LinearLayout::vertical();
        if draft {
            l.push(
                Paragraph::new("DRAFT - not approved").styled(
                    Style::new()
                        .bold()
                        .with_font_size(14)
                        .with_color(Color::Rgb(180, 0, 0)),
                ),
            );
        }
        l.push(Paragraph::new(lines[0].clone()).styled(Style::new().bold().with_font_size(11)));
        for line in &lines[1..3] {
            l.push(Paragraph::new(line.clone()).styled(Style::new().with_font_size(8)));
        }
        let of = total.map_or_else(|| "?".to_string(), |t| t.to_string());
        l.push(
            Paragraph::new(format!("{}    page {page} of {of}", lines[3]))
                .styled(Style::new().bold().with_font_size(9)),
        );
        l.push(Break::new(1));
        l
    });
    doc.set_page_decorator(deco);
    for b in blocks(c) {
        match b {
            Block::Heading(h) => {
                doc.push(Break::new(0.6));
                doc.push(Paragraph::new(h).styled(Style::new().bold().with_font_size(12)));
            }
            Block::Para(p) => doc.push(Paragraph::new(p)),
            Block::Fields(f) => {
                let mut t = TableLayout::new(vec![1, 3]);
                for (k, v) in f {
                    t.row()
                        .element(Paragraph::new(k).styled(Style::new().bold()))
                        .element(Paragraph::new(v))
                        .push()
                        .map_err(err)?;
                }
                doc.push(t);
            }
            Block::Table(head, rows) => {
                let weights = match head.len() {
                    2 => vec![1, 2],
                    5 => vec![4, 2, 3, 2, 5],
                    7 => vec![4, 1, 3, 3, 4, 3, 1],
                    n => vec![1; n],
                };
                let small = Style::new().with_font_size(7);
                let mut t = TableLayout::new(weights);
                t.set_cell_decorator(FrameCellDecorator::new(true, true, false));
                let mut row = t.row();
                for h in head {
                    row.push_element(Paragraph::new(h).styled(small.bold()).padded(1));
                }
                row.push().map_err(err)?;
                for r in rows {
                    let mut row = t.row();
                    for cell in r {
                        row.push_element(Paragraph::new(cell).styled(small).padded(1));
                    }
                    row.push().map_err(err)?;
                }
                doc.push(t);
            }
        }
    }
    let mut out = Vec::new();
    doc.render(&mut out).map_err(err)?;
    Ok(out)
}
