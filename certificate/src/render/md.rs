//! The certificate as Markdown.

use super::doc::{Block, blocks, header};
use crate::model::Certificate;

fn cell(s: &str) -> String {
    s.replace('|', "\\|").replace('\n', " ")
}

/// Renders Markdown: the page header once at the top, then the blocks.
pub fn markdown(c: &Certificate) -> String {
    let mut s = String::new();
    if c.draft {
        s.push_str("**DRAFT**\n\n");
    }
    for line in header(c) {
        s.push_str(&format!("{line}  \n"));
    }
    s.push('\n');
    for b in blocks(c) {
        match b {
            Block::Heading(h) => s.push_str(&format!("## {h}\n\n")),
            Block::Para(p) => s.push_str(&format!("{p}\n\n")),
            Block::Fields(f) => {
                for (k, v) in f {
                    s.push_str(&format!("- **{k}**: {v}\n"));
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
