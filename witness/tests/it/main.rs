//! The integration tests of this crate in one binary (one link instead of one per file).

mod closed_forms;
mod read_back;
