//! What a diagnostic shows of a file: the line of the problem and one line either side,
//! each cut to a few hundred bytes around the problem, control bytes and invalid UTF-8
//! escaped (`\0`, `\x1b`). A NUL-filled or newline-less file of gigabytes is reported in a
//! few hundred bytes, and never writes raw control bytes to a terminal. Line numbers are
//! the file's.

use miette::{MietteError, MietteSpanContents, SourceCode, SourceSpan, SpanContents};

/// Bytes shown before a problem on its line, and after its (cut) end.
const AROUND: usize = 48;
/// Bytes of the problem itself shown at most.
const SPAN_MAX: usize = 64;
/// Bytes of a context line shown at most.
const CONTEXT_MAX: usize = 120;
/// A line up to this long is shown whole.
const LINE_MAX: usize = 320;

/// A few escaped lines of a file, with the file's line number of the first.
#[derive(Debug, Clone)]
pub struct Excerpt {
    name: String,
    text: String,
    /// 0-based line of the file where `text` starts.
    first_line: usize,
}

impl Excerpt {
    /// The excerpt of `bytes` (a whole file) around `bytes[start..end]`, and that range's
    /// span in it.
    pub fn around(name: &str, bytes: &[u8], start: usize, end: usize) -> (Self, SourceSpan) {
        Self::around_at(name, bytes, 0, start, end)
    }

    /// As [`Excerpt::around`] for `bytes`, a part of a file that starts at 0-based line
    /// `line_base`.
    pub fn around_at(
        name: &str,
        bytes: &[u8],
        line_base: usize,
        start: usize,
        end: usize,
    ) -> (Self, SourceSpan) {
        let start = start.min(bytes.len());
        let end = end.clamp(start, bytes.len());
        let ls = line_start(bytes, start);
        let le = line_end(bytes, start);
        let line = line_base + line_breaks(&bytes[..ls]);
        let mut text = String::new();
        let mut first_line = line;
        if ls > 0 {
            // The line before, shown from its start.
            let pe = if ls >= 2 && bytes[ls - 1] == b'\n' && bytes[ls - 2] == b'\r' {
                ls - 2
            } else {
                ls - 1
            };
            let ps = line_start(bytes, pe);
            push_cut(&mut text, bytes, ps, pe, ps, context_end(ps, pe), None);
            text.push('\n');
            first_line = line - 1;
        }
        let (span_end, from, to) = if le - ls <= LINE_MAX {
            (end, ls, le)
        } else {
            let span_end = end.min(start + SPAN_MAX);
            let from = start.saturating_sub(AROUND).max(ls);
            (span_end, from, (span_end.max(start + 1) + AROUND).min(le))
        };
        let mut at = (0, 0);
        push_cut(
            &mut text,
            bytes,
            ls,
            le,
            from,
            to.max(from),
            Some((start, span_end, &mut at)),
        );
        if le < bytes.len() {
            let ns = if bytes[le] == b'\r' && bytes.get(le + 1) == Some(&b'\n') {
                le + 2
            } else {
                le + 1
            };
            if ns < bytes.len() {
                let ne = line_end(bytes, ns);
                text.push('\n');
                push_cut(&mut text, bytes, ns, ne, ns, context_end(ns, ne), None);
            }
        }
        let span = (at.0, at.1 - at.0).into();
        let excerpt = Excerpt {
            name: name.to_string(),
            text,
            first_line,
        };
        (excerpt, span)
    }
}

/// Appends `bytes[from..to]` of the line `bytes[ls..le]` escaped, marking a cut with `…`;
/// with `mark`, records where `mark.0` and `mark.1` fall in `text`.
fn push_cut(
    text: &mut String,
    bytes: &[u8],
    ls: usize,
    le: usize,
    from: usize,
    to: usize,
    mut mark: Option<(usize, usize, &mut (usize, usize))>,
) {
    if from > ls {
        text.push('…');
    }
    let mut i = from;
    let mut note = |i: usize, text: &String| {
        if let Some((s, e, at)) = mark.as_mut() {
            if i == *s {
                at.0 = text.len();
                at.1 = text.len();
            }
            if i == *e {
                at.1 = text.len();
            }
        }
    };
    while i < to {
        note(i, text);
        let text = &mut *text;
        let rest = &bytes[i..to];
        let n = match std::str::from_utf8(&rest[..rest.len().min(4)]) {
            Ok(s) => s.chars().next().map_or(1, char::len_utf8),
            Err(e) if e.valid_up_to() > 0 => std::str::from_utf8(&rest[..e.valid_up_to()])
                .ok()
                .and_then(|s| s.chars().next())
                .map_or(1, char::len_utf8),
            Err(_) => 0,
        };
        if n == 0 {
            text.push_str(&format!("\\x{:02x}", bytes[i]));
            i += 1;
            continue;
        }
        let c = std::str::from_utf8(&bytes[i..i + n])
            .ok()
            .and_then(|s| s.chars().next())
            .unwrap_or('\u{fffd}');
        push_escaped(text, c);
        i += n;
    }
    note(i, text);
    // A span running past what is shown ends where the text shown does.
    if let Some((_, e, at)) = mark.as_mut()
        && *e > to
    {
        at.1 = text.len();
    }
    if to < le {
        text.push('…');
    }
}

/// `c`, or its escape when it is a control character.
fn push_escaped(text: &mut String, c: char) {
    match c {
        '\0' => text.push_str("\\0"),
        '\t' => text.push_str("\\t"),
        c if c.is_control() => text.push_str(&format!("\\x{:02x}", c as u32)),
        c => text.push(c),
    }
}

/// `s` cut to `max` characters (`…` marks a cut), control characters escaped: a cell or a
/// header quoted in a message.
pub fn short(s: &str, max: usize) -> String {
    let mut out = String::new();
    for (k, c) in s.chars().enumerate() {
        if k == max {
            out.push('…');
            break;
        }
        push_escaped(&mut out, c);
    }
    out
}

/// Where a context line `[ls, le)` is cut.
fn context_end(ls: usize, le: usize) -> usize {
    if le - ls <= LINE_MAX {
        le
    } else {
        ls + CONTEXT_MAX
    }
}

fn line_start(bytes: &[u8], at: usize) -> usize {
    bytes[..at]
        .iter()
        .rposition(|&b| b == b'\n' || b == b'\r')
        .map_or(0, |p| p + 1)
}

fn line_end(bytes: &[u8], at: usize) -> usize {
    bytes[at..]
        .iter()
        .position(|&b| b == b'\n' || b == b'\r')
        .map_or(bytes.len(), |p| at + p)
}

/// Line breaks in `bytes`: LF, CRLF or a bare CR, as miette and the readers break lines.
fn line_breaks(bytes: &[u8]) -> usize {
    let mut n = 0;
    for (i, &b) in bytes.iter().enumerate() {
        if b == b'\n' || (b == b'\r' && bytes.get(i + 1) != Some(&b'\n')) {
            n += 1;
        }
    }
    n
}

impl SourceCode for Excerpt {
    fn read_span<'a>(
        &'a self,
        span: &SourceSpan,
        context_lines_before: usize,
        context_lines_after: usize,
    ) -> Result<Box<dyn SpanContents<'a> + 'a>, MietteError> {
        let c = self
            .text
            .read_span(span, context_lines_before, context_lines_after)?;
        Ok(Box::new(MietteSpanContents::new_named(
            self.name.clone(),
            c.data(),
            *c.span(),
            c.line() + self.first_line,
            c.column(),
            c.line_count(),
        )))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_huge_nul_line_is_cut_and_escaped() {
        let mut bytes = b"t,ax\n0.1,2\n".to_vec();
        bytes.extend(std::iter::repeat_n(0u8, 1_000_000));
        bytes.extend(b"\n0.3,4\n");
        let (e, span) = Excerpt::around("f.csv", &bytes, 11, bytes.len() - 7);
        assert!(e.text.len() < 1000, "{}", e.text.len());
        assert!(e.text.starts_with("0.1,2\n\\0\\0"), "{:?}", &e.text[..40]);
        assert!(e.text.ends_with("…\n0.3,4"), "{:?}", e.text);
        assert_eq!(e.first_line, 1);
        assert_eq!(span.offset(), 6);
        assert_eq!(span.len(), 2 * SPAN_MAX);
        assert_eq!(short("a\0b", 2), "a\\0…");
    }
}
