//! The certificate as PDF, typeset by genpdf (line breaking, tables, page decorations) on
//! printpdf, in DejaVu Sans embedded whole (with its ToUnicode map: the text can be selected
//! and searched). The header on every page names the laboratory, the number and "page N of
//! M", and says DRAFT for an unapproved run; M comes from a first typesetting pass.

use super::doc::{Block, blocks, header};
use super::logo::Logo;
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

/// Typesets the certificate: two passes, the first to count the pages; the laboratory's
/// logo, when given, in the top margin of every page.
pub fn pdf(c: &Certificate, logo: Option<&Logo>) -> Result<Vec<u8>, PdfError> {
    let pages = Rc::new(Cell::new(0usize));
    typeset(c, None, pages.clone(), None)?;
    typeset(c, Some(pages.get()), pages, logo)
}

fn typeset(
    c: &Certificate,
    total: Option<usize>,
    seen: Rc<Cell<usize>>,
    logo: Option<&Logo>,
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
            Block::Para(p) => doc.push(Paragraph::new(breakable(&p, fit(180.0, 9.0)))),
            Block::Fields(f) => {
                let mut t = TableLayout::new(vec![1, 3]);
                for (k, v) in f {
                    t.row()
                        .element(Paragraph::new(k).styled(Style::new().bold()))
                        .element(Paragraph::new(breakable(&v, fit(135.0, 9.0))))
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
                let sum: usize = weights.iter().sum();
                let widths: Vec<usize> = weights
                    .iter()
                    .map(|w| fit(180.0 * *w as f64 / sum as f64 - 2.0, 7.0))
                    .collect();
                let mut t = TableLayout::new(weights);
                t.set_cell_decorator(FrameCellDecorator::new(true, true, false));
                let mut row = t.row();
                for h in head {
                    row.push_element(Paragraph::new(h).styled(small.bold()).padded(1));
                }
                row.push().map_err(err)?;
                for r in rows {
                    let mut row = t.row();
                    for (cell, w) in r.iter().zip(&widths) {
                        let cell = breakable(cell, *w);
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
    if total.is_some() {
        tidy(&out, logo)
    } else {
        Ok(out)
    }
}

/// How many characters of DejaVu Sans at `pt` fit in `mm` (digits, hex and lower case are
/// at most 0.65 em wide: a SHA-256 fits a field's column whole).
fn fit(mm: f64, pt: f64) -> usize {
    ((mm * 72.0 / 25.4) / (pt * 0.65)).floor().max(4.0) as usize
}

/// `text` with a space put into any run of more than `max` non-space characters: genpdf
/// drops the rest of a paragraph whose word is wider than its column.
fn breakable(text: &str, max: usize) -> String {
    let mut out = String::with_capacity(text.len());
    let mut run = 0;
    for c in text.chars() {
        if c.is_whitespace() {
            run = 0;
        } else {
            if run == max {
                out.push(' ');
                run = 0;
            }
            run += 1;
        }
        out.push(c);
    }
    out
}

/// Rewrites what printpdf 0.3 writes loosely, with lopdf: each font's ToUnicode map as a
/// plain CMap (printpdf puts PostScript comments inside it and writes code points past
/// U+FFFF as five hex digits, which stricter readers refuse), and every stream compressed
/// (the embedded fonts shrink to about a third); the logo stamped on every page.
fn tidy(pdf: &[u8], logo: Option<&Logo>) -> Result<Vec<u8>, PdfError> {
    let mut doc = lopdf::Document::load_mem(pdf).map_err(err)?;
    let maps: Vec<lopdf::ObjectId> = doc
        .objects
        .values()
        .filter_map(|o| o.as_dict().ok())
        .filter_map(|d| d.get(b"ToUnicode").ok()?.as_reference().ok())
        .collect();
    for id in maps {
        let stream = doc
            .get_object_mut(id)
            .and_then(|o| o.as_stream_mut())
            .map_err(err)?;
        let text = String::from_utf8_lossy(&stream.content).into_owned();
        stream.set_plain_content(clean_cmap(&text).into_bytes());
    }
    if let Some(logo) = logo {
        super::logo::stamp(&mut doc, logo).map_err(err)?;
    }
    doc.compress();
    let mut out = Vec::new();
    doc.save_to(&mut out).map_err(err)?;
    Ok(out)
}

/// A ToUnicode CMap with the `<glyph> <unicode>` pairs of `text` within the BMP, in blocks
/// of at most 100.
fn clean_cmap(text: &str) -> String {
    let pairs: Vec<(&str, &str)> = text
        .lines()
        .filter_map(|l| {
            let l = l.trim();
            let (a, b) = l.strip_prefix('<')?.split_once("> <")?;
            let b = b.strip_suffix('>')?;
            (a.len() == 4 && b.len() == 4).then_some((a, b))
        })
        .collect();
    let mut s = String::from(
        "/CIDInit /ProcSet findresource begin\n12 dict begin\nbegincmap\n\
         /CIDSystemInfo << /Registry (Adobe) /Ordering (UCS) /Supplement 0 >> def\n\
         /CMapName /Adobe-Identity-UCS def\n/CMapType 2 def\n\
         1 begincodespacerange\n<0000> <FFFF>\nendcodespacerange\n",
    );
    for chunk in pairs.chunks(100) {
        s.push_str(&format!("{} beginbfchar\n", chunk.len()));
        for (g, u) in chunk {
            s.push_str(&format!("<{g}> <{u}>\n"));
        }
        s.push_str("endbfchar\n");
    }
    s.push_str("endcmap\nCMapName currentdict /CMap defineresource pop\nend\nend\n");
    s
}
