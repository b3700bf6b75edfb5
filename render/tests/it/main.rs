//! The integration tests of this crate in one binary (one link instead of one per file).

#[path = "../render_common/mod.rs"]
mod render_common;

mod render_browser;
mod render_docs;
mod render_errors;
mod render_templates;
