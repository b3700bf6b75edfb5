//! One writer per run folder: every command that writes a run folder holds an advisory lock
//! on its `.ratecal.lock` (flock on Unix, LockFileEx on Windows, through `std::fs::File`'s
//! own locking, stable since Rust 1.89, so no crate is needed). The kernel releases it when
//! the process ends, however it ends: a `kill -9` leaves no stale lock. The file also says
//! who holds it, so a second writer is refused at once naming the holder. It is never
//! sealed, verified or archived.

use crate::names::{LOCK_FILE, MANIFEST, SEAL_FILE};
use miette::{Report, miette};
use ratecal_recording::rfc3339;
use std::fs::{File, OpenOptions, TryLockError};
use std::io::{Read, Seek, Write};
use std::path::Path;

/// A held lock on a run folder; released when dropped (or when the process dies). A clean
/// release removes the lock file; one a killed process leaves is harmless (never sealed,
/// verified or archived) and taken over by the next writer.
#[derive(Debug)]
pub struct FolderLock {
    file: Option<File>,
    path: std::path::PathBuf,
}

impl Drop for FolderLock {
    fn drop(&mut self) {
        // Removed while still held: a writer that opened the old file then finds it is no
        // longer the one at this path, and tries again (`same_file`).
        #[cfg(unix)]
        let _ = std::fs::remove_file(&self.path);
        drop(self.file.take());
    }
}

/// Whether `file` is still the file at `path` (not removed by a writer that let go).
fn same_file(file: &File, path: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        match (file.metadata(), std::fs::metadata(path)) {
            (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
            _ => false,
        }
    }
    #[cfg(not(unix))]
    {
        let _ = (file, path);
        true
    }
}

/// Takes the lock of run folder `dir` (created if need be) for `command`, or refuses at
/// once when another process holds it.
pub fn acquire(dir: &Path, command: &str) -> Result<FolderLock, Report> {
    let path = dir.join(LOCK_FILE);
    let cannot = |e: std::io::Error| {
        miette!(
            code = "run_folder::lock",
            help = "check that the run folder exists and is writable",
            "cannot lock the run folder {}: {e}",
            dir.display()
        )
    };
    let mut file = loop {
        let mut file = ratecal_recording::commit::open_with_nofollow(
            OpenOptions::new()
                .read(true)
                .write(true)
                .create(true)
                .truncate(false),
            &path,
        )
        .map_err(|e| link_or(e, &cannot))?;
        match file.try_lock() {
            Ok(()) if same_file(&file, &path) => break file,
            // The holder let go and removed it meanwhile: open the new one.
            Ok(()) => continue,
            Err(TryLockError::WouldBlock) => return Err(in_use(dir, &mut file)),
            Err(TryLockError::Error(e)) => return Err(cannot(e)),
        }
    };
    // Who holds it, for the writer refused next.
    let holder = format!(
        "pid {}\nsince {}\ncommand {command}\n",
        std::process::id(),
        rfc3339(std::time::SystemTime::now())
    );
    file.set_len(0)
        .and_then(|()| file.rewind())
        .and_then(|()| file.write_all(holder.as_bytes()))
        .and_then(|()| file.flush())
        .map_err(cannot)?;
    hold_for_tests();
    Ok(FolderLock {
        file: Some(file),
        path,
    })
}

/// A planted symlink refused as such (named, with its own help); other errors as `cannot`.
fn link_or(e: std::io::Error, cannot: &dyn Fn(std::io::Error) -> Report) -> Report {
    if e.kind() == std::io::ErrorKind::InvalidInput {
        miette!(
            code = "run_folder::symlink",
            help = "a run folder holds no symbolic links where ratecal writes: remove the link \
                    (and check who planted it), then run the command again",
            "{e}"
        )
    } else {
        cannot(e)
    }
}

/// The lock of the run folder `file` is written into, when it lies in one (a folder holding
/// manifest.yaml or seal.json); `None` elsewhere.
pub fn for_file(file: &Path, command: &str) -> Result<Option<FolderLock>, Report> {
    let dir = match file.parent() {
        Some(p) if p.as_os_str().is_empty() => Path::new("."),
        Some(p) => p,
        None => return Ok(None),
    };
    if !(dir.join(MANIFEST).is_file() || dir.join(SEAL_FILE).is_file()) {
        return Ok(None);
    }
    acquire(dir, command).map(Some)
}

/// The refusal, naming the holder as its lock file records it.
fn in_use(dir: &Path, file: &mut File) -> Report {
    let mut text = String::new();
    // The holder writes its name just after locking: it may not be there yet.
    let _ = file.read_to_string(&mut text);
    let field = |key: &str| {
        text.lines()
            .find_map(|l| l.strip_prefix(key).map(|v| v.trim().to_string()))
            .filter(|v| !v.is_empty())
    };
    let who = match (field("pid "), field("since ")) {
        (Some(pid), Some(since)) => format!("process {pid} since {since}"),
        (Some(pid), None) => format!("process {pid}"),
        _ => "another process".to_string(),
    };
    let what = field("command ")
        .map(|c| format!(" (`{c}`)"))
        .unwrap_or_default();
    miette!(
        code = "run_folder::in_use",
        help = "one command writes a run folder at a time: wait for it to end, then try again",
        "{} is in use by {who}{what}: nothing was written",
        dir.display()
    )
}

/// Tests make a writer hold its lock a while (`RATECAL_TEST_HOLD_LOCK_MS`), so that a
/// second writer surely meets it.
fn hold_for_tests() {
    if let Some(ms) = std::env::var("RATECAL_TEST_HOLD_LOCK_MS")
        .ok()
        .and_then(|v| v.parse::<u64>().ok())
    {
        std::thread::sleep(std::time::Duration::from_millis(ms));
    }
}
