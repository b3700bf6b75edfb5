//! Writing a run folder's seal (`seal.json`, `seal.sha256`) and the files added to a sealed
//! folder later, each as one committed change; what a seal holds and how it is checked is
//! [`crate::seal`].

use crate::names::{SEAL_FILE, SEAL_HASH_FILE};
use crate::seal::{Seal, is_unsealed_file};
use ed25519_dalek::SigningKey;
use ratecal_recording::commit::{Intent, commit, crash_point, pending_dir, recover, write_synced};
use ratecal_recording::{FileState, WrittenFile, hash_folder, hash_folder_known, rfc3339};
use std::collections::BTreeMap;
use std::path::Path;

/// Every entry under `dir` but the seal's own files and the lock file, by `/`-separated
/// relative path: its SHA-256 (hashed streaming, symlinks followed) or why it cannot be
/// read (docs/archive.md, Symlinks and special files).
pub fn folder_files(dir: &Path) -> std::io::Result<BTreeMap<String, FileState>> {
    hash_folder(dir, is_unsealed_file)
}

/// Seals every file of a run folder, signed with `key` if given; written last. Refused
/// when an entry cannot be read (it could not be shown unaltered later).
pub fn write(dir: &Path, key: Option<&SigningKey>) -> std::io::Result<()> {
    write_known(dir, key, &[])
}

/// As [`write`], for a folder just written: the files in `known` (hashed as they were
/// written, `RecordingWriter::written`) are not read again while their length is the one
/// written. `verify` still reads every file.
pub fn write_known(
    dir: &Path,
    key: Option<&SigningKey>,
    known: &[WrittenFile],
) -> std::io::Result<()> {
    recover(dir)?;
    let files = hash_folder_known(dir, is_unsealed_file, known)?;
    let mut hashes = Vec::with_capacity(files.len());
    for (path, state) in &files {
        match state {
            FileState::Hashed { sha256, .. } => hashes.push((path.as_str(), sha256.as_str())),
            FileState::Unreadable(why) => {
                return Err(std::io::Error::other(format!(
                    "{path}: {why} (a sealed folder holds regular files only)"
                )));
            }
        }
    }
    let now = rfc3339(std::time::SystemTime::now());
    let mut seal = Seal::from_hashes(&now, hashes);
    if let Some(k) = key {
        seal.sign(k);
    }
    save_with(dir, &seal, &[])
}

/// Replaces the seal (an approval added to it), as one committed change.
pub fn save(dir: &Path, seal: &Seal) -> std::io::Result<()> {
    save_with(dir, seal, &[])
}

/// Replaces the seal, together with `files` (name, bytes) written into the folder, as one
/// change: all staged under the pending folder, then committed (`ratecal_recording::commit`):
/// a crash leaves the old seal and files or the new ones, never a mix that reads altered.
fn save_with(dir: &Path, seal: &Seal, files: &[(String, Vec<u8>)]) -> std::io::Result<()> {
    let pending = pending_dir(dir)?;
    let json = seal.to_json();
    let mut moves = Vec::with_capacity(files.len() + 2);
    for (name, bytes) in files {
        write_synced(&pending.join(name), bytes)?;
        moves.push(name.clone());
    }
    write_synced(&pending.join(SEAL_FILE), json.as_bytes())?;
    write_synced(
        &pending.join(SEAL_HASH_FILE),
        Seal::hash_line(&json).as_bytes(),
    )?;
    moves.extend([SEAL_FILE.to_string(), SEAL_HASH_FILE.to_string()]);
    crash_point("before-seal-intent");
    commit(
        dir,
        &Intent {
            moves,
            removes: Vec::new(),
        },
    )
}

/// The seal of `dir` when it is a sealed run folder whose seal parses.
fn sealed(dir: &Path) -> Option<Seal> {
    let text = std::fs::read_to_string(dir.join(SEAL_FILE)).ok()?;
    serde_json::from_str::<Seal>(&text).ok()
}

/// Writes `files` (name, bytes) into `dir`. In a sealed run folder they join its seal as one
/// addition with the time and `command`, files and seal replaced in one committed change;
/// elsewhere each file is simply written. Returns whether they joined a seal.
///
/// `read` names the folder's files the new ones were computed from: a sealed folder is
/// verified first (refused, [`Refused::Altered`], when it fails its seal) and the addition
/// records their hashes as the seal holds them.
pub fn write_files(
    dir: &Path,
    files: &[(String, Vec<u8>)],
    command: &str,
    read: &[&str],
) -> std::io::Result<bool> {
    // A change a crash left unfinished is carried out (or dropped) first: its intent must
    // not be overwritten by this one.
    recover(dir)?;
    if std::fs::symlink_metadata(dir.join(SEAL_FILE)).is_ok() {
        let report = crate::verify::verify_folder(dir, None)
            .map_err(|e| std::io::Error::other(e.to_string()))?;
        let names: Vec<&str> = files.iter().map(|(n, _)| n.as_str()).collect();
        if let Some(failing) = crate::verify::fails_seal(&report, &names) {
            return Err(std::io::Error::new(
                std::io::ErrorKind::InvalidData,
                Refused::Altered(failing),
            ));
        }
    }
    let Some(mut seal) = sealed(dir) else {
        std::fs::create_dir_all(dir)?;
        for (name, bytes) in files {
            ratecal_recording::commit::write_nofollow(&dir.join(name), bytes)?;
        }
        return Ok(false);
    };
    let hashes: Vec<(String, String)> = files
        .iter()
        .map(|(n, b)| (n.clone(), ratecal_recording::sha256_hex(b)))
        .collect();
    let borrowed: Vec<(&str, &str)> = hashes
        .iter()
        .map(|(n, h)| (n.as_str(), h.as_str()))
        .collect();
    let now = rfc3339(std::time::SystemTime::now());
    let held = seal.held();
    seal.add_hashes(&now, command, &borrowed);
    if let Some(a) = seal.added.last_mut() {
        a.inputs = read
            .iter()
            .filter_map(|n| held.get(*n).map(|h| (n.to_string(), h.clone())))
            .collect();
    }
    save_with(dir, &seal, files)?;
    Ok(true)
}

/// [`write_files`] of one file given by its path.
pub fn write_file(
    path: &Path,
    bytes: Vec<u8>,
    command: &str,
    read: &[&str],
) -> std::io::Result<bool> {
    let dir = match path.parent() {
        Some(p) if p.as_os_str().is_empty() => Path::new("."),
        Some(p) => p,
        None => Path::new("."),
    };
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .ok_or_else(|| std::io::Error::other(format!("{} names no file", path.display())))?;
    write_files(dir, &[(name, bytes)], command, read)
}

/// Why [`write_files`] refused a sealed folder: it fails its seal (the files that do).
#[derive(Debug)]
pub enum Refused {
    /// Altered: the names `verify` gives.
    Altered(String),
}

impl std::fmt::Display for Refused {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Refused::Altered(names) => write!(
                f,
                "the run folder fails its seal ({names}): nothing was written or added to it"
            ),
        }
    }
}

impl std::error::Error for Refused {}

/// Whether an error of [`write_files`] is its refusal of an altered sealed folder.
pub fn is_altered(e: &std::io::Error) -> bool {
    e.get_ref().is_some_and(|r| r.is::<Refused>())
}

/// The command line as run, for the seal's record of additions.
pub fn command_line() -> String {
    let args: Vec<String> = std::env::args().skip(1).collect();
    format!("ratecal {}", args.join(" "))
}
