//! A folder's files as the seal, `verify` and the archive see them, read the same way by
//! each: symlinks are followed everywhere (the content counts, not the link), every file is
//! hashed streaming (memory flat in its size), and an entry that cannot be read as a
//! regular file (a dangling symlink, a symlink loop, a FIFO, a socket, a device) is named
//! with why, never opened (opening a FIFO would block).

use sha2::{Digest, Sha256};
use std::collections::{BTreeMap, BTreeSet};
use std::io::{self, Read};
use std::path::{Path, PathBuf};

/// One entry of a folder: its content's hash, or why it cannot be read.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum FileState {
    /// A regular file (or a symlink to one): lowercase hex SHA-256 and size in bytes.
    Hashed {
        /// SHA-256, lowercase hex.
        sha256: String,
        /// Bytes.
        size: u64,
    },
    /// Not readable as a regular file: why (`a dangling symlink`, `a FIFO`...).
    Unreadable(String),
}

/// Streaming SHA-256 and size of a regular file (a symlink is followed); refuses anything
/// else without opening it.
///
/// A large file hashed once by this process is not hashed again while its identity, size,
/// modification and status-change times are the ones it was hashed with (`digests`): a
/// command that checks a folder's seal before its work and again before it writes reads a
/// recording once. No write to a file leaves its status-change time as it was; a file
/// changed in the last seconds is not kept, as the clock that stamps it is coarse (a later
/// write in the same tick would leave the times as they were).
pub fn sha256_file(path: &Path) -> io::Result<(String, u64)> {
    regular(path)?;
    let before = digests::stamp(path);
    if let Some(hit) = before.as_ref().and_then(digests::get) {
        return Ok(hit);
    }
    let mut f = std::fs::File::open(path)?;
    let mut hasher = Sha256::new();
    let mut buf = vec![0u8; 256 * 1024];
    let mut size = 0u64;
    loop {
        let n = match f.read(&mut buf) {
            Ok(0) => break,
            Ok(n) => n,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(e),
        };
        hasher.update(&buf[..n]);
        size += n as u64;
    }
    let out = (hex::encode(hasher.finalize()), size);
    if let Some(b) = before
        && digests::stamp(path).as_ref() == Some(&b)
        && b.len == size
    {
        digests::put(b, &out);
    }
    Ok(out)
}

/// The digests of large files this process has hashed, by what identifies their content.
mod digests {
    use std::path::Path;
    use std::sync::Mutex;

    /// Files smaller than this are hashed every time (a cache would save nothing).
    const LARGE: u64 = 1 << 20;
    /// Digests kept at most.
    const KEPT: usize = 16;

    /// What a file's content is known by: device, inode, size, modification and
    /// status-change times (ns).
    #[derive(Debug, Clone, PartialEq)]
    pub(super) struct Stamp {
        id: (u64, u64),
        pub len: u64,
        times: (i64, i64, i64, i64),
    }

    static KNOWN: Mutex<Vec<(Stamp, (String, u64))>> = Mutex::new(Vec::new());

    #[cfg(unix)]
    pub(super) fn stamp(path: &Path) -> Option<Stamp> {
        use std::os::unix::fs::MetadataExt;
        let m = std::fs::metadata(path).ok()?;
        (m.len() >= LARGE).then(|| Stamp {
            id: (m.dev(), m.ino()),
            len: m.len(),
            times: (m.mtime(), m.mtime_nsec(), m.ctime(), m.ctime_nsec()),
        })
    }

    #[cfg(not(unix))]
    pub(super) fn stamp(_: &Path) -> Option<Stamp> {
        None
    }

    pub(super) fn get(s: &Stamp) -> Option<(String, u64)> {
        let known = KNOWN.lock().ok()?;
        known.iter().find(|k| &k.0 == s).map(|k| k.1.clone())
    }

    /// Seconds since a file last changed for its digest to be kept.
    const SETTLED_S: i64 = 2;

    pub(super) fn put(s: Stamp, d: &(String, u64)) {
        let now = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_secs() as i64);
        if s.times.0.max(s.times.2) > now - SETTLED_S {
            return;
        }
        if let Ok(mut known) = KNOWN.lock() {
            known.retain(|k| k.0.id != s.id);
            if known.len() >= KEPT {
                known.remove(0);
            }
            known.push((s, d.clone()));
        }
    }
}

/// `Ok` when `path` is (or a symlink leads to) a regular file; otherwise an error saying
/// what it is instead (kind `InvalidInput` for a FIFO, socket or device).
pub fn regular(path: &Path) -> io::Result<()> {
    match std::fs::metadata(path) {
        Ok(m) if m.is_file() => Ok(()),
        Ok(m) => Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("not a regular file ({})", kind_of(&m)),
        )),
        Err(e) => Err(io::Error::new(e.kind(), why_unreadable(path, &e))),
    }
}

/// A file a writer just wrote: its `/`-separated relative path, SHA-256 (lowercase hex)
/// and length in bytes, hashed as it was written.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct WrittenFile {
    /// Relative path (`imu.csv`).
    pub name: String,
    /// Lowercase hex SHA-256 of the bytes written.
    pub sha256: String,
    /// Bytes written.
    pub len: u64,
}

/// Every file under `dir` by `/`-separated relative path, symlinks followed, each hashed
/// streaming; `skip` leaves out names (relative paths) that are not part of the folder's
/// content. Errs only when `dir` itself cannot be listed.
pub fn hash_folder(
    dir: &Path,
    skip: impl Fn(&str) -> bool,
) -> io::Result<BTreeMap<String, FileState>> {
    hash_folder_known(dir, skip, &[])
}

/// As [`hash_folder`], but the regular files in `known` (relative path, SHA-256, length:
/// what [`crate::RecordingWriter::written`] returns for the files it just wrote) are not
/// read again when their length is still the one written; `verify` and the archive read
/// everything ([`hash_folder`]).
pub fn hash_folder_known(
    dir: &Path,
    skip: impl Fn(&str) -> bool,
    known: &[WrittenFile],
) -> io::Result<BTreeMap<String, FileState>> {
    let mut out = BTreeMap::new();
    let mut seen = BTreeSet::new();
    seen.insert(dir.canonicalize()?);
    let mut stack: Vec<PathBuf> = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let mut entries: Vec<PathBuf> = std::fs::read_dir(&d)?
            .map(|e| e.map(|e| e.path()))
            .collect::<io::Result<_>>()?;
        entries.sort();
        for path in entries {
            let rel = path.strip_prefix(dir).unwrap_or(&path);
            let name = rel
                .components()
                .map(|c| c.as_os_str().to_string_lossy().into_owned())
                .collect::<Vec<_>>()
                .join("/");
            if skip(&name) {
                continue;
            }
            let state = match std::fs::metadata(&path) {
                Ok(m) if m.is_dir() => {
                    // A symlink back to a folder already walked would never end.
                    match path.canonicalize() {
                        Ok(c) if seen.insert(c.clone()) => {
                            stack.push(path);
                            continue;
                        }
                        Ok(_) => {
                            FileState::Unreadable("a symlink loop (a folder seen already)".into())
                        }
                        Err(e) => FileState::Unreadable(e.to_string()),
                    }
                }
                Ok(m) if m.is_file() => {
                    match known.iter().find(|k| k.name == name && k.len == m.len()) {
                        Some(k) => FileState::Hashed {
                            sha256: k.sha256.clone(),
                            size: k.len,
                        },
                        None => match sha256_file(&path) {
                            Ok((sha256, size)) => FileState::Hashed { sha256, size },
                            Err(e) => FileState::Unreadable(e.to_string()),
                        },
                    }
                }
                Ok(m) => FileState::Unreadable(format!("not a regular file ({})", kind_of(&m))),
                Err(e) => FileState::Unreadable(why_unreadable(&path, &e)),
            };
            out.insert(name, state);
        }
    }
    Ok(out)
}

/// Why `path` cannot be read, in words: a dangling symlink, a loop, or the OS's message.
fn why_unreadable(path: &Path, e: &io::Error) -> String {
    let link = std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink());
    if link && e.kind() == io::ErrorKind::NotFound {
        let to = std::fs::read_link(path)
            .map(|t| t.display().to_string())
            .unwrap_or_default();
        return format!("a dangling symlink (to {to})");
    }
    if link && e.raw_os_error() == Some(ELOOP) {
        return "a symlink loop".into();
    }
    e.to_string()
}

/// ELOOP on Linux (and most Unix systems but the BSDs, where it is 62).
#[cfg(any(
    target_os = "macos",
    target_os = "freebsd",
    target_os = "openbsd",
    target_os = "netbsd"
))]
const ELOOP: i32 = 62;
#[cfg(not(any(
    target_os = "macos",
    target_os = "freebsd",
    target_os = "openbsd",
    target_os = "netbsd"
)))]
const ELOOP: i32 = 40;

/// What a non-regular, non-folder entry is.
fn kind_of(m: &std::fs::Metadata) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let t = m.file_type();
        if t.is_fifo() {
            return "a FIFO";
        }
        if t.is_socket() {
            return "a socket";
        }
        if t.is_block_device() || t.is_char_device() {
            return "a device";
        }
    }
    if m.is_dir() {
        "a folder"
    } else {
        "a special file"
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A settled large file's digest is kept, and a write of the same length (the times
    /// change) is hashed again.
    #[cfg(unix)]
    #[test]
    fn a_kept_digest_is_dropped_when_the_file_changes() {
        let tmp = tempfile::tempdir().unwrap();
        let p = tmp.path().join("imu.csv");
        let (a, b) = (vec![7u8; 2 << 20], vec![8u8; 2 << 20]);
        std::fs::write(&p, &a).unwrap();
        let fresh = sha256_file(&p).unwrap();
        assert_eq!(fresh.0, crate::sha256_hex(&a));
        assert!(
            digests::get(&digests::stamp(&p).unwrap()).is_none(),
            "just written"
        );
        std::thread::sleep(std::time::Duration::from_millis(2100));
        assert_eq!(sha256_file(&p).unwrap(), fresh);
        assert_eq!(
            digests::get(&digests::stamp(&p).unwrap()),
            Some(fresh.clone())
        );
        std::fs::write(&p, &b).unwrap();
        let (sha, n) = sha256_file(&p).unwrap();
        assert_eq!((sha, n), (crate::sha256_hex(&b), 2 << 20));
    }

    #[test]
    fn hashes_stream_and_follow_symlinks() {
        let tmp = tempfile::tempdir().unwrap();
        let d = tmp.path();
        std::fs::write(d.join("a.csv"), b"abc").unwrap();
        let big = vec![7u8; 600_000];
        std::fs::write(d.join("big"), &big).unwrap();
        let (sha, n) = sha256_file(&d.join("big")).unwrap();
        assert_eq!((sha, n), (crate::sha256_hex(&big), 600_000));
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink(d.join("a.csv"), d.join("link.csv")).unwrap();
            std::os::unix::fs::symlink(d.join("gone"), d.join("dangling")).unwrap();
            std::os::unix::fs::symlink(d.join("loop"), d.join("loop")).unwrap();
            let f = hash_folder(d, |_| false).unwrap();
            assert_eq!(f["link.csv"], f["a.csv"]);
            let why = |k: &str| match &f[k] {
                FileState::Unreadable(w) => w.clone(),
                s => panic!("{k}: {s:?}"),
            };
            assert!(
                why("dangling").contains("dangling symlink"),
                "{}",
                why("dangling")
            );
            assert!(why("loop").contains("symlink loop"), "{}", why("loop"));
        }
    }
}
