//! Every example in docs/language.md: `rcal` blocks check, `rcal-step` blocks parse inside
//! a step, `rcal-error` blocks are refused; every block is in canonical layout.

use ratecal_check::{CheckOptions, NoImports, check_text};

const DOC: &str = include_str!("../../../docs/language.md");

fn blocks() -> Vec<(String, String)> {
    let mut out = Vec::new();
    let mut cur: Option<(String, String)> = None;
    for line in DOC.lines() {
        match (&mut cur, line.strip_prefix("```")) {
            (None, Some(tag)) if !tag.is_empty() => cur = Some((tag.to_string(), String::new())),
            (Some(_), Some("")) => out.extend(cur.take()),
            (Some((_, body)), _) => {
                body.push_str(line);
                body.push('\n');
            }
            _ => {}
        }
    }
    out
}

#[test]
fn every_example_holds() {
    let blocks = blocks();
    let mut counts = [0; 3];
    for (tag, body) in &blocks {
        match tag.as_str() {
            "rcal" => {
                let c = check_text("doc", body, &NoImports, &CheckOptions::default())
                    .unwrap_or_else(|d| panic!("{d:?}\n{body}"));
                assert!(c.warnings.is_empty(), "{:?}", c.warnings);
                assert_eq!(
                    ratecal_grammar::canonical(body).unwrap().text,
                    *body,
                    "not canonical:\n{body}"
                );
                counts[0] += 1;
            }
            "rcal-step" => {
                let indented: String = body.lines().map(|l| format!("    {l}\n")).collect();
                let text =
                    format!("procedure doc version 0.0.0 {{\n  step doc {{\n{indented}  }}\n}}\n");
                let canon =
                    ratecal_grammar::canonical(&text).unwrap_or_else(|d| panic!("{d:?}\n{text}"));
                assert_eq!(canon.text, text, "not canonical");
                counts[1] += 1;
            }
            "rcal-error" => {
                assert!(
                    check_text("doc", body, &NoImports, &CheckOptions::default()).is_err(),
                    "accepted:\n{body}"
                );
                counts[2] += 1;
            }
            _ => {}
        }
    }
    assert!(counts.iter().all(|&c| c > 0), "{counts:?}");
}

#[test]
fn the_whole_example_lasts_what_the_text_says() {
    let (_, body) = blocks()
        .into_iter()
        .find(|(t, _)| t == "rcal")
        .expect("an rcal block");
    let plan = check_text("doc", &body, &NoImports, &CheckOptions::default())
        .expect("checks")
        .plan;
    // 6 x (30 s settle + 10 s) plus the moves: "4 min" once rounded
    assert_eq!((plan.estimated_duration_s / 60.0).round(), 4.0);
    assert!(DOC.contains("demo-static 1.0.0: ok, estimated duration 4 min"));
}
