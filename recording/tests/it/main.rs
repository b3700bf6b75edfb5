//! The integration tests of this crate in one binary (one link instead of one per file).

#[path = "../../../tests/support/shared.rs"]
mod shared;

mod attitude;
mod host_times;
mod recording_read;
mod span;
mod written;
