//! Audit: what changed between two versions of a procedure, whether a procedure folder's
//! released versions are intact. Run folders, their seals and their verification are
//! `ratecal-folder`'s.
//!
//! - [`diff`] compares two checked [`Plan`](ratecal_plan::Plan)s and lists [`Change`]s;
//!   [`render`] turns them into the text an auditor signs, the stable JSON, or the one-line
//!   summary of `ratecal log`.
//! - [`versions`] holds the rules of a procedure folder and its `versions.lock`.
//!
//! Nothing here opens a file: the CLI reads and hands in the data.

mod change;
mod diff;
mod direction;
pub mod render;
/// Procedure folders and `versions.lock` live beside the plan (the analysis reads them too).
pub use ratecal_plan::versions;

pub use change::{Change, ChangeKind, DiffReport, Side};
pub use diff::diff;

use ratecal_plan::Plan;

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
