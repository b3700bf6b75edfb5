//! The certificate as Markdown.

use super::doc::{Block, blocks, header};
use crate::model::Certificate;

/// Text as Markdown shows it literally: HTML's `<`, `>` and `&` as entities (a renderer
/// would otherwise run what a user typed, `<script>` in `--customer`), Markdown's own
/// markup characters escaped.
fn esc(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '\\' | '`' | '*' | '_' | '[' | ']' | '#' | '|' => {
                out.push('\\');
                out.push(c);
            }
            '\n' => out.push(' '),
            c => out.push(c),
        }
    }
    out
}

fn cell(s: &str) -> String {
    esc(s)
}

/// Renders Markdown: the page header once at the top, then the blocks.
pub fn markdown(c: &Certificate) -> String {
    let mut s = String::new();
    for m in c.markings() {
        s.push_str(&format!("**{m}**\n\n"));
    }
    for line in header(c) {
        s.push_str(&format!("{}  \n", esc(&line)));
    }
    s.push('\n');
    for b in blocks(c) {
        match b {
            Block::Heading(h) => s.push_str(&format!("## {}\n\n", esc(&h))),
            Block::Para(p) => s.push_str(&format!("{}\n\n", esc(&p))),
            Block::Fields(f) => {
                for (k, v) in f {
                    s.push_str(&format!("- **{}**: {}\n", esc(&k), esc(&v)));
                }
                s.push('\n');
            }
            Block::Table(head, rows) => {
                s.push_str(&format!(
                    "| {} |\n",
                    head.iter().map(|h| cell(h)).collect::<Vec<_>>().join(" | ")
                ));
                s.push_str(&format!("|{}\n", "---|".repeat(head.len())));
                for r in rows {
                    s.push_str(&format!(
                        "| {} |\n",
                        r.iter().map(|c| cell(c)).collect::<Vec<_>>().join(" | ")
                    ));
                }
                s.push('\n');
            }
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::esc;

    #[test]
    fn what_a_user_typed_is_shown_not_run() {
        assert_eq!(
            esc("<script>alert(1)</script> & *x*"),
            "&lt;script&gt;alert(1)&lt;/script&gt; &amp; \\*x\\*"
        );
    }
}
