//! Effect files (docs/user-effects.md): `ok_*.effect` fixtures and the documented examples
//! load; `err_*.effect` fixtures are refused with located diagnostics, snapshot-tested as
//! users see them; garbage never panics and every diagnostic names a line and a column.

use proptest::prelude::*;
use ratecal_analysis::explain::user;
use std::path::{Path, PathBuf};

fn files(dir: &Path, prefix: &str) -> Vec<PathBuf> {
    let mut out: Vec<PathBuf> = std::fs::read_dir(dir)
        .expect("folder")
        .flatten()
        .map(|e| e.path())
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with(prefix) && n.ends_with(".effect"))
        })
        .collect();
    out.sort();
    out
}

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/effects")
}

fn load(path: &Path) -> Result<Vec<&'static user::UserEffect>, Vec<ratecal_grammar::Diagnostic>> {
    let name = format!(
        "fixtures/effects/{}",
        path.file_name()
            .and_then(|n| n.to_str())
            .unwrap_or_default()
    );
    user::load(&[(name, std::fs::read_to_string(path).unwrap())])
}

#[test]
fn ok_fixtures_and_the_documented_examples_load() {
    let docs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/examples/effects");
    let mut all = files(&fixtures(), "ok_");
    all.extend(files(&docs, ""));
    assert!(all.len() >= 3);
    for f in all {
        let effects = load(&f).unwrap_or_else(|d| panic!("{}: {d:?}", f.display()));
        assert!(!effects.is_empty());
    }
}

#[test]
fn err_fixtures_are_refused_with_located_diagnostics() {
    let errs = files(&fixtures(), "err_");
    assert!(errs.len() >= 5);
    for f in errs {
        let diags = load(&f)
            .err()
            .unwrap_or_else(|| panic!("{} was accepted", f.display()));
        for d in &diags {
            assert!(
                d.line_col().is_some(),
                "{}: {d:?} has no position",
                f.display()
            );
            assert!(d.help.is_some(), "{}: {d:?} has no help", f.display());
        }
        let out: Vec<String> = diags.iter().map(|d| d.render()).collect();
        let stem = f
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or_default()
            .to_string();
        insta::with_settings!({ snapshot_path => "snapshots", prepend_module_to_snapshot => false }, {
            insta::assert_snapshot!(format!("effect_{stem}"), out.join("\n"));
        });
    }
}

fn assert_graceful(text: &str) {
    if let Err(diags) = user::load(&[("input.effect".into(), text.to_string())]) {
        assert!(!diags.is_empty());
        for d in &diags {
            assert!(
                d.line_col().is_some(),
                "no position: {d:?}\ninput: {text:?}"
            );
            let _ = d.render();
        }
    }
}

const CROSS: &str = include_str!("../../../docs/examples/effects/accel_cross_xz.effect");

fn tokens() -> impl Strategy<Value = String> {
    let words = vec![
        "effect",
        "e",
        "{",
        "}",
        "explanation",
        "follows",
        "\"text\"",
        "param",
        "p",
        "q",
        "unit",
        "\"mm\"",
        "needs",
        "\"rotate\"",
        "ax",
        "gz",
        "qx",
        "+=",
        "+",
        "-",
        "*",
        "/",
        "^",
        "(",
        ")",
        ",",
        "f_b.x",
        "w_b.y",
        "up_b.z",
        "w_b.",
        "g",
        "t_s",
        "pi",
        "deg",
        "sin",
        "sqrt",
        "abs",
        "nope",
        "0",
        "1e-3",
        "1e999",
        ".5",
        "2.",
        "#",
        "\n",
        "\"",
        "lever_arm",
    ];
    prop::collection::vec(prop::sample::select(words), 0..80).prop_map(|w| w.join(" "))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn random_bytes(bytes in prop::collection::vec(any::<u8>(), 0..400)) {
        assert_graceful(&String::from_utf8_lossy(&bytes));
    }

    #[test]
    fn random_tokens(text in tokens()) {
        assert_graceful(&text);
    }

    #[test]
    fn mutated_example(cut in 0usize..CROSS.len(), len in 0usize..40, insert in "[ -~\n]{0,12}") {
        let mut text = CROSS.to_string();
        let start = (0..=cut).rev().find(|&i| text.is_char_boundary(i)).unwrap_or(0);
        let end = (start + len).min(text.len());
        let end = (end..=text.len()).find(|&i| text.is_char_boundary(i)).unwrap_or(text.len());
        text.replace_range(start..end, &insert);
        assert_graceful(&text);
    }
}

#[test]
fn deep_or_long_input_is_refused_without_exhausting_the_stack() {
    let deep = format!(
        "effect e {{ ax += {}p{} }}",
        "(".repeat(100_000),
        ")".repeat(100_000)
    );
    assert_graceful(&deep);
    let sum = |n: usize| {
        format!(
            "effect e {{ explanation \"x\" param p unit \"1\" needs \"m\" ax += p * (1{}) }}",
            " + f_b.x".repeat(n)
        )
    };
    assert!(user::load(&[("sum.effect".into(), sum(200))]).is_ok());
    let d = user::load(&[("sum.effect".into(), sum(100_000))])
        .err()
        .unwrap();
    assert_eq!(d[0].code, "effect::too_deep");
    assert!(d[0].line_col().is_some());
    let negs = format!("effect e {{ ax += {}p }}", "-".repeat(10_000));
    assert_graceful(&negs);
}

const DOC: &str = include_str!("../../../docs/user-effects.md");

#[test]
fn the_documentation_lists_every_name_and_its_examples_load() {
    let mut blocks = 0;
    let mut cur: Option<String> = None;
    for line in DOC.lines() {
        match (&mut cur, line) {
            (None, "```effect") => cur = Some(String::new()),
            (Some(body), "```") => {
                user::load(&[("doc.effect".into(), body.clone())])
                    .unwrap_or_else(|d| panic!("{d:?}\n{body}"));
                blocks += 1;
                cur = None;
            }
            (Some(body), l) => {
                body.push_str(l);
                body.push('\n');
            }
            _ => {}
        }
    }
    assert!(blocks >= 1);
    for s in user::signals() {
        let vector = s.name.split('.').next().unwrap_or(s.name);
        assert!(
            DOC.contains(&format!("`{vector}`")),
            "{} is not documented",
            s.name
        );
    }
    for (f, _) in user::FUNCTIONS {
        assert!(DOC.contains(f), "function {f} is not documented");
    }
    for (c, _) in user::CONSTANTS {
        assert!(
            DOC.contains(&format!("`{c}`")),
            "constant {c} is not documented"
        );
    }
    for (c, _) in user::CHANNELS {
        assert!(DOC.contains(c), "channel {c} is not documented");
    }
}
