//! Fixture procedures: `ok_*.rcal` must check without errors, `err_*.rcal` must be
//! refused; the rendered diagnostics (what users see) are snapshot-tested.

use ratecal_check::{CheckOptions, Sources, check_text};
use std::path::{Path, PathBuf};

struct FixtureSources(PathBuf);

impl Sources for FixtureSources {
    fn load(&self, _from: &str, name: &str) -> Result<(String, String), String> {
        std::fs::read_to_string(self.0.join(name))
            .map(|t| (format!("fixtures/{name}"), t))
            .map_err(|e| e.to_string())
    }
}

fn fixtures(prefix: &str) -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures");
    let mut out: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("fixtures folder")
        .flatten()
        .map(|e| e.path())
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with(prefix) && n.ends_with(".rcal"))
        })
        .collect();
    out.sort();
    out
}

fn run(path: &Path) -> (bool, String) {
    let text = std::fs::read_to_string(path).expect("read fixture");
    let name = format!(
        "fixtures/{}",
        path.file_name()
            .and_then(|n| n.to_str())
            .unwrap_or_default()
    );
    let sources = FixtureSources(path.parent().expect("parent").to_path_buf());
    match check_text(&name, &text, &sources, &CheckOptions::default()) {
        Ok(c) => {
            let mut out = format!(
                "{} {}: ok, estimated duration {:.1} s\n",
                c.plan.name, c.plan.version, c.plan.estimated_duration_s
            );
            for w in &c.warnings {
                out.push_str(&w.render());
            }
            (true, out)
        }
        Err(diags) => {
            for d in &diags {
                assert!(
                    d.line_col().is_some(),
                    "{}: diagnostic without a position: {d:?}",
                    name
                );
            }
            (
                false,
                diags
                    .iter()
                    .map(|d| d.render())
                    .collect::<Vec<_>>()
                    .join("\n"),
            )
        }
    }
}

#[test]
fn ok_fixtures_check() {
    let files = fixtures("ok_");
    assert!(!files.is_empty());
    for f in files {
        let (ok, out) = run(&f);
        assert!(ok, "{} was refused:\n{out}", f.display());
        let stem = f
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or_default()
            .to_string();
        insta::with_settings!({ snapshot_path => "snapshots", prepend_module_to_snapshot => false }, {
            insta::assert_snapshot!(stem, out);
        });
    }
}

#[test]
fn err_fixtures_are_refused_with_diagnostics() {
    let files = fixtures("err_");
    assert!(!files.is_empty());
    for f in files {
        let (ok, out) = run(&f);
        assert!(!ok, "{} was accepted", f.display());
        let stem = f
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or_default()
            .to_string();
        insta::with_settings!({ snapshot_path => "snapshots", prepend_module_to_snapshot => false }, {
            insta::assert_snapshot!(stem, out);
        });
    }
}
