//! The integration tests of this crate in one binary (one link instead of one per file).

mod diagnostics;
mod docs;
mod fixtures;
mod garbage;
mod manual;
mod plan;
mod registry_observability;
mod size_effect_plan;
