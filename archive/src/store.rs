//! The content-addressed file store: each stored file once, named by its SHA-256, in a
//! folder (`files/ab/abcdef...`) or in the `blobs` table.

use crate::{ArchiveError, Result};
use sqlx::AnyPool;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Where stored files live.
#[derive(Debug, Clone)]
pub enum Store {
    /// Under this folder.
    Folder(PathBuf),
    /// In the database's `blobs` table.
    Database,
}

/// Folder of unfinished writes; a killed add leaves at most a file here, never a half file
/// under its hash.
const TMP: &str = "tmp";

impl Store {
    /// Path of a stored file in a folder store.
    pub fn path(root: &Path, sha: &str) -> PathBuf {
        root.join(&sha[..2]).join(sha)
    }

    /// Stores `bytes` under `sha` unless already there (committed before any index row).
    pub async fn put(&self, pool: &AnyPool, sha: &str, bytes: &[u8]) -> Result<()> {
        match self {
            Store::Folder(root) => put_file(root, sha, bytes),
            Store::Database => {
                sqlx::query(
                    "INSERT INTO blobs (sha256, size, data) VALUES ($1, $2, $3) \
                     ON CONFLICT (sha256) DO NOTHING",
                )
                .bind(sha)
                .bind(bytes.len() as i64)
                .bind(bytes.to_vec())
                .execute(pool)
                .await?;
                Ok(())
            }
        }
    }

    /// Stores the file at `src` under `sha` unless already there; false (nothing stored)
    /// when its content does not hash to `sha`. A folder store copies it streaming (memory
    /// flat in its size); the database store binds it whole (one row per file).
    pub async fn put_file(&self, pool: &AnyPool, sha: &str, src: &Path) -> Result<bool> {
        match self {
            Store::Folder(root) => copy_file(root, sha, src),
            Store::Database => {
                let bytes = std::fs::read(src).map_err(|e| ArchiveError::io(src, e))?;
                if ratecal_folder::hashes::sha256_hex(&bytes) != sha {
                    return Ok(false);
                }
                self.put(pool, sha, &bytes).await?;
                Ok(true)
            }
        }
    }

    /// The bytes stored under `sha`, `None` when absent.
    pub async fn get(&self, pool: &AnyPool, sha: &str) -> Result<Option<Vec<u8>>> {
        match self {
            Store::Folder(root) => {
                let p = Self::path(root, sha);
                match std::fs::read(&p) {
                    Ok(b) => Ok(Some(b)),
                    Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
                    Err(e) => Err(ArchiveError::io(p, e)),
                }
            }
            Store::Database => {
                let row: Option<(Vec<u8>,)> =
                    sqlx::query_as("SELECT data FROM blobs WHERE sha256 = $1")
                        .bind(sha)
                        .fetch_optional(pool)
                        .await?;
                Ok(row.map(|r| r.0))
            }
        }
    }

    /// Whether a file is stored under `sha`.
    pub async fn has(&self, pool: &AnyPool, sha: &str) -> Result<bool> {
        match self {
            Store::Folder(root) => Ok(Self::path(root, sha).is_file()),
            Store::Database => {
                let row: Option<(String,)> =
                    sqlx::query_as("SELECT sha256 FROM blobs WHERE sha256 = $1")
                        .bind(sha)
                        .fetch_optional(pool)
                        .await?;
                Ok(row.is_some())
            }
        }
    }

    /// Every hash the store holds.
    pub async fn hashes(&self, pool: &AnyPool) -> Result<Vec<String>> {
        match self {
            Store::Folder(root) => folder_hashes(root),
            Store::Database => {
                let rows: Vec<(String,)> =
                    sqlx::query_as("SELECT sha256 FROM blobs ORDER BY sha256")
                        .fetch_all(pool)
                        .await?;
                Ok(rows.into_iter().map(|r| r.0).collect())
            }
        }
    }

    /// Removes the unfinished writes a killed add left in `tmp/`: those whose writer (the
    /// pid in their name) is no longer running, and any older than a day. A write another
    /// add is making now is left alone. Returns what was removed.
    pub fn remove_leftovers(&self) -> Vec<PathBuf> {
        let mut removed = Vec::new();
        for path in self.leftovers() {
            if abandoned(&path) && std::fs::remove_file(&path).is_ok() {
                removed.push(path);
            }
        }
        removed
    }

    /// Unfinished writes left by an interrupted add (harmless: never named by the index).
    pub fn leftovers(&self) -> Vec<PathBuf> {
        match self {
            Store::Folder(root) => std::fs::read_dir(root.join(TMP))
                .map(|rd| rd.flatten().map(|e| e.path()).collect())
                .unwrap_or_default(),
            Store::Database => Vec::new(),
        }
    }
}

/// Whether an unfinished write (`tmp/<sha>.<pid>.<nanos>`) was abandoned: its writer is
/// gone (no `/proc/<pid>`, where the system has `/proc`), or it is older than a day.
fn abandoned(path: &Path) -> bool {
    let day = std::time::Duration::from_secs(24 * 3600);
    let old = std::fs::metadata(path)
        .and_then(|m| m.modified())
        .ok()
        .and_then(|t| t.elapsed().ok())
        .is_some_and(|age| age > day);
    let pid = path
        .file_name()
        .and_then(|n| n.to_str())
        .and_then(|n| n.split('.').nth(1))
        .and_then(|p| p.parse::<u32>().ok());
    let proc_ = Path::new("/proc/self").exists();
    let gone = match pid {
        Some(p) if proc_ => {
            p != std::process::id() && !Path::new("/proc").join(p.to_string()).exists()
        }
        _ => false,
    };
    old || gone
}

/// Where a file of hash `sha` goes and the `tmp/` name to write it under first; `None`
/// when the store holds it already.
fn staging(root: &Path, sha: &str) -> Result<Option<(PathBuf, PathBuf)>> {
    let dest = Store::path(root, sha);
    if dest.is_file() {
        return Ok(None);
    }
    let tmp_dir = root.join(TMP);
    let io = |p: &Path, e| ArchiveError::io(p, e);
    std::fs::create_dir_all(&tmp_dir).map_err(|e| io(&tmp_dir, e))?;
    let parent = dest.parent().unwrap_or(root);
    std::fs::create_dir_all(parent).map_err(|e| io(parent, e))?;
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.subsec_nanos());
    let tmp = tmp_dir.join(format!("{sha}.{}.{nanos}", std::process::id()));
    Ok(Some((dest, tmp)))
}

/// Writes into `tmp/`, syncs, then renames into place: the name appears only when whole.
fn put_file(root: &Path, sha: &str, bytes: &[u8]) -> Result<()> {
    let Some((dest, tmp)) = staging(root, sha)? else {
        return Ok(());
    };
    let io = |p: &Path, e| ArchiveError::io(p, e);
    let mut f =
        ratecal_recording::commit::open_nofollow(&tmp, true, false).map_err(|e| io(&tmp, e))?;
    f.write_all(bytes).map_err(|e| io(&tmp, e))?;
    f.sync_all().map_err(|e| io(&tmp, e))?;
    drop(f);
    std::fs::rename(&tmp, &dest).map_err(|e| io(&dest, e))
}

/// `put_file` into a folder store: copies `src` into `tmp/` hashing it on the way, syncs,
/// then renames into place only when the hash is `sha`.
fn copy_file(root: &Path, sha: &str, src: &Path) -> Result<bool> {
    use sha2::{Digest, Sha256};
    use std::io::Read;
    let Some((dest, tmp)) = staging(root, sha)? else {
        return Ok(true);
    };
    let io = |p: &Path, e| ArchiveError::io(p, e);
    ratecal_recording::regular(src).map_err(|e| io(src, e))?;
    let mut from = std::fs::File::open(src).map_err(|e| io(src, e))?;
    let mut to =
        ratecal_recording::commit::open_nofollow(&tmp, true, false).map_err(|e| io(&tmp, e))?;
    let mut hasher = Sha256::new();
    let mut buf = vec![0u8; 256 * 1024];
    let copied = (|| -> std::io::Result<()> {
        loop {
            let n = match from.read(&mut buf) {
                Ok(0) => return to.sync_all(),
                Ok(n) => n,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
                Err(e) => return Err(e),
            };
            hasher.update(&buf[..n]);
            to.write_all(&buf[..n])?;
        }
    })();
    drop(to);
    if let Err(e) = copied {
        let _ = std::fs::remove_file(&tmp);
        return Err(io(&tmp, e));
    }
    if hex::encode(hasher.finalize()) != sha {
        let _ = std::fs::remove_file(&tmp);
        return Ok(false);
    }
    ratecal_recording::commit::crash_point("archive-before-rename");
    std::fs::rename(&tmp, &dest).map_err(|e| io(&dest, e))?;
    Ok(true)
}

fn folder_hashes(root: &Path) -> Result<Vec<String>> {
    let mut out = Vec::new();
    let rd = std::fs::read_dir(root).map_err(|e| ArchiveError::io(root, e))?;
    for sub in rd.flatten() {
        let name = sub.file_name().to_string_lossy().into_owned();
        if name == TMP || !sub.path().is_dir() {
            continue;
        }
        let inner = std::fs::read_dir(sub.path()).map_err(|e| ArchiveError::io(sub.path(), e))?;
        out.extend(
            inner
                .flatten()
                .map(|e| e.file_name().to_string_lossy().into_owned()),
        );
    }
    out.sort();
    Ok(out)
}
