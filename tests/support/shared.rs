//! The shared examples (`../shared/examples/NAME` beside the repository, or one level up
//! for a worktree), found from any crate's tests. Included by path where needed.

use std::path::{Path, PathBuf};

/// `../shared/examples/<name>`, or `None` with a "skipped" line when this machine lacks it.
pub fn shared_example(name: &str) -> Option<PathBuf> {
    let found = Path::new(env!("CARGO_MANIFEST_DIR"))
        .ancestors()
        .skip(1)
        .take(3)
        .map(|a| a.join("shared/examples").join(name))
        .find(|p| p.exists());
    if found.is_none() {
        println!("skipped: ../shared/examples/{name} is absent");
    }
    found
}
