//! The sources' rows, streamed: text files of any delimiter or whitespace, CRLF or LF, one
//! line at a time, side by side when there are several (the columns of the second follow
//! those of the first). Only the cells the map names are converted; a bad one is refused
//! with its file, line and column.

mod cells;
mod mat;
mod mat_rows;

pub use cells::{sniff, split_cells};
pub use mat::{Matrix, read_mat};
use mat_rows::{MatRows, mat_cell_error};

use crate::error::{ErrorKind, ImportError, Say};
use crate::map::{Col, ColRef, Delimiter, Format, ImportMap, SourceSpec};
use sha2::{Digest, Sha256};
use std::fs::File;
use std::io::{BufRead, BufReader, Read};
use std::ops::Range;
use std::path::Path;

type Res<T> = Result<T, Box<ImportError>>;

/// A reader that hashes what passes through it (the sources' SHA-256 for the provenance,
/// without reading them twice).
struct Hashing<R> {
    inner: R,
    hash: Sha256,
}

impl<R: Read> Read for Hashing<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.hash.update(&buf[..n]);
        Ok(n)
    }
}

/// One source file read a line at a time.
struct LineSource {
    name: String,
    r: BufReader<Hashing<File>>,
    buf: Vec<u8>,
    /// 1-based number of the line in `buf`.
    line: u64,
    delim: Delimiter,
    cells: Vec<Range<usize>>,
    /// Columns of the header (or of the first row, without one).
    width: Option<usize>,
    /// Global index of this source's first column.
    offset: usize,
}

impl LineSource {
    /// Reads the next line into `buf` (without its line break); `false` at the end.
    fn next_line(&mut self) -> Res<bool> {
        self.buf.clear();
        let n = (&mut self.r)
            .take(MAX_LINE as u64 + 1)
            .read_until(b'\n', &mut self.buf)
            .map_err(|e| io_error(&self.name, &e))?;
        if n == 0 {
            return Ok(false);
        }
        self.line += 1;
        if n > MAX_LINE && self.buf.last() != Some(&b'\n') {
            return Err(self.error(
                0..1,
                ErrorKind::Cell,
                &format!(
                    "line {} is longer than {} MiB (no line break): not a table of numbers",
                    self.line,
                    MAX_LINE >> 20
                ),
                "check the file (a binary file, or one whose line breaks were lost?) and \
                 source.format",
            ));
        }
        while matches!(self.buf.last(), Some(b'\n' | b'\r')) {
            self.buf.pop();
        }
        Ok(true)
    }

    /// The next non-blank line, split into cells; `false` at the end.
    fn next_row(&mut self) -> Res<bool> {
        loop {
            if !self.next_line()? {
                return Ok(false);
            }
            if self.buf.iter().all(|b| b.is_ascii_whitespace()) {
                continue;
            }
            if self.delim == Delimiter::Auto {
                self.delim = sniff(&self.buf);
            }
            split_cells(&self.buf, self.delim, &mut self.cells);
            return Ok(true);
        }
    }

    fn error(
        &self,
        range: Range<usize>,
        kind: ErrorKind,
        what: &str,
        help: &str,
    ) -> Box<ImportError> {
        ImportError::in_line(
            kind,
            &self.name,
            self.line,
            &self.buf,
            range,
            Say {
                what,
                label: "here",
                help,
            },
        )
    }
}

/// Where a converted row came from (for diagnostics after the row was read).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RowAt {
    /// 0-based sample index.
    pub sample: u64,
    /// 1-based line in the first source.
    pub line: u64,
}

/// The sources side by side, with the global columns the map asks for.
pub struct Rows {
    sources: Vec<LineSource>,
    /// Global column of each slot.
    slots: Vec<usize>,
    /// (source, column within it) of each slot.
    local: Vec<(usize, usize)>,
    sample: u64,
    /// A MATLAB source instead of the text ones.
    mat: Option<MatRows>,
}

impl Rows {
    /// Opens the sources (read as `src` says), skips their leading lines, reads their
    /// headers, and resolves the map's `cols` (slot order) to columns.
    pub fn open(paths: &[&Path], src: &SourceSpec, map: &ImportMap, cols: &[&Col]) -> Res<Rows> {
        if let Format::Mat { variable, .. } = &src.format {
            return Self::open_mat(paths, map, variable, cols);
        }
        let mut sources = Vec::with_capacity(paths.len());
        let mut names: Vec<String> = Vec::new();
        let mut offset = 0;
        for p in paths {
            let name = p.display().to_string();
            let f = File::open(p).map_err(|e| io_error(&name, &e))?;
            let mut s = LineSource {
                name,
                r: BufReader::with_capacity(
                    1 << 16,
                    Hashing {
                        inner: f,
                        hash: Sha256::new(),
                    },
                ),
                buf: Vec::with_capacity(256),
                line: 0,
                delim: src.delimiter,
                cells: Vec::with_capacity(16),
                width: None,
                offset,
            };
            for _ in 0..src.skip_lines {
                if !s.next_line()? {
                    return Err(ImportError::in_file(
                        ErrorKind::Cell,
                        &s.name,
                        &format!("ends before the {} lines to skip", src.skip_lines),
                        "check source.skip_lines in the map",
                    ));
                }
            }
            if src.header {
                if !s.next_row()? {
                    return Err(ImportError::in_file(
                        ErrorKind::Cell,
                        &s.name,
                        "has no header line",
                        "the first line after source.skip_lines names the columns \
                         (or write `header: none`)",
                    ));
                }
                for c in &s.cells {
                    let (t, _, _) = src.encoding.decode(&s.buf[c.clone()]);
                    names.push(unquote(t.trim()).to_string());
                }
                s.width = Some(s.cells.len());
                offset += s.cells.len();
            } else {
                // Width from the first data row, read on demand.
                offset = usize::MAX;
            }
            sources.push(s);
        }
        if !src.header && sources.len() > 1 {
            // Columns by index over several header-less files: peek each file's width.
            let mut off = 0;
            for s in &mut sources {
                s.offset = off;
                let w = peek_width(&s.name, src)?;
                s.width = Some(w);
                off += w;
            }
        } else if !src.header {
            sources[0].offset = 0;
        }
        let mut slots = Vec::with_capacity(cols.len());
        for c in cols {
            if let ColRef::Name(n) = &c.col {
                ambiguous(&names, n, map, &c.at)?;
            }
            let g = match &c.col {
                ColRef::Index(i) => *i,
                ColRef::Name(n) => names.iter().position(|h| h == n.trim()).ok_or_else(|| {
                    let close = names
                        .iter()
                        .find(|h| h.eq_ignore_ascii_case(n.trim()))
                        .map(|h| format!("did you mean `{h}`? "))
                        .unwrap_or_default();
                    ImportError::in_text(
                        ErrorKind::Map,
                        &map.file,
                        &map.text,
                        c.at.clone(),
                        Say {
                            what: &format!("no column `{n}` in the sources' header"),
                            label: "not in the header",
                            help: &format!("{close}the header has: {}", names.join(", ")),
                        },
                    )
                })?,
            };
            slots.push(g);
        }
        let local = slots
            .iter()
            .map(|&g| {
                let k = sources.iter().rposition(|s| s.offset <= g).unwrap_or(0);
                (k, g - sources[k].offset)
            })
            .collect();
        Ok(Rows {
            sources,
            slots,
            local,
            sample: 0,
            mat: None,
        })
    }

    /// Reads the next row's slots into `out`; `None` at the end of the sources.
    pub fn next(&mut self, out: &mut [f64]) -> Res<Option<RowAt>> {
        if self.mat.is_some() {
            return self.next_mat(out);
        }
        let mut ended = None;
        for (k, s) in self.sources.iter_mut().enumerate() {
            let more = s.next_row()?;
            if k == 0 {
                ended = Some(!more);
            } else if ended != Some(!more) {
                let (a, b) = (&self.sources[0], &self.sources[k]);
                return Err(ImportError::in_file(
                    ErrorKind::Cell,
                    &b.name,
                    &format!(
                        "has {} rows than {} (line {} of {}, line {} of this file)",
                        if more { "more" } else { "fewer" },
                        a.name,
                        a.line,
                        a.name,
                        b.line
                    ),
                    "sources given together are read side by side: one sample per row in each",
                ));
            }
        }
        if ended == Some(true) {
            return Ok(None);
        }
        for s in &self.sources {
            extra_cells(s)?;
        }
        for (slot, &(k, c)) in self.local.iter().enumerate() {
            let s = &self.sources[k];
            let Some(r) = s.cells.get(c) else {
                let what = format!(
                    "this row has {} columns; the map asks for column {} (0-based {})",
                    s.cells.len(),
                    c + 1,
                    self.slots[slot]
                );
                return Err(s.error(
                    s.buf.len()..s.buf.len(),
                    ErrorKind::Cell,
                    &what,
                    "every row needs the columns the map names; check source.delimiter and \
                     source.skip_lines",
                ));
            };
            out[slot] = parse_cell(s, r.clone())?;
        }
        let at = RowAt {
            sample: self.sample,
            line: self.sources[0].line,
        };
        self.sample += 1;
        Ok(Some(at))
    }

    /// Each source's SHA-256 (lowercase hex) once they were read to the end.
    pub fn finish(&mut self) -> Vec<String> {
        if let Some(m) = &self.mat {
            return vec![m.sha256.clone()];
        }
        self.sources
            .iter_mut()
            .map(|s| {
                // Whatever follows the last row (nothing, at the end of the rows).
                let _ = std::io::copy(&mut s.r, &mut std::io::sink());
                hex::encode(s.r.get_ref().hash.clone().finalize())
            })
            .collect()
    }

    /// The first source's name.
    pub fn name(&self) -> &str {
        match &self.mat {
            Some(m) => &m.name,
            None => &self.sources[0].name,
        }
    }

    /// An error at slot `slot` of the row just read.
    pub fn cell_error(
        &self,
        slot: usize,
        kind: ErrorKind,
        what: &str,
        help: &str,
    ) -> Box<ImportError> {
        let (k, c) = self.local[slot];
        if let Some(m) = &self.mat {
            return mat_cell_error(m, self.sample.saturating_sub(1) as usize, c, what, help);
        }
        let s = &self.sources[k];
        let r = s.cells.get(c).cloned().unwrap_or(0..0);
        s.error(r, kind, what, help)
    }
}

/// An error at a column the map names.
pub(super) fn map_error(map: &ImportMap, c: &Col, what: &str, help: &str) -> Box<ImportError> {
    ImportError::in_text(
        ErrorKind::Map,
        &map.file,
        &map.text,
        c.at.clone(),
        Say {
            what,
            label: "this column",
            help,
        },
    )
}

fn parse_cell(s: &LineSource, r: Range<usize>) -> Res<f64> {
    let raw = &s.buf[r.clone()];
    let text = std::str::from_utf8(raw).ok().map(|t| unquote(t.trim()));
    match text.map(str::parse::<f64>) {
        Some(Ok(v)) if v.is_finite() => Ok(v),
        Some(Ok(_)) => Err(s.error(
            r,
            ErrorKind::Cell,
            "not a finite number (NaN or infinite)",
            "the importer does not fill gaps: remove or repair the row in the source",
        )),
        _ => Err(s.error(
            r,
            ErrorKind::Cell,
            &format!("`{}` is not a number", snippet(raw)),
            "check source.skip_lines and source.header (a header or metadata line read as \
             data?) and source.delimiter",
        )),
    }
}

/// At most [`SNIPPET`] characters of `raw` for a diagnostic, `...` marking a cut.
fn snippet(raw: &[u8]) -> String {
    let text = String::from_utf8_lossy(&raw[..raw.len().min(4 * SNIPPET)]);
    let mut out: String = text.chars().take(SNIPPET).collect();
    if out.len() < raw.len() {
        out.push_str("...");
    }
    out
}

/// The most characters of a cell a diagnostic quotes.
const SNIPPET: usize = 40;

/// The longest line a source may hold, bytes: a row of numbers is a few hundred; a file
/// with no line break is refused at this length, never read whole.
pub const MAX_LINE: usize = 1 << 20;

/// Refuses a row with more cells than its source's header names (empty ones from a
/// trailing delimiter aside): its values belong to no column, and the row may be two run
/// together or shifted.
fn extra_cells(s: &LineSource) -> Res<()> {
    let Some(w) = s.width else {
        return Ok(());
    };
    let Some(first) =
        (s.cells.iter().skip(w)).find(|r| !s.buf[(*r).clone()].trim_ascii().is_empty())
    else {
        return Ok(());
    };
    let what = format!(
        "this row has {} cells; the header names {w} columns",
        s.cells.len()
    );
    Err(s.error(
        first.clone(),
        ErrorKind::Cell,
        &what,
        "every row has one cell per header column; check source.delimiter, or the line \
         for two rows run together",
    ))
}

/// Refuses a header name `n` that names more than one column: which one is meant is not
/// the map's to guess.
fn ambiguous(names: &[String], n: &str, map: &ImportMap, at: &Range<usize>) -> Res<()> {
    let hits: Vec<String> = (names.iter().enumerate())
        .filter(|(_, h)| *h == n.trim())
        .map(|(i, _)| i.to_string())
        .collect();
    if hits.len() < 2 {
        return Ok(());
    }
    Err(ImportError::in_text(
        ErrorKind::Map,
        &map.file,
        &map.text,
        at.clone(),
        Say {
            what: &format!(
                "column `{n}` names {} columns of the sources' header (0-based {})",
                hits.len(),
                hits.join(", ")
            ),
            label: "more than one column",
            help: &format!(
                "name the column by its 0-based index instead (e.g. `{}`), or rename one in \
                 the header",
                hits[0]
            ),
        },
    ))
}

fn unquote(t: &str) -> &str {
    t.strip_prefix('"')
        .and_then(|x| x.strip_suffix('"'))
        .unwrap_or(t)
}

/// Cells in the first data row of a header-less source.
fn peek_width(name: &str, src: &SourceSpec) -> Res<usize> {
    let f = File::open(name).map_err(|e| io_error(name, &e))?;
    let mut s = LineSource {
        name: name.to_string(),
        r: BufReader::new(Hashing {
            inner: f,
            hash: Sha256::new(),
        }),
        buf: Vec::new(),
        line: 0,
        delim: src.delimiter,
        cells: Vec::new(),
        width: None,
        offset: 0,
    };
    for _ in 0..src.skip_lines {
        s.next_line()?;
    }
    s.next_row()?;
    Ok(s.cells.len())
}

/// An IO error naming the file.
pub fn io_error(name: &str, e: &std::io::Error) -> Box<ImportError> {
    ImportError::in_file(
        ErrorKind::Io,
        name,
        &format!("cannot read: {e}"),
        "check the path and its permissions",
    )
}
