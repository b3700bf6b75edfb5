//! Crash-consistent changes of a run folder. Every file ratecal writes into a run folder is
//! written whole under `.ratecal-pending/`, fsynced, and renamed into place; a change of
//! several files (a seal and its hash, the streams of a resumed run) is staged there, then
//! committed by writing an intent file (`INTENT`: the names to move in and to remove), then
//! renamed one by one. A crash leaves either no intent (the folder is as before; the staged
//! files are thrown away by [`recover`]) or an intent that [`recover`] carries out. The
//! pending folder is never sealed, verified or archived.

use serde::{Deserialize, Serialize};
use std::fs::File;
use std::io::{self, Write};
use std::path::{Path, PathBuf};

/// The scratch folder inside a run folder.
pub const PENDING_DIR: &str = ".ratecal-pending";
/// The commit point of a staged change, inside [`PENDING_DIR`].
const INTENT: &str = "INTENT";

/// Whether a `/`-separated path of a run folder is scratch (under [`PENDING_DIR`]).
pub fn is_pending(path: &str) -> bool {
    path == PENDING_DIR || path.starts_with(&format!("{PENDING_DIR}/"))
}

/// What a committed change does: the staged files moved into the folder (in this order), then
/// the files removed.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Intent {
    /// Names staged in the pending folder, moved to the same name in the run folder.
    pub moves: Vec<String>,
    /// Names removed from the run folder after the moves.
    pub removes: Vec<String>,
}

/// The pending folder of `dir`, created if need be.
pub fn pending_dir(dir: &Path) -> io::Result<PathBuf> {
    let p = dir.join(PENDING_DIR);
    std::fs::create_dir_all(&p)?;
    Ok(p)
}

/// Flushes a folder's entries (a rename is durable once its folder is).
pub fn sync_dir(dir: &Path) -> io::Result<()> {
    #[cfg(unix)]
    {
        File::open(dir)?.sync_all()
    }
    #[cfg(not(unix))]
    {
        let _ = dir;
        Ok(())
    }
}

/// Writes `bytes` fully into `path` and fsyncs it.
pub fn write_synced(path: &Path, bytes: &[u8]) -> io::Result<()> {
    let mut f = File::create(path)?;
    f.write_all(bytes)?;
    f.sync_all()
}

/// Replaces `dir/name` atomically: written whole and fsynced under the pending folder, then
/// renamed over it.
pub fn write_atomic(dir: &Path, name: &str, bytes: &[u8]) -> io::Result<()> {
    // A folder being staged is itself the pending folder.
    let tmp_dir = if dir.file_name().is_some_and(|n| n == PENDING_DIR) {
        dir.to_path_buf()
    } else {
        pending_dir(dir)?
    };
    let tmp = tmp_dir.join(format!("{name}.tmp"));
    write_synced(&tmp, bytes)
        .map_err(|e| io::Error::new(e.kind(), format!("{}: {e}", tmp.display())))?;
    crash_point(&format!("before-rename-{name}"));
    std::fs::rename(&tmp, dir.join(name))?;
    if tmp_dir != dir {
        // Left only when empty: a staged change may be in it.
        let _ = std::fs::remove_dir(&tmp_dir);
    }
    sync_dir(dir)
}

/// Commits staged files: the intent written (the commit point), then carried out.
pub fn commit(dir: &Path, intent: &Intent) -> io::Result<()> {
    let pending = pending_dir(dir)?;
    let json = serde_json::to_vec(intent).map_err(io::Error::other)?;
    let tmp = pending.join(format!("{INTENT}.tmp"));
    write_synced(&tmp, &json)?;
    std::fs::rename(&tmp, pending.join(INTENT))?;
    sync_dir(&pending)?;
    crash_point("after-intent");
    carry_out(dir, intent)
}

/// Moves and removes as the intent says; each step may already be done (a second try after a
/// crash), then the pending folder goes.
fn carry_out(dir: &Path, intent: &Intent) -> io::Result<()> {
    let pending = dir.join(PENDING_DIR);
    for name in &intent.moves {
        let from = pending.join(name);
        if from.exists() {
            std::fs::rename(&from, dir.join(name))?;
            crash_point(&format!("after-move-{name}"));
        }
    }
    for name in &intent.removes {
        match std::fs::remove_file(dir.join(name)) {
            Err(e) if e.kind() != io::ErrorKind::NotFound => return Err(e),
            _ => {}
        }
    }
    sync_dir(dir)?;
    std::fs::remove_dir_all(&pending)?;
    sync_dir(dir)
}

/// What [`recover`] found.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Recovered {
    /// No pending folder.
    Clean,
    /// Staged files without an intent, thrown away: the folder is as before the change.
    RolledBack,
    /// An interrupted commit, finished.
    RolledForward(Intent),
}

/// Finishes or throws away what a crash left in the pending folder (call holding the
/// folder's lock).
pub fn recover(dir: &Path) -> io::Result<Recovered> {
    let pending = dir.join(PENDING_DIR);
    if std::fs::symlink_metadata(&pending).is_err() {
        return Ok(Recovered::Clean);
    }
    match pending_intent(dir) {
        Some(intent) => {
            carry_out(dir, &intent)?;
            Ok(Recovered::RolledForward(intent))
        }
        None => {
            // Only the temporary file of a single replacement (never renamed): nothing to tell.
            let staged = std::fs::read_dir(&pending)?
                .filter_map(Result::ok)
                .any(|e| !e.file_name().to_string_lossy().ends_with(".tmp"));
            std::fs::remove_dir_all(&pending)?;
            sync_dir(dir)?;
            Ok(if staged {
                Recovered::RolledBack
            } else {
                Recovered::Clean
            })
        }
    }
}

/// The intent of an interrupted commit, if the pending folder holds one.
pub fn pending_intent(dir: &Path) -> Option<Intent> {
    let text = std::fs::read(dir.join(PENDING_DIR).join(INTENT)).ok()?;
    serde_json::from_slice(&text).ok()
}

/// Tests stop the process at named points (`RATECAL_CRASH_AT=after-intent`, or
/// `after-checkpoint#3` for the third time it is reached): it aborts there at once, as a
/// kill would, leaving the files as they are. Nothing happens without the variable.
pub fn crash_point(name: &str) {
    use std::sync::atomic::{AtomicUsize, Ordering};
    static HITS: AtomicUsize = AtomicUsize::new(0);
    let Some(at) = std::env::var_os("RATECAL_CRASH_AT") else {
        return;
    };
    let at = at.to_string_lossy();
    let (point, nth) = match at.split_once('#') {
        Some((p, n)) => (p, n.parse::<usize>().unwrap_or(1)),
        None => (at.as_ref(), 1),
    };
    if point == name && HITS.fetch_add(1, Ordering::SeqCst) + 1 == nth {
        let _ = io::stderr().write_all(format!("crash point {at}\n").as_bytes());
        std::process::abort();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_intent_is_carried_out_and_staged_files_without_one_are_dropped() {
        let tmp = tempfile::tempdir().unwrap();
        let d = tmp.path();
        std::fs::write(d.join("a"), "old a").unwrap();
        std::fs::write(d.join("gone"), "x").unwrap();
        // Staged, no intent: rolled back, the folder as before.
        write_synced(&pending_dir(d).unwrap().join("a"), b"new a").unwrap();
        assert_eq!(recover(d).unwrap(), Recovered::RolledBack);
        assert_eq!(std::fs::read_to_string(d.join("a")).unwrap(), "old a");
        assert!(!d.join(PENDING_DIR).exists());
        // An intent left half done (the first move made): rolled forward.
        let p = pending_dir(d).unwrap();
        write_synced(&p.join("a"), b"new a").unwrap();
        write_synced(&p.join("b"), b"new b").unwrap();
        let intent = Intent {
            moves: vec!["a".into(), "b".into()],
            removes: vec!["gone".into()],
        };
        std::fs::write(p.join(INTENT), serde_json::to_vec(&intent).unwrap()).unwrap();
        std::fs::rename(p.join("a"), d.join("a")).unwrap();
        assert_eq!(
            recover(d).unwrap(),
            Recovered::RolledForward(intent.clone())
        );
        assert_eq!(std::fs::read_to_string(d.join("a")).unwrap(), "new a");
        assert_eq!(std::fs::read_to_string(d.join("b")).unwrap(), "new b");
        assert!(!d.join("gone").exists());
        assert_eq!(recover(d).unwrap(), Recovered::Clean);
    }
}
