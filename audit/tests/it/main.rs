//! The integration tests of this crate in one binary (one link instead of one per file).

#[path = "../audit_support/mod.rs"]
mod audit_support;

mod audit_diff;
mod audit_fixtures;
mod audit_prop;
mod audit_render;
mod audit_versions;
