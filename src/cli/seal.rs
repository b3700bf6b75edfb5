//! Reading and writing a run folder's seal (`seal.json`, `seal.sha256`) and the lab's keys;
//! what a seal holds and how it is checked is `ratecal_engine::audit::seal`.

use ed25519_dalek::pkcs8::{DecodePrivateKey, DecodePublicKey};
use ed25519_dalek::{SigningKey, VerifyingKey};
use miette::{Report, miette};
use ratecal_engine::audit::seal::{SEAL_FILE, SEAL_HASH_FILE, Seal, is_unsealed_file};
use ratecal_engine::recording::{FileState, hash_folder, rfc3339, sha256_file};
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
    let files = folder_files(dir)?;
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
    save(dir, &seal)
}

/// Writes `seal.json` and its hash beside it.
pub fn save(dir: &Path, seal: &Seal) -> std::io::Result<()> {
    let json = seal.to_json();
    std::fs::write(dir.join(SEAL_FILE), &json)?;
    std::fs::write(dir.join(SEAL_HASH_FILE), Seal::hash_line(&json))
}

/// After writing `file`: if it lies in a sealed run folder, adds it to that seal with the
/// time and `command` (the seal is left alone when it no longer parses: `verify` says so).
pub fn record_addition(file: &Path, command: &str) -> std::io::Result<bool> {
    record_additions(&[file], command)
}

/// After writing `files`, all in one folder: if it is a sealed run folder, adds them to its
/// seal as one addition with the time and `command`.
pub fn record_additions(files: &[&Path], command: &str) -> std::io::Result<bool> {
    let Some(dir) = files.first().and_then(|f| f.parent()).map(|p| {
        if p.as_os_str().is_empty() {
            Path::new(".")
        } else {
            p
        }
    }) else {
        return Ok(false);
    };
    let Ok(text) = std::fs::read_to_string(dir.join(SEAL_FILE)) else {
        return Ok(false);
    };
    let Ok(mut seal) = serde_json::from_str::<Seal>(&text) else {
        return Ok(false);
    };
    let mut named = Vec::with_capacity(files.len());
    for file in files {
        let name = file
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        named.push((name, sha256_file(file)?.0));
    }
    let borrowed: Vec<(&str, &str)> = named
        .iter()
        .map(|(n, h)| (n.as_str(), h.as_str()))
        .collect();
    let now = rfc3339(std::time::SystemTime::now());
    seal.add_hashes(&now, command, &borrowed);
    save(dir, &seal)?;
    Ok(true)
}

/// The command line as run, for the seal's record of additions.
pub fn command_line() -> String {
    let args: Vec<String> = std::env::args().skip(1).collect();
    format!("ratecal {}", args.join(" "))
}

/// Reads the lab's private key (PKCS#8 PEM, as `ratecal key new` writes it).
pub fn signing_key(path: &Path) -> Result<SigningKey, Report> {
    let text = std::fs::read_to_string(path).map_err(|e| {
        key_error(
            path,
            &e.to_string(),
            "give the lab.key `ratecal key new DIR` wrote",
        )
    })?;
    SigningKey::from_pkcs8_pem(&text).map_err(|e| {
        key_error(
            path,
            &format!("not an Ed25519 private key ({e})"),
            "give the lab.key `ratecal key new DIR` wrote (PKCS#8 PEM)",
        )
    })
}

/// Reads the lab's public key (SPKI PEM, as `ratecal key new` writes it).
pub fn verifying_key(path: &Path) -> Result<VerifyingKey, Report> {
    let text = std::fs::read_to_string(path).map_err(|e| {
        key_error(
            path,
            &e.to_string(),
            "give the lab.pub `ratecal key new DIR` wrote",
        )
    })?;
    VerifyingKey::from_public_key_pem(&text).map_err(|e| {
        key_error(
            path,
            &format!("not an Ed25519 public key ({e})"),
            "give the lab.pub `ratecal key new DIR` wrote (SPKI PEM)",
        )
    })
}

fn key_error(path: &Path, why: &str, help: &str) -> Report {
    miette!(
        code = "key::unreadable",
        help = help.to_string(),
        "cannot use {} as a key: {why}",
        path.display()
    )
}
