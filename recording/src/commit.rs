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

/// The pending folder of `dir`, created if need be; refused when a symlink stands in its
/// place (files staged there would be written wherever it points).
pub fn pending_dir(dir: &Path) -> io::Result<PathBuf> {
    let p = dir.join(PENDING_DIR);
    match std::fs::symlink_metadata(&p) {
        Ok(m) if m.file_type().is_symlink() => return Err(link_refused(&p)),
        Ok(m) if m.is_dir() => {}
        Ok(_) => {
            return Err(io::Error::other(format!(
                "{} is not a folder: nothing was written",
                p.display()
            )));
        }
        Err(e) if e.kind() == io::ErrorKind::NotFound => std::fs::create_dir(&p)?,
        Err(e) => return Err(e),
    }
    Ok(p)
}

/// The refusal of a symlink found where ratecal writes a file (docs/run-folders.md):
/// ratecal never writes through one, so a link planted in a folder cannot redirect a write.
pub fn link_refused(path: &Path) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidInput,
        format!(
            "\"{}\" is a symbolic link: ratecal never writes through a link, nothing was written \
             (remove the link, then run the command again)",
            path.display()
        ),
    )
}

/// Opens `path` for writing without following a symlink in its place: created, or
/// truncated when `truncate` (else appended to when `append`). A symlink there, dangling or
/// not, is refused ([`link_refused`]) and nothing is written anywhere.
pub fn open_nofollow(path: &Path, truncate: bool, append: bool) -> io::Result<File> {
    let mut o = std::fs::OpenOptions::new();
    o.create(true);
    if append {
        o.append(true);
    } else {
        o.write(true).truncate(truncate);
    }
    open_with_nofollow(&mut o, path)
}

/// Opens `path` with the options `o`, never following a symlink in its place (refused,
/// [`link_refused`]).
pub fn open_with_nofollow(o: &mut std::fs::OpenOptions, path: &Path) -> io::Result<File> {
    #[cfg(unix)]
    std::os::unix::fs::OpenOptionsExt::custom_flags(o, libc::O_NOFOLLOW);
    #[cfg(not(unix))]
    if std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink()) {
        return Err(link_refused(path));
    }
    o.open(path).map_err(|e| nofollow_error(path, e))
}

/// The error of an open with `O_NOFOLLOW`: the link named when there is one.
pub fn nofollow_error(path: &Path, e: io::Error) -> io::Error {
    if std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink()) {
        link_refused(path)
    } else {
        e
    }
}

/// Writes `bytes` as the whole of `path` (created or truncated), never through a symlink.
pub fn write_nofollow(path: &Path, bytes: &[u8]) -> io::Result<()> {
    open_nofollow(path, true, false)?.write_all(bytes)
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
    let mut f = open_nofollow(path, true, false)?;
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
    match std::fs::symlink_metadata(&pending) {
        Err(_) => return Ok(Recovered::Clean),
        Ok(m) if m.file_type().is_symlink() => return Err(link_refused(&pending)),
        Ok(_) => {}
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
/// kill would, leaving the files as they are. Nothing happens without the variable, nor in a
/// build without the `fault-injection` feature (a plain `cargo build --release`: only the
/// root crate's tests enable it, through its dev-dependencies).
#[cfg(not(feature = "fault-injection"))]
pub fn crash_point(_name: &str) {}

/// See above: the hook of a build with the `fault-injection` feature.
#[cfg(feature = "fault-injection")]
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
    /// Reaches the crash point `inert-probe` (run alone by the test below, with the
    /// variable naming it set).
    #[test]
    fn crash_point_probe() {
        crash_point("inert-probe");
    }

    /// A build without the `fault-injection` feature (a plain `cargo build`, this crate's
    /// own tests) never stops at a crash point, whatever `RATECAL_CRASH_AT` says: this test
    /// binary run again with the variable set, the probe reaching the named point.
    #[cfg(not(feature = "fault-injection"))]
    #[test]
    fn crash_points_are_inert_without_the_feature() {
        let o = std::process::Command::new(std::env::current_exe().unwrap())
            .args([
                "--exact",
                "commit::tests::crash_point_probe",
                "--test-threads=1",
            ])
            .env("RATECAL_CRASH_AT", "inert-probe")
            .output()
            .unwrap();
        let out = String::from_utf8_lossy(&o.stdout);
        assert!(
            o.status.success(),
            "{out}{}",
            String::from_utf8_lossy(&o.stderr)
        );
        assert!(out.contains("1 passed"), "{out}");
    }

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
