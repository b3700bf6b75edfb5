//! The shared examples (`../shared/examples/NAME` beside the repository, or one level up
//! for a worktree), found from any crate's tests. Included by path where needed.

use std::path::{Path, PathBuf};

/// `../shared/examples/<name>`, or `None` with a "skipped" line when this machine lacks it.
pub fn shared_example(name: &str) -> Option<PathBuf> {
    shared_path(&format!("examples/{name}"))
}

/// `../shared/<rel>` beside the repository (or a worktree's parent), or `None` with a
/// "skipped" line when this machine lacks it.
pub fn shared_path(rel: &str) -> Option<PathBuf> {
    let found = Path::new(env!("CARGO_MANIFEST_DIR"))
        .ancestors()
        .skip(1)
        .take(3)
        .map(|a| a.join("shared").join(rel))
        .find(|p| p.exists());
    if found.is_none() {
        println!("skipped: ../shared/{rel} is absent");
    }
    found
}
