//! The fast path for imu.csv and table.csv: the file streamed through a small reused
//! buffer (never held whole), split in byte ranges parsed on two threads, each cell
//! converted while it is split, straight into the stream's own layout.
//!
//! It handles what acquisition systems write: unquoted numeric cells, one record a line,
//! blank lines, CRLF. Anything else (a quote, a ragged row, a cell that is not a number)
//! makes it give up, and the exact reader (`csvread`, the csv crate) reads the file again
//! to accept it or to locate the problem.

use super::csvread::{column_name, parse_f64};
use super::number::number;
use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::path::Path;

/// Most columns kept from one file.
pub(crate) const MAX_SLOTS: usize = 8;
/// Read buffer size.
const CHUNK: usize = 1 << 20;

/// Why the fast path gave up; the exact reader takes over.
#[derive(Debug)]
pub(crate) struct GiveUp;

/// Where the wanted columns are: `want[field]` is the slot a field fills, or `SKIP`.
#[derive(Debug, Clone)]
pub(crate) struct Layout {
    pub want: Vec<usize>,
    /// Byte offset of the first data line (after the header).
    pub data_start: u64,
    /// Whether the cells after the last wanted one are left unread (the index's time-only
    /// pass: those cells are checked when a span holding them is read).
    pub lazy_tail: bool,
}

impl Layout {
    /// A layout that reads the wanted fields and checks every line's cells.
    pub(crate) fn new(want: Vec<usize>, data_start: u64) -> Self {
        Layout {
            want,
            data_start,
            lazy_tail: false,
        }
    }

    /// This layout reading only the cells of `slots` (the others skipped, the cells after
    /// the last one read left unread): a pass over a few columns of every line.
    pub(crate) fn only(&self, slots: &[usize]) -> Layout {
        let want = self.want.iter();
        Layout {
            want: want
                .map(|&w| if slots.contains(&w) { w } else { SKIP })
                .collect(),
            data_start: self.data_start,
            lazy_tail: true,
        }
    }
}

pub(crate) const SKIP: usize = usize::MAX;

/// Receives parsed rows (the wanted cells in slot order).
pub(crate) trait RowSink: Send {
    fn push(&mut self, row: &[f64; MAX_SLOTS]);
    /// Whether the next row (a line that is not blank) is wanted: one that is not is
    /// passed over unread, only its end found, and not pushed.
    #[inline]
    fn wants(&mut self) -> bool {
        true
    }
}

/// Reads the header line of `path`: field names, and the offset after it.
pub(crate) fn header(path: &Path) -> std::io::Result<(Vec<String>, u64)> {
    let mut f = File::open(path)?;
    let mut buf = Vec::with_capacity(4096);
    let mut chunk = [0u8; 4096];
    loop {
        let n = f.read(&mut chunk)?;
        buf.extend_from_slice(&chunk[..n]);
        if let Some(p) = buf.iter().position(|&b| b == b'\n') {
            buf.truncate(p + 1);
            break;
        }
        if n == 0 || buf.len() > 1 << 20 {
            break;
        }
    }
    let len = buf.len() as u64;
    let line = buf.strip_suffix(b"\n").unwrap_or(&buf);
    let line = line.strip_suffix(b"\r").unwrap_or(line);
    let names = line.split(|&b| b == b',').map(column_name).collect();
    Ok((names, len))
}

/// Lines per byte of the data of `path` (from `data_start` to `len`): the denser of a block
/// at its start and one in its middle (the time column widens as the run goes on, and an
/// estimate that errs high costs address space, not memory); 0 when nothing can be read.
pub(crate) fn line_density(path: &Path, data_start: u64, len: u64) -> f64 {
    const SAMPLE: u64 = 64 * 1024;
    let Ok(mut f) = File::open(path) else {
        return 0.0;
    };
    let mut buf = Vec::with_capacity(SAMPLE as usize);
    let mut density = |from: u64| -> f64 {
        buf.clear();
        let n = f
            .seek(SeekFrom::Start(from))
            .and_then(|_| (&mut f).take(SAMPLE).read_to_end(&mut buf));
        match n {
            Ok(n) if n > 0 => buf.iter().filter(|&&b| b == b'\n').count() as f64 / n as f64,
            _ => 0.0,
        }
    };
    let middle = data_start + len.saturating_sub(data_start).saturating_sub(SAMPLE) / 2;
    density(data_start).max(density(middle))
}

/// Rows to reserve for `bytes` of data at `density` lines per byte: a little over the
/// estimate (capacity never touched costs address space, not memory).
pub(crate) fn rows_for(density: f64, bytes: u64) -> usize {
    ((bytes as f64 * density * 1.02) as usize + 16).min(bytes as usize / 2 + 16)
}

/// Parses the rows of `path` whose line starts at a byte offset in `[start, end)`.
/// A range that starts mid-line begins at the next line.
pub(crate) fn scan_range<S: RowSink>(
    path: &Path,
    layout: &Layout,
    start: u64,
    end: u64,
    sink: &mut S,
) -> Result<(), GiveUp> {
    let mut f = File::open(path).map_err(|_| GiveUp)?;
    // Start one byte early: if that byte ends a line, the range starts on a line start.
    let from = if start > layout.data_start {
        start - 1
    } else {
        start
    };
    f.seek(SeekFrom::Start(from)).map_err(|_| GiveUp)?;
    // A short range (a time span, an index block) needs no more than itself and the end
    // of its last line; the buffer grows if a line is longer.
    let wanted = end.saturating_sub(from).saturating_add(4096);
    let mut buf = vec![0u8; CHUNK.min(wanted as usize)];
    let mut filled = 0;
    let mut base = from; // file offset of buf[0]
    let mut skip_partial = from < start;
    let mut eof = false;
    loop {
        if !eof {
            while filled < buf.len() {
                let n = f.read(&mut buf[filled..]).map_err(|_| GiveUp)?;
                if n == 0 {
                    eof = true;
                    break;
                }
                filled += n;
            }
        }
        let mut pos = 0;
        if skip_partial {
            match memchr(b'\n', &buf[..filled]) {
                Some(p) => {
                    pos = p + 1;
                    skip_partial = false;
                }
                None if eof => return Ok(()),
                None => {
                    // A line longer than the buffer: drop it and keep looking.
                    base += filled as u64;
                    filled = 0;
                    continue;
                }
            }
        }
        // Whole lines in the buffer (all of it at the end of the file).
        let upto = if eof {
            filled
        } else {
            match buf[pos..filled].iter().rposition(|&b| b == b'\n') {
                Some(p) => pos + p + 1,
                None => {
                    // A line far longer than a sample's: the exact reader refuses it,
                    // located, without this buffer growing to the size of the file.
                    if filled - pos > super::lines::MAX_LINE {
                        return Err(GiveUp);
                    }
                    // One line fills the buffer: grow it.
                    if pos > 0 {
                        buf.copy_within(pos..filled, 0);
                        base += pos as u64;
                        filled -= pos;
                    }
                    buf.resize(buf.len() * 2, 0);
                    continue;
                }
            }
        };
        let limit = end.saturating_sub(base).min(upto as u64) as usize;
        let stop = parse_lines(&buf[..upto], pos, limit, layout, sink)?;
        if stop || eof {
            return Ok(());
        }
        buf.copy_within(upto..filled, 0);
        base += upto as u64;
        filled -= upto;
    }
}

/// Parses the lines of `buf` that start in `[pos, limit)`; `buf` ends at a line end (or
/// the end of the file). True when a line starting at or after `limit` was reached.
fn parse_lines<S: RowSink>(
    buf: &[u8],
    mut pos: usize,
    limit: usize,
    layout: &Layout,
    sink: &mut S,
) -> Result<bool, GiveUp> {
    let width = layout.want.len();
    let last_wanted = layout.want.iter().rposition(|&w| w != SKIP);
    let tail_from = if layout.lazy_tail { last_wanted } else { None };
    let mut row = [0.0f64; MAX_SLOTS];
    while pos < buf.len() {
        if pos >= limit {
            return Ok(true);
        }
        // Blank (whitespace-only) lines are skipped, as the exact reader does.
        let first = buf[pos];
        if first == b'\n' || first == b'\r' || first == b' ' || first == b'\t' {
            let e = memchr(b'\n', &buf[pos..]).map_or(buf.len(), |p| pos + p);
            if buf[pos..e].iter().all(u8::is_ascii_whitespace) {
                pos = e + 1;
                continue;
            }
        }
        if !sink.wants() {
            pos = memchr(b'\n', &buf[pos..]).map_or(buf.len(), |p| pos + p + 1);
            continue;
        }
        let mut field = 0;
        loop {
            let slot = if field < width {
                layout.want[field]
            } else {
                return Err(GiveUp); // more fields than the header
            };
            let (v, next) = if slot == SKIP {
                (0.0, skip_field(buf, pos).ok_or(GiveUp)?)
            } else {
                match number(buf, pos) {
                    Some(x) => x,
                    None => {
                        let e = skip_field(buf, pos).ok_or(GiveUp)?;
                        let v = parse_f64(trim_cr(&buf[pos..e])).ok_or(GiveUp)?;
                        (v, e)
                    }
                }
            };
            if slot != SKIP {
                row[slot] = v;
            }
            if tail_from == Some(field) {
                // The rest of the line unread: on to the next one.
                field = width;
                pos = match memchr::memchr(b'\n', &buf[next..]) {
                    Some(p) => next + p + 1,
                    None => buf.len(),
                };
                break;
            }
            field += 1;
            match buf.get(next) {
                Some(b',') => pos = next + 1,
                Some(b'\r') if buf.get(next + 1).is_none_or(|&b| b == b'\n') => {
                    pos = next + 2;
                    break;
                }
                Some(b'\n') | None => {
                    pos = next + 1;
                    break;
                }
                Some(_) => return Err(GiveUp),
            }
        }
        if field != width {
            return Err(GiveUp);
        }
        sink.push(&row);
    }
    Ok(false)
}

fn trim_cr(b: &[u8]) -> &[u8] {
    b.strip_suffix(b"\r").unwrap_or(b)
}

/// End of the field starting at `pos` (a `,`, a line end, or the end of `buf`); `None`
/// at a quote, which only the exact reader understands.
#[inline]
fn skip_field(buf: &[u8], mut pos: usize) -> Option<usize> {
    while pos < buf.len() {
        match buf[pos] {
            b',' | b'\n' => return Some(pos),
            b'\r' if buf.get(pos + 1).is_none_or(|&b| b == b'\n') => return Some(pos),
            b'"' => return None,
            _ => pos += 1,
        }
    }
    Some(pos)
}

fn memchr(needle: u8, hay: &[u8]) -> Option<usize> {
    memchr::memchr(needle, hay)
}

/// Splits `sizes` bytes of work over two threads: byte offsets in the first file where
/// the first part ends, so that both parts are about the same size.
pub(crate) fn split_point(first: (u64, u64), second_len: u64) -> u64 {
    let (start, end) = first;
    let total = (end - start) + second_len;
    (start + total / 2).min(end)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Default)]
    struct Rows(Vec<Vec<f64>>, usize);
    impl RowSink for Rows {
        fn push(&mut self, row: &[f64; MAX_SLOTS]) {
            self.0.push(row[..self.1].to_vec());
        }
    }

    impl Rows {
        fn append(&mut self, other: Self) {
            self.0.extend(other.0);
        }
    }

    fn scan_text(text: &str, chunks_at: u64) -> Result<Vec<Vec<f64>>, GiveUp> {
        let dir = std::env::temp_dir().join(format!(
            "ratecal-scan-{}-{}",
            std::process::id(),
            text.len() as u64 * 31 + chunks_at
        ));
        std::fs::write(&dir, text).unwrap();
        let (names, data_start) = header(&dir).unwrap();
        let want = names
            .iter()
            .map(|n| match n.as_str() {
                "t" => 0,
                "a" => 1,
                _ => SKIP,
            })
            .collect();
        let layout = Layout::new(want, data_start);
        let len = text.len() as u64;
        let mid = chunks_at.clamp(data_start, len);
        let mut a = Rows(Vec::new(), 2);
        let mut b = Rows(Vec::new(), 2);
        let r = scan_range(&dir, &layout, data_start, mid, &mut a)
            .and_then(|_| scan_range(&dir, &layout, mid, len, &mut b));
        std::fs::remove_file(&dir).ok();
        r?;
        a.append(b);
        Ok(a.0)
    }

    #[test]
    fn every_split_point_gives_the_same_rows() {
        let text = "t,x,a\n0.5,q,-1.25\n\n1,w,2e3\r\n  \n1.5,e,+3\n2,r,4";
        let want = vec![
            vec![0.5, -1.25],
            vec![1.0, 2000.0],
            vec![1.5, 3.0],
            vec![2.0, 4.0],
        ];
        for cut in 0..=text.len() as u64 {
            assert_eq!(scan_text(text, cut).unwrap(), want, "cut at {cut}");
        }
    }

    /// The reserve covers the rows without doubling them, even in a file whose time column
    /// widens by a fifth (short lines first, long lines last).
    #[test]
    fn rows_are_estimated_from_the_middle_of_the_file() {
        let mut text = String::from("t,a\n");
        let n = 200_000;
        for i in 0..n {
            text += &format!("{:.3},1.5\n", i as f64 * 0.001);
        }
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.csv");
        std::fs::write(&path, &text).unwrap();
        let start = 4;
        let len = text.len() as u64;
        let rows = rows_for(line_density(&path, start, len), len - start);
        assert!(rows >= n, "{rows} < {n}");
        assert!(rows <= n + n / 4, "{rows} rows reserved for {n}");
        // Unreadable or line-less data reserves next to nothing.
        assert_eq!(
            rows_for(line_density(&dir.path().join("absent"), 0, 100), 100),
            16
        );
    }

    #[test]
    fn unusual_input_gives_up() {
        for text in [
            "t,x,a\n1,\"q\",2\n",
            "t,x,a\n1,q\n",
            "t,x,a\n1,q,2,3\n",
            "t,x,a\n1,q,abc\n",
        ] {
            assert!(scan_text(text, 0).is_err(), "{text:?}");
        }
    }
}
