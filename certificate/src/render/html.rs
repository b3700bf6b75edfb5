//! The certificate as one self-contained HTML page; printed, its header repeats on every
//! page (a fixed element) and says DRAFT for an unapproved run.

use super::doc::{Block, blocks, header};
use crate::model::Certificate;

/// Escapes text for HTML.
fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

const CSS: &str = "body{font-family:sans-serif;font-size:10pt;margin:0 2em}\
header{border-bottom:1px solid #444;padding:.5em 0}\
@media print{header{position:fixed;top:0;left:0;right:0;background:#fff}main{margin-top:7em}}\
.draft{color:#b00;font-weight:bold;font-size:14pt}\
table{border-collapse:collapse;margin:.5em 0}td,th{border:1px solid #999;padding:2px 6px;text-align:left}\
dt{font-weight:bold;float:left;clear:left;width:12em}dd{margin-left:13em}";

/// Renders HTML.
pub fn html(c: &Certificate) -> String {
    let mut s = format!(
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>Certificate No. {}</title><style>{CSS}</style></head><body>\n<header>",
        esc(c.number_text())
    );
    for m in c.markings() {
        s.push_str(&format!("<div class=\"draft\">{m}</div>"));
    }
    for line in header(c) {
        s.push_str(&format!("<div>{}</div>", esc(&line)));
    }
    s.push_str("</header>\n<main>\n");
    for b in blocks(c) {
        match b {
            Block::Heading(h) => s.push_str(&format!("<h2>{}</h2>\n", esc(&h))),
            Block::Para(p) => s.push_str(&format!("<p>{}</p>\n", esc(&p))),
            Block::Fields(f) => {
                s.push_str("<dl>");
                for (k, v) in f {
                    s.push_str(&format!("<dt>{}</dt><dd>{}</dd>", esc(&k), esc(&v)));
                }
                s.push_str("</dl>\n");
            }
            Block::Table(head, rows) => {
                s.push_str("<table><tr>");
                for h in head {
                    s.push_str(&format!("<th>{}</th>", esc(&h)));
                }
                s.push_str("</tr>");
                for r in rows {
                    s.push_str("<tr>");
                    for c in r {
                        s.push_str(&format!("<td>{}</td>", esc(&c)));
                    }
                    s.push_str("</tr>");
                }
                s.push_str("</table>\n");
            }
        }
    }
    s.push_str("</main></body></html>\n");
    s
}
