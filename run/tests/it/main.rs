//! The integration tests of this crate in one binary (one link instead of one per file).

#[path = "../../../tests/support/station/mod.rs"]
mod common;

mod run_interpreter;
mod run_sim;
