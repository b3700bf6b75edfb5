//! Splitting a line into cells.

use crate::map::Delimiter;
use std::ops::Range;

/// The delimiter a line uses: tab, `;`, `,`, else runs of whitespace.
pub fn sniff(line: &[u8]) -> Delimiter {
    for d in [b'\t', b';', b','] {
        if line.contains(&d) {
            return Delimiter::Byte(d);
        }
    }
    Delimiter::Whitespace
}

/// The cells of `line` as byte ranges (into `out`, cleared first).
pub fn split_cells(line: &[u8], delim: Delimiter, out: &mut Vec<Range<usize>>) {
    out.clear();
    match delim {
        Delimiter::Byte(d) => {
            let mut start = 0;
            for (i, &b) in line.iter().enumerate() {
                if b == d {
                    out.push(start..i);
                    start = i + 1;
                }
            }
            out.push(start..line.len());
        }
        Delimiter::Whitespace | Delimiter::Auto => {
            let mut start = None;
            for (i, &b) in line.iter().enumerate() {
                let ws = b == b' ' || b == b'\t';
                match (ws, start) {
                    (false, None) => start = Some(i),
                    (true, Some(s)) => {
                        out.push(s..i);
                        start = None;
                    }
                    _ => {}
                }
            }
            if let Some(s) = start {
                out.push(s..line.len());
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cells(line: &str, d: Delimiter) -> Vec<&str> {
        let mut v = Vec::new();
        split_cells(line.as_bytes(), d, &mut v);
        v.into_iter().map(|r| &line[r]).collect()
    }

    #[test]
    fn delimiters_and_whitespace() {
        assert_eq!(cells("a,b,,c", Delimiter::Byte(b',')), ["a", "b", "", "c"]);
        assert_eq!(
            cells("   2.98e-02   3.3108e+04\t1", Delimiter::Whitespace),
            ["2.98e-02", "3.3108e+04", "1"]
        );
        assert_eq!(sniff(b"Fs,100"), Delimiter::Byte(b','));
        assert_eq!(sniff(b"1;2,5"), Delimiter::Byte(b';'));
        assert_eq!(sniff(b" 1  2"), Delimiter::Whitespace);
    }
}
