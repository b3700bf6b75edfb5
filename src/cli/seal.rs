//! Reading and writing a run folder's seal (`seal.json`, `seal.sha256`) and the lab's keys;
//! what a seal holds and how it is checked is `ratecal_engine::audit::seal`.

use ed25519_dalek::pkcs8::{DecodePrivateKey, DecodePublicKey};
use ed25519_dalek::{SigningKey, VerifyingKey};
use miette::{Report, miette};
use ratecal_engine::audit::seal::{SEAL_FILE, SEAL_HASH_FILE, Seal, is_unsealed_file};
use ratecal_engine::recording::rfc3339;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Every file under `dir` but the seal's own and the lock file, by `/`-separated relative path, with its bytes.
pub fn folder_files(dir: &Path) -> std::io::Result<BTreeMap<String, Vec<u8>>> {
    let mut out = BTreeMap::new();
    let mut stack: Vec<PathBuf> = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d)? {
            let path = entry?.path();
            if path.is_dir() {
                stack.push(path);
                continue;
            }
            let rel = path.strip_prefix(dir).unwrap_or(&path);
            let name = rel
                .components()
                .map(|c| c.as_os_str().to_string_lossy().into_owned())
                .collect::<Vec<_>>()
                .join("/");
            if !is_unsealed_file(&name) {
                out.insert(name, std::fs::read(&path)?);
            }
        }
    }
    Ok(out)
}

/// Seals every file of a run folder, signed with `key` if given; written last.
pub fn write(dir: &Path, key: Option<&SigningKey>) -> std::io::Result<()> {
    let files = folder_files(dir)?;
    let now = rfc3339(std::time::SystemTime::now());
    let mut seal = Seal::new(&now, files.iter().map(|(p, b)| (p.as_str(), b.as_slice())));
    if let Some(k) = key {
        seal.sign(k);
    }
    save(dir, &seal)
}

fn save(dir: &Path, seal: &Seal) -> std::io::Result<()> {
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
        named.push((name, std::fs::read(file)?));
    }
    let borrowed: Vec<(&str, &[u8])> = named
        .iter()
        .map(|(n, b)| (n.as_str(), b.as_slice()))
        .collect();
    let now = rfc3339(std::time::SystemTime::now());
    seal.add(&now, command, &borrowed);
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
