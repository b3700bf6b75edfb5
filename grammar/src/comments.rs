//! Comments are skipped by the grammar; this module finds them in the text and attaches
//! each to the AST: a comment on the line of an entry's end trails that entry, any other
//! goes before the next entry of the innermost block holding it (a comment written inside
//! an entry but outside its nested blocks moves before the entry), and comments after the
//! last entry stay at the block's end. It also records blank lines between entries.

use crate::ast::*;
use std::collections::HashMap;

/// Finds every `# ...` comment outside strings.
pub(crate) fn scan(text: &str) -> Vec<Comment> {
    let bytes = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    let mut in_str = false;
    while i < bytes.len() {
        let b = bytes[i];
        if in_str {
            match b {
                b'\\' => i += 1,
                b'"' | b'\n' => in_str = false,
                _ => {}
            }
            i += 1;
            continue;
        }
        match b {
            b'"' => in_str = true,
            b'#' => {
                let end = text[i..].find('\n').map_or(text.len(), |k| i + k);
                let body = text[i + 1..end].trim_end();
                out.push(Comment {
                    text: body.to_string(),
                    span: Span::new(i, i + 1 + body.len()),
                });
                i = end;
                continue;
            }
            _ => {}
        }
        i += 1;
    }
    out
}

/// Attaches the comments to the file and marks blank lines.
pub(crate) fn attach(file: &mut File, comments: Vec<Comment>, text: &str) {
    // pest leaves the whitespace and comments skipped before a failed optional part at the
    // end of an entry inside the entry's span: cut them off first.
    let starts: HashMap<usize, usize> = comments
        .iter()
        .map(|c| (c.span.end, c.span.start))
        .collect();
    file.body.trim_spans(text, &starts);
    for c in comments {
        file.body.attach(c, text);
    }
    file.body.mark_blanks(text);
}

/// A block that can take comments.
pub(crate) trait Sink {
    /// The block's span.
    fn span(&self) -> Span;
    /// Attaches one comment (comments come in source order).
    fn attach(&mut self, c: Comment, text: &str);
    /// Sets `blank_before` on entries, recursively.
    fn mark_blanks(&mut self, text: &str);
    /// Cuts trailing whitespace and comments off entry spans, recursively.
    fn trim_spans(&mut self, text: &str, comment_starts: &HashMap<usize, usize>);
}

fn trim_end(text: &str, span: Span, comment_starts: &HashMap<usize, usize>) -> Span {
    let mut end = span.end;
    loop {
        let trimmed = text[span.start..end].trim_end_matches([' ', '\t', '\r', '\n', ';']);
        end = span.start + trimmed.len();
        match comment_starts.get(&end) {
            Some(&s) if s >= span.start => end = s,
            _ => return Span::new(span.start, end),
        }
    }
}

/// A node that may hold blocks.
pub(crate) trait Nested {
    /// Its nested blocks.
    fn blocks(&mut self) -> Vec<&mut dyn Sink>;
}

impl<T: Nested> Sink for Block<T> {
    fn span(&self) -> Span {
        self.span
    }

    fn attach(&mut self, c: Comment, text: &str) {
        let pos = c.span.start;
        if let Some(item) = self.items.iter_mut().find(|i| i.span.contains(pos)) {
            for b in item.node.blocks() {
                if b.span().contains(pos) {
                    b.attach(c, text);
                    return;
                }
            }
            item.comments.push(c);
            return;
        }
        let prev = self.items.iter().rposition(|i| i.span.end <= pos);
        if let Some(k) = prev {
            let item = &mut self.items[k];
            if item.trailing.is_none() && !text[item.span.end..pos].contains('\n') {
                item.trailing = Some(c);
                return;
            }
        }
        match self.items.iter_mut().find(|i| i.span.start >= c.span.end) {
            Some(next) => next.comments.push(c),
            None => self.end_comments.push(c),
        }
    }

    fn trim_spans(&mut self, text: &str, comment_starts: &HashMap<usize, usize>) {
        for item in &mut self.items {
            item.span = trim_end(text, item.span, comment_starts);
            for b in item.node.blocks() {
                b.trim_spans(text, comment_starts);
            }
        }
    }

    fn mark_blanks(&mut self, text: &str) {
        let mut prev_end: Option<usize> = None;
        for item in &mut self.items {
            let start = item
                .comments
                .iter()
                .map(|c| c.span.start)
                .fold(item.span.start, usize::min);
            item.blank_before = match prev_end {
                Some(e) if e <= start => has_blank_line(&text[e..start]),
                _ => false,
            };
            prev_end = Some(item.trailing.as_ref().map_or(item.span.end, |t| t.span.end));
            for b in item.node.blocks() {
                b.mark_blanks(text);
            }
        }
    }
}

fn has_blank_line(between: &str) -> bool {
    let lines: Vec<&str> = between.split('\n').collect();
    lines.len() > 2
        && lines[1..lines.len() - 1]
            .iter()
            .any(|l| l.trim_matches([' ', '\t', '\r', ';']).is_empty())
}

impl Nested for TopItem {
    fn blocks(&mut self) -> Vec<&mut dyn Sink> {
        match self {
            TopItem::Procedure(p) => vec![&mut p.body],
            _ => vec![],
        }
    }
}

impl Nested for ProcItem {
    fn blocks(&mut self) -> Vec<&mut dyn Sink> {
        match self {
            ProcItem::Requires { body, .. } => vec![body],
            ProcItem::Environment(b) => vec![b],
            ProcItem::Step(s) => vec![&mut s.body],
            ProcItem::Verify(v) => vec![&mut v.limits],
            _ => vec![],
        }
    }
}

impl Nested for Stmt {
    fn blocks(&mut self) -> Vec<&mut dyn Sink> {
        match self {
            Stmt::Settle(b) => vec![b],
            Stmt::For { body, .. } | Stmt::Repeat { body, .. } => vec![body],
            Stmt::Fit(f) => f.options.iter_mut().map(|b| b as &mut dyn Sink).collect(),
            Stmt::Verify(v) => vec![&mut v.limits],
            _ => vec![],
        }
    }
}

macro_rules! leaf {
    ($($t:ty),*) => {$(
        impl Nested for $t {
            fn blocks(&mut self) -> Vec<&mut dyn Sink> {
                Vec::new()
            }
        }
    )*};
}
leaf!(Limit, EnvItem, SettleItem, FitOpt);
