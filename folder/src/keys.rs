//! The lab's keys, as `ratecal key new` writes them: the private key signs seals and
//! approvals, the public key verifies them.

use ed25519_dalek::pkcs8::{DecodePrivateKey, DecodePublicKey};
use ed25519_dalek::{SigningKey, VerifyingKey};
use miette::{Report, miette};
use std::path::Path;

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
