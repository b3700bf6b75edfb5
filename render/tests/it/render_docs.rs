//! docs/report-templates.md documents every field of the data model: each top-level key,
//! and each key of the pre-digested sections, of the full fixture's context is named there.

use crate::render_common;
use ratecal_render::context_json;

#[test]
fn every_context_field_is_documented() {
    let doc_path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/report-templates.md");
    let doc = std::fs::read_to_string(doc_path).expect("docs/report-templates.md exists");
    let ctx = context_json(&render_common::full());
    let mut missing = vec![];
    let top = ctx.as_object().unwrap();
    for (key, value) in top {
        if !doc.contains(&format!("`{key}`")) {
            missing.push(key.clone());
        }
        // Sections the render stage builds itself (not results.json or manifest as written).
        let own = [
            "report",
            "traceability",
            "environment",
            "acquisition",
            "process",
            "summary",
            "recommendations",
        ];
        if own.contains(&key.as_str()) {
            for sub in value.as_object().unwrap().keys() {
                if !doc.contains(&format!("`{sub}`")) {
                    missing.push(format!("{key}.{sub}"));
                }
            }
        }
    }
    for key in ["plots", "template"] {
        assert!(doc.contains(&format!("`{key}`")), "{key}");
    }
    assert!(missing.is_empty(), "undocumented fields: {missing:?}");
}
