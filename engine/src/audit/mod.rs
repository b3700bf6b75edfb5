//! Audit: what changed between two versions of a procedure, whether a procedure folder's
//! released versions are intact, and whether a run folder was altered since the run.
//!
//! - [`diff`] compares two checked [`Plan`](crate::plan::Plan)s and lists [`Change`]s;
//!   [`render`] turns them into the text an auditor signs, the stable JSON, or the one-line
//!   summary of `ratecal log`.
//! - [`versions`] holds the rules of a procedure folder and its `versions.lock`.
//! - [`verify`] compares the hashes a run recorded with the files handed in.
//! - [`seal`] seals a run folder (every file's hash, optionally signed) and checks it.
//!
//! Nothing here opens a file: the CLI reads and hands in the data.

mod change;
mod diff;
mod direction;
pub mod render;
pub mod seal;
pub mod verify;
/// Procedure folders and `versions.lock` live beside the plan (the analysis reads them too).
pub use ratecal_plan::versions;

pub use change::{Change, ChangeKind, DiffReport, Side};
pub use diff::diff;

use crate::plan::Plan;

/// The diff of two plans with both sides named by name, version and canonical SHA-256.
pub fn diff_report(old: &Plan, old_sha256: &str, new: &Plan, new_sha256: &str) -> DiffReport {
    let side = |p: &Plan, sha: &str| Side {
        name: p.name.clone(),
        version: p.version.clone(),
        sha256: sha.to_string(),
    };
    DiffReport {
        old: side(old, old_sha256),
        new: side(new, new_sha256),
        changes: diff(old, new),
    }
}
