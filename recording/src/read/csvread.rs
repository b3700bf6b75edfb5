//! The exact CSV reader for imu.csv and table.csv (the csv crate, one reused `ByteRecord`):
//! it accepts what the fast path (`scan`) gives up on, and locates every problem.

// A refused recording is built once per read: the error's size costs nothing.
#![allow(clippy::result_large_err)]

use crate::error::{RecordingError, empty_stream, line_col_bytes};
use crate::excerpt::{Excerpt, short};
use std::ops::Range;

/// Columns of one CSV file, in the order they were asked for; `None` for an absent
/// optional column.
pub(crate) struct Columns {
    /// Data per asked column.
    pub cols: Vec<Option<Vec<f64>>>,
}

/// Reads `bytes` (the text of `file`) keeping `required` and `optional` columns by name.
/// Extra columns are allowed and skipped.
pub(crate) fn read_columns(
    file: &str,
    bytes: &[u8],
    required: &[&str],
    optional: &[&str],
) -> Result<Columns, RecordingError> {
    read_rows(file, bytes, None, required, optional, |_| {})
}

/// `read_columns` of the records that start in `data` (a range of record starts, after the
/// header; all of them for `None`), located in the whole of `bytes`; `on_row` gets each
/// kept record's start.
pub(crate) fn read_rows(
    file: &str,
    bytes: &[u8],
    data: Option<Range<usize>>,
    required: &[&str],
    optional: &[&str],
    mut on_row: impl FnMut(usize),
) -> Result<Columns, RecordingError> {
    let mut rdr = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .from_reader(bytes);
    let mut rec = csv::ByteRecord::new();
    let src = |start: usize, end: usize| Excerpt::around(file, bytes, start, end);
    let header_ok = rdr.read_byte_record(&mut rec).map_err(|e| io(file, e))?;
    if !header_ok {
        return Err(empty_stream(file, bytes));
    }
    let names: Vec<String> = rec.iter().map(column_name).collect();
    let header_len = bytes
        .iter()
        .position(|&b| b == b'\n')
        .unwrap_or(bytes.len());
    let mut idx = Vec::with_capacity(required.len() + optional.len());
    for &c in required {
        match names.iter().position(|n| n == c) {
            Some(i) => idx.push(Some(i)),
            None => {
                let (src, span) = src(0, header_len);
                return Err(RecordingError::MissingColumn {
                    file: file.to_string(),
                    column: c.to_string(),
                    required: required.join(", "),
                    found: short(&names.join(", "), 200),
                    src,
                    span,
                });
            }
        }
    }
    for &c in optional {
        idx.push(names.iter().position(|n| n == c));
    }
    // Records from `data.start` on: a reader of their bytes, positions shifted back.
    let base = data.as_ref().map_or(0, |d| d.start);
    if let Some(d) = &data {
        rdr = csv::ReaderBuilder::new()
            .has_headers(false)
            .flexible(true)
            .from_reader(&bytes[d.start.min(bytes.len())..d.end.min(bytes.len())]);
    }
    // Rough row count from the byte size, to allocate once.
    let size = data.as_ref().map_or(bytes.len(), |d| d.len());
    let guess = size / (header_len.max(8) + 1) + 16;
    let mut cols: Vec<Option<Vec<f64>>> = idx
        .iter()
        .map(|i| i.map(|_| Vec::with_capacity(guess)))
        .collect();
    let width = names.len();
    while rdr.read_byte_record(&mut rec).map_err(|e| io(file, e))? {
        let pos = base + rec.position().expect("csv records carry positions").byte() as usize;
        if rec.len() != width {
            if rec.len() == 1
                && rec
                    .get(0)
                    .is_some_and(|f| f.iter().all(u8::is_ascii_whitespace))
            {
                continue; // blank line
            }
            let start = record_start(bytes, pos);
            let end = bytes[start..]
                .iter()
                .position(|&b| b == b'\n' || b == b'\r')
                .map_or(bytes.len(), |p| start + p);
            let (src, span) = src(start, end);
            return Err(RecordingError::RaggedRow {
                file: file.to_string(),
                line: line_col_bytes(bytes, start).0,
                found: rec.len(),
                expected: width,
                src,
                span,
            });
        }
        for (k, i) in idx.iter().enumerate() {
            let Some(i) = *i else { continue };
            let cell = &rec[i];
            match parse_f64(cell) {
                Some(v) => cols[k].as_mut().expect("present column").push(v),
                None => {
                    let start = record_start(bytes, pos);
                    let (offset, column) = cell_offset(bytes, start, i);
                    let end = (offset + cell.len().max(1)).min(bytes.len());
                    let (src, span) = src(offset, end);
                    return Err(RecordingError::NotANumber {
                        file: file.to_string(),
                        line: line_col_bytes(bytes, start).0,
                        column,
                        name: short(&names[i], 60),
                        cell: short(&String::from_utf8_lossy(cell), 60),
                        src,
                        span,
                    });
                }
            }
        }
        on_row(record_start(bytes, pos));
    }
    Ok(Columns { cols })
}

fn io(file: &str, e: csv::Error) -> RecordingError {
    RecordingError::Io {
        file: file.to_string(),
        message: e.to_string(),
    }
}

/// Where the record at byte `pos` starts. After a CR the csv crate may put a record's
/// start on the line-end bytes that follow it (the LF of a CRLF, the second CR of a CR CR
/// LF): a record never starts with a line end, so the row starts after them.
fn record_start(bytes: &[u8], pos: usize) -> usize {
    let start = pos.min(bytes.len());
    start
        + bytes[start..]
            .iter()
            .take_while(|&&b| b == b'\r' || b == b'\n')
            .count()
}

/// Byte offset where data row `row` starts (0-based, after the header, blank lines not
/// counted), rows split as the exact reader splits them; the end of `bytes` past the last.
pub(crate) fn row_start(bytes: &[u8], row: usize) -> usize {
    let mut rdr = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .from_reader(bytes);
    let mut rec = csv::ByteRecord::new();
    let mut seen = 0;
    let mut header = true;
    while let Ok(true) = rdr.read_byte_record(&mut rec) {
        let blank = rec.len() == 1 && rec[0].iter().all(u8::is_ascii_whitespace);
        if std::mem::take(&mut header) || blank {
            continue;
        }
        if seen == row {
            let pos = rec.position().expect("csv records carry positions");
            return record_start(bytes, pos.byte() as usize);
        }
        seen += 1;
    }
    bytes.len()
}

/// A header cell as a column name: trimmed, without the byte-order mark that spreadsheet
/// programs put before the first one.
pub(crate) fn column_name(cell: &[u8]) -> String {
    let name = String::from_utf8_lossy(cell);
    name.trim()
        .trim_start_matches('\u{feff}')
        .trim()
        .to_string()
}

/// Byte offset and 1-based character column of field `field` of the line starting at `start`.
pub(crate) fn cell_offset(bytes: &[u8], start: usize, field: usize) -> (usize, usize) {
    let mut off = start;
    for _ in 0..field {
        match bytes[off..].iter().position(|&b| b == b',') {
            Some(p) => off += p + 1,
            None => break,
        }
    }
    let column = String::from_utf8_lossy(&bytes[start..off]).chars().count() + 1;
    (off, column)
}

/// Parses a finite decimal number. Short decimals (up to 19 significant digits, exponent
/// within 10^±22 after scaling) take Clinger's exact fast path: an integer mantissa below
/// 2^53 divided or multiplied by an exact power of ten rounds once, so the result is the
/// correctly rounded value, as `str::parse` would give. Everything else falls back to it.
#[inline]
pub(crate) fn parse_f64(cell: &[u8]) -> Option<f64> {
    fast(cell).or_else(|| {
        let b = cell.trim_ascii();
        let v: f64 = std::str::from_utf8(b).ok()?.parse().ok()?;
        v.is_finite().then_some(v)
    })
}

const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

fn fast(b: &[u8]) -> Option<f64> {
    let (neg, b) = match b.first()? {
        b'-' => (true, &b[1..]),
        b'+' => (false, &b[1..]),
        _ => (false, b),
    };
    let mut mant: u64 = 0;
    let mut i = 0;
    // Integer part, then fraction; every digit counts towards the 19 that fit a u64
    // (leading zeros too: rare, and the exact fallback handles them). Past 19 it wraps, and
    // the count sends the cell to the fallback.
    while i < b.len() && b[i].is_ascii_digit() {
        mant = mant.wrapping_mul(10).wrapping_add(u64::from(b[i] - b'0'));
        i += 1;
    }
    let int_digits = i;
    let mut frac = 0usize;
    if i < b.len() && b[i] == b'.' {
        i += 1;
        let s = i;
        while i < b.len() && b[i].is_ascii_digit() {
            mant = mant.wrapping_mul(10).wrapping_add(u64::from(b[i] - b'0'));
            i += 1;
        }
        frac = i - s;
    }
    let digits = int_digits + frac;
    if digits == 0 || digits > 19 {
        return None;
    }
    let mut exp: i32 = 0;
    if i < b.len() && (b[i] == b'e' || b[i] == b'E') {
        i += 1;
        let eneg = match b.get(i) {
            Some(b'-') => {
                i += 1;
                true
            }
            Some(b'+') => {
                i += 1;
                false
            }
            _ => false,
        };
        let s = i;
        while i < b.len() && b[i].is_ascii_digit() && i - s < 4 {
            exp = exp * 10 + i32::from(b[i] - b'0');
            i += 1;
        }
        if i == s {
            return None;
        }
        if eneg {
            exp = -exp;
        }
    }
    if i != b.len() || mant > (1u64 << 53) {
        return None;
    }
    let e = exp - frac as i32;
    let m = mant as f64;
    let v = match e {
        0 => m,
        1..=22 => m * POW10[e as usize],
        -22..=-1 => m / POW10[(-e) as usize],
        _ => return None,
    };
    Some(if neg { -v } else { v })
}

#[cfg(test)]
mod tests {
    use super::parse_f64;

    #[test]
    fn fast_path_matches_std() {
        for s in [
            "0",
            "-0.013975",
            "9.788327",
            "22.000",
            "1e-3",
            "-1.5E+2",
            "0.0000001",
            "123456789.123456",
            "3.14159265358979",
            "-100.0",
            "0.1",
            "17",
            "2.5e-7",
            "12345678901234567890.5",
            "1e300",
        ] {
            let want: f64 = s.parse().unwrap();
            assert_eq!(
                parse_f64(s.as_bytes()).unwrap().to_bits(),
                want.to_bits(),
                "{s}"
            );
        }
        for s in ["", "-", "abc", "1.2.3", "1e", "nan", "inf", "1,5", "--1"] {
            assert!(parse_f64(s.as_bytes()).is_none(), "{s}");
        }
    }

    /// More digits than a u64 holds: the mantissa wraps (debug builds used to panic on
    /// the overflowing add) and the exact fallback converts.
    #[test]
    fn long_digit_strings_fall_back() {
        for s in [
            "99999999999999999999999999999999999999999",
            "18446744073709551616",
            "0.99999999999999999999999999999999999999999",
            "-7777777777777777777777777777777.77777777777777777777777777777",
        ] {
            let want: f64 = s.parse().unwrap();
            assert_eq!(parse_f64(s.as_bytes()), Some(want), "{s}");
        }
    }
}
