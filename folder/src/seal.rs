//! The seal of a run folder: the SHA-256 of every file, written last (`seal.json`), its own
//! hash beside it (`seal.sha256`), optionally an Ed25519 signature by the lab's key. Files
//! ratecal adds later are listed with when and by which command. The CLI reads the folder
//! and hands the files in; nothing here opens a file.

use crate::hashes::{FileCheck, Status, VerifyReport, sha256_hex};
pub use crate::names::{LOCK_FILE, SEAL_FILE, SEAL_HASH_FILE};
use ed25519_dalek::{Signature, Signer, SigningKey, Verifier, VerifyingKey};
use ratecal_recording::FileState;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// The format tag of a seal.
pub const SEAL_FORMAT: &str = "ratecal-seal/1";

/// What `seal.json` holds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Seal {
    /// `ratecal-seal/1`.
    pub format: String,
    /// When the run sealed its folder (RFC 3339).
    pub sealed: String,
    /// SHA-256 of each file of the folder when sealed, by path (`/`-separated).
    pub files: BTreeMap<String, String>,
    /// The lab's signature over [`Seal::signed_text`], if the run was signed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub signature: Option<SealSignature>,
    /// Files ratecal added or rewrote after sealing, oldest first.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub added: Vec<Addition>,
    /// Who approved the run for issue (`ratecal approve`), signed over the seal as it was.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub approval: Option<Approval>,
}

/// An approval of the run's results for a certificate: who, in which role, when, and the
/// Ed25519 signature of [`Seal::approved_text`] by the approver's key.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Approval {
    /// The approver's name.
    pub signer: String,
    /// The approver's role (`Head of laboratory`...).
    pub role: String,
    /// When (RFC 3339).
    pub time: String,
    /// `SHA256:` and the hex SHA-256 of the approver's public key bytes.
    pub key_fingerprint: String,
    /// The approver's public key, 32 bytes hex.
    pub public_key: String,
    /// Signature of [`Seal::approved_text`], 64 bytes hex.
    pub signature: String,
    /// How many of the seal's additions it covers (those made before it); later ones are
    /// listed after it and leave it standing. Absent in an older approval: all of them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub additions: Option<usize>,
}

/// The fingerprint under which a public key is shown: `SHA256:` and the hex SHA-256 of its
/// 32 bytes.
pub fn key_fingerprint(key: &VerifyingKey) -> String {
    format!("SHA256:{}", sha256_hex(key.as_bytes()))
}

/// Signs `text` with the lab's key: the public key and the signature, both hex (what a
/// seal and a procedure's release line hold).
pub fn sign_text(key: &SigningKey, text: &str) -> (String, String) {
    let sig = key.sign(text.as_bytes());
    (
        hex::encode(key.verifying_key().as_bytes()),
        hex::encode(sig.to_bytes()),
    )
}

/// Whether `signature` by `public_key` (both hex) signs `text`: `None` when it does,
/// otherwise why not.
pub fn text_signature_problem(public_key: &str, signature: &str, text: &str) -> Option<String> {
    let key: Option<[u8; 32]> = hex::decode(public_key).ok().and_then(|b| b.try_into().ok());
    let Some(key) = key.and_then(|k| VerifyingKey::from_bytes(&k).ok()) else {
        return Some("the public key is not an Ed25519 key".into());
    };
    let bytes: Option<[u8; 64]> = hex::decode(signature).ok().and_then(|b| b.try_into().ok());
    let Some(bytes) = bytes else {
        return Some("the signature is not 64 bytes of hex".into());
    };
    match key.verify(text.as_bytes(), &Signature::from_bytes(&bytes)) {
        Ok(()) => None,
        Err(_) => Some("the signature does not match".into()),
    }
}

/// An Ed25519 signature and the public key that made it (both hex).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SealSignature {
    /// `ed25519`.
    pub algorithm: String,
    /// Public key, 32 bytes hex.
    pub public_key: String,
    /// Signature, 64 bytes hex.
    pub signature: String,
}

/// Files ratecal wrote into a sealed folder later (a re-rendered report, a new analysis).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Addition {
    /// When (RFC 3339).
    pub time: String,
    /// The command that wrote them.
    pub command: String,
    /// SHA-256 of each file written, by path.
    pub files: BTreeMap<String, String>,
    /// SHA-256 of each of the folder's files they were computed from, by path, as the seal
    /// held them when they were written: `verify` checks each against that record.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub inputs: BTreeMap<String, String>,
}

/// An addition of a seal and its index among the additions.
type Added<'a> = (usize, &'a Addition);

/// Whether a path names the seal itself (never listed in it).
pub fn is_seal_file(path: &str) -> bool {
    path == SEAL_FILE || path == SEAL_HASH_FILE
}

/// Whether a path is outside what a seal covers: the seal's own files, the lock file and
/// the pending folder of an unfinished change.
pub fn is_unsealed_file(path: &str) -> bool {
    is_seal_file(path) || is_scratch(path)
}

/// Whether a path is a run folder's scratch, never part of its content: the lock file and
/// the pending folder (`ratecal_recording::commit`).
pub fn is_scratch(path: &str) -> bool {
    path == LOCK_FILE || ratecal_recording::commit::is_pending(path)
}

impl Seal {
    /// Seals `files` (path and bytes, the seal's own files left out) at time `sealed`.
    pub fn new<'a>(sealed: &str, files: impl IntoIterator<Item = (&'a str, &'a [u8])>) -> Self {
        let hashed: Vec<(&str, String)> =
            files.into_iter().map(|(p, b)| (p, sha256_hex(b))).collect();
        Self::from_hashes(sealed, hashed.iter().map(|(p, h)| (*p, h.as_str())))
    }

    /// Seals files by their SHA-256 (hashed streaming by the caller) at time `sealed`.
    pub fn from_hashes<'a>(
        sealed: &str,
        files: impl IntoIterator<Item = (&'a str, &'a str)>,
    ) -> Self {
        Seal {
            format: SEAL_FORMAT.into(),
            sealed: sealed.into(),
            files: files
                .into_iter()
                .filter(|(p, _)| !is_seal_file(p))
                .map(|(p, h)| (p.to_string(), h.to_string()))
                .collect(),
            signature: None,
            added: Vec::new(),
            approval: None,
        }
    }

    /// The text a signature covers: format, time and one `sha256  path` line per sealed
    /// file (additions are covered by the seal's hash, not by the signature).
    pub fn signed_text(&self) -> String {
        let mut s = format!("{}\n{}\n", self.format, self.sealed);
        for (path, sha) in &self.files {
            s.push_str(&format!("{sha}  {path}\n"));
        }
        s
    }

    /// Signs the sealed files with the lab's key.
    pub fn sign(&mut self, key: &SigningKey) {
        let (public_key, signature) = sign_text(key, &self.signed_text());
        self.signature = Some(SealSignature {
            algorithm: "ed25519".into(),
            public_key,
            signature,
        });
    }

    /// The text an approval covers: who, role, when, every sealed file and every file
    /// added since, as the seal holds them at approval (a later addition is not approved).
    pub fn approved_text(&self, signer: &str, role: &str, time: &str) -> String {
        let mut s = format!("ratecal-approval/1\n{signer}\n{role}\n{time}\n");
        s.push_str(&self.signed_text());
        for a in &self.added {
            s.push_str(&format!("added {} {}\n", a.time, a.command));
            for (path, sha) in &a.files {
                s.push_str(&format!("{sha}  {path}\n"));
            }
        }
        s
    }

    /// Records the approval of the run by `signer` in `role` at `time`, signed with `key`
    /// (replaces an earlier approval).
    pub fn approve(&mut self, signer: &str, role: &str, time: &str, key: &SigningKey) {
        let sig = key.sign(self.approved_text(signer, role, time).as_bytes());
        self.approval = Some(Approval {
            signer: signer.into(),
            role: role.into(),
            time: time.into(),
            key_fingerprint: key_fingerprint(&key.verifying_key()),
            public_key: hex::encode(key.verifying_key().as_bytes()),
            signature: hex::encode(sig.to_bytes()),
            additions: Some(self.added.len()),
        });
    }

    /// How many additions the approval (if any) covers; the later ones came after it.
    pub fn approved_additions(&self) -> Option<usize> {
        let a = self.approval.as_ref()?;
        Some(
            a.additions
                .unwrap_or(self.added.len())
                .min(self.added.len()),
        )
    }

    /// `None` when the approval (if any) is signed by the key it names, its fingerprint is
    /// that key's, and it covers the seal as it is now; else why not.
    pub fn approval_problem(&self) -> Option<String> {
        let a = self.approval.as_ref()?;
        let key: Option<VerifyingKey> = hex::decode(&a.public_key)
            .ok()
            .and_then(|b| <[u8; 32]>::try_from(b).ok())
            .and_then(|b| VerifyingKey::from_bytes(&b).ok());
        let Some(key) = key else {
            return Some("the approver's public key is not an Ed25519 key".into());
        };
        if key_fingerprint(&key) != a.key_fingerprint {
            return Some("the fingerprint is not the approver's key's".into());
        }
        let bytes: Option<[u8; 64]> = hex::decode(&a.signature)
            .ok()
            .and_then(|b| b.try_into().ok());
        let Some(bytes) = bytes else {
            return Some("the signature is not 64 bytes of hex".into());
        };
        let mut before = self.clone();
        before.approval = None;
        // Additions after the approval are not covered by it, and do not undo it.
        if let Some(n) = a.additions {
            if n > before.added.len() {
                return Some("it counts more additions than the seal lists".into());
            }
            before.added.truncate(n);
        }
        let text = before.approved_text(&a.signer, &a.role, &a.time);
        match key.verify(text.as_bytes(), &Signature::from_bytes(&bytes)) {
            Ok(()) => None,
            Err(_) => Some(
                "the signature does not match the approver, the time or the files as sealed \
                 (altered, or files added after the approval)"
                    .into(),
            ),
        }
    }

    /// Records files written after sealing.
    pub fn add(&mut self, time: &str, command: &str, files: &[(&str, &[u8])]) {
        let hashed: Vec<(&str, String)> = files.iter().map(|(p, b)| (*p, sha256_hex(b))).collect();
        let refs: Vec<(&str, &str)> = hashed.iter().map(|(p, h)| (*p, h.as_str())).collect();
        self.add_hashes(time, command, &refs);
    }

    /// Records files written after sealing, by their SHA-256.
    pub fn add_hashes(&mut self, time: &str, command: &str, files: &[(&str, &str)]) {
        self.added.push(Addition {
            time: time.into(),
            command: command.into(),
            files: files
                .iter()
                .map(|(p, h)| (p.to_string(), h.to_string()))
                .collect(),
            inputs: BTreeMap::new(),
        });
    }

    /// The SHA-256 the seal holds now for each file (the newest record of it wins).
    pub fn held(&self) -> BTreeMap<String, String> {
        let mut held = self.files.clone();
        for a in &self.added {
            held.extend(a.files.iter().map(|(p, h)| (p.clone(), h.clone())));
        }
        held
    }

    /// `seal.json` text.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("seal serializes") + "\n"
    }

    /// `seal.sha256` text for this seal's JSON.
    pub fn hash_line(json: &str) -> String {
        format!("{}  {SEAL_FILE}\n", sha256_hex(json.as_bytes()))
    }
}

/// Checks a run folder against its seal: `seal` and `seal_hash` are the seal files' text
/// (`None` when missing), `files` every other file of the folder with its bytes, `key` the
/// lab's public key when the signature must be checked.
pub fn verify_seal(
    seal: Option<&str>,
    seal_hash: Option<&str>,
    files: &BTreeMap<String, Vec<u8>>,
    key: Option<&VerifyingKey>,
) -> VerifyReport {
    let hashed: BTreeMap<String, FileState> = files
        .iter()
        .map(|(p, b)| {
            let state = FileState::Hashed {
                sha256: sha256_hex(b),
                size: b.len() as u64,
            };
            (p.clone(), state)
        })
        .collect();
    verify_hashes(seal, seal_hash, &hashed, key)
}

/// [`verify_seal`] of files hashed by the caller (streaming); an entry it could not read
/// is named with why.
pub fn verify_hashes(
    seal: Option<&str>,
    seal_hash: Option<&str>,
    files: &BTreeMap<String, FileState>,
    key: Option<&VerifyingKey>,
) -> VerifyReport {
    let mut report = VerifyReport::default();
    let mut push = |file: &str, status: Status| {
        report.checks.push(FileCheck {
            file: file.into(),
            status,
        })
    };
    let Some(text) = seal else {
        push(SEAL_FILE, Status::Missing);
        return report;
    };
    let parsed: Seal = match serde_json::from_str(text) {
        Ok(s) => s,
        Err(e) => {
            push(SEAL_FILE, Status::Unparsable(e.to_string()));
            return report;
        }
    };
    if parsed.format != SEAL_FORMAT {
        let why = format!("format `{}`, not `{SEAL_FORMAT}`", parsed.format);
        push(SEAL_FILE, Status::Unparsable(why));
        return report;
    }
    let actual = sha256_hex(text.as_bytes());
    let recorded = seal_hash.and_then(|h| h.split_whitespace().next());
    push(
        &format!("{SEAL_FILE} (its hash in {SEAL_HASH_FILE})"),
        match recorded {
            None => Status::Missing,
            Some(h) if h.eq_ignore_ascii_case(&actual) => Status::Intact,
            Some(h) => Status::Altered {
                expected: h.into(),
                actual,
            },
        },
    );
    // The newest record of a file wins: a re-rendered report replaces the sealed one.
    let approved = parsed.approved_additions();
    let mut expected: BTreeMap<&str, (&str, Option<Added>)> = parsed
        .files
        .iter()
        .map(|(p, h)| (p.as_str(), (h.as_str(), None)))
        .collect();
    for (i, a) in parsed.added.iter().enumerate() {
        for (p, h) in &a.files {
            expected.insert(p.as_str(), (h.as_str(), Some((i, a))));
        }
    }
    // What each addition was computed from is what the seal held at the time.
    let mut held: BTreeMap<&str, &str> = parsed
        .files
        .iter()
        .map(|(p, h)| (p.as_str(), h.as_str()))
        .collect();
    for a in &parsed.added {
        for (p, h) in &a.inputs {
            if let Some(was) = held.get(p.as_str())
                && !was.eq_ignore_ascii_case(h)
            {
                push(
                    &format!("{p} (as read by `{}` at {})", a.command, a.time),
                    Status::Altered {
                        expected: was.to_string(),
                        actual: h.clone(),
                    },
                );
            }
        }
        held.extend(a.files.iter().map(|(p, h)| (p.as_str(), h.as_str())));
    }
    for (path, (sha, added)) in &expected {
        let name = match added {
            Some((i, a)) if approved.is_some_and(|n| *i >= n) => format!(
                "{path} (written by `{}` at {}, after the approval: not approved)",
                a.command, a.time
            ),
            Some((_, a)) => format!("{path} (written by `{}` at {})", a.command, a.time),
            None => path.to_string(),
        };
        let status = match files.get(*path) {
            None => Status::Missing,
            Some(FileState::Unreadable(why)) => Status::Unreadable(why.clone()),
            Some(FileState::Hashed { sha256: now, .. }) => {
                let now = now.clone();
                if now.eq_ignore_ascii_case(sha) {
                    Status::Intact
                } else {
                    Status::Altered {
                        expected: sha.to_string(),
                        actual: now,
                    }
                }
            }
        };
        push(&name, status);
    }
    for (path, state) in files
        .iter()
        .filter(|(p, _)| !expected.contains_key(p.as_str()))
    {
        match state {
            FileState::Unreadable(why) => push(path, Status::Unreadable(why.clone())),
            FileState::Hashed { .. } => push(path, Status::Unknown),
        }
    }
    if let Some(a) = &parsed.approval {
        let what = format!("approval by {} ({}) at {}", a.signer, a.role, a.time);
        push(
            &what,
            parsed
                .approval_problem()
                .map_or(Status::Intact, Status::Unsigned),
        );
    }
    if let Some(key) = key {
        push(
            "signature",
            signature_status(&parsed, key).map_or(Status::Intact, Status::Unsigned),
        );
        // A later addition is not signed: it must not stand in for a file the lab signed.
        for a in &parsed.added {
            for p in a.files.keys().filter(|p| parsed.files.contains_key(*p)) {
                let why = format!(
                    "signed file rewritten later by `{}` at {}",
                    a.command, a.time
                );
                push(p, Status::Unsigned(why));
            }
        }
    }
    report
}

/// `None` when the seal is signed by `key`, else why not.
fn signature_status(seal: &Seal, key: &VerifyingKey) -> Option<String> {
    let Some(sig) = &seal.signature else {
        return Some("the seal is not signed".into());
    };
    if !sig
        .public_key
        .eq_ignore_ascii_case(&hex::encode(key.as_bytes()))
    {
        return Some(format!("signed by another key ({})", sig.public_key));
    }
    let bytes: Option<[u8; 64]> = hex::decode(&sig.signature)
        .ok()
        .and_then(|b| b.try_into().ok());
    let Some(bytes) = bytes else {
        return Some("the signature is not 64 bytes of hex".into());
    };
    match key.verify(
        seal.signed_text().as_bytes(),
        &Signature::from_bytes(&bytes),
    ) {
        Ok(()) => None,
        Err(_) => Some("the signature does not match the sealed hashes".into()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn folder(files: &[(&str, &str)]) -> BTreeMap<String, Vec<u8>> {
        files
            .iter()
            .map(|(p, t)| (p.to_string(), t.as_bytes().to_vec()))
            .collect()
    }

    #[test]
    fn additions_supersede_and_signatures_cover_only_the_sealed_files() {
        let f = folder(&[("imu.csv", "1"), ("report.md", "old")]);
        let key = SigningKey::from_bytes(&[7; 32]);
        let mut seal = Seal::new("t0", f.iter().map(|(p, b)| (p.as_str(), b.as_slice())));
        seal.sign(&key);
        let json = seal.to_json();
        let hash = Seal::hash_line(&json);
        let pk = key.verifying_key();
        assert!(verify_seal(Some(&json), Some(&hash), &f, Some(&pk)).intact());

        // A re-rendered report, recorded: intact without a key, not vouched for by it.
        let g = folder(&[("imu.csv", "1"), ("report.md", "new")]);
        seal.add("t1", "ratecal report", &[("report.md", b"new")]);
        let json = seal.to_json();
        let hash = Seal::hash_line(&json);
        assert!(verify_seal(Some(&json), Some(&hash), &g, None).intact());
        let signed = verify_seal(Some(&json), Some(&hash), &g, Some(&pk));
        assert!(!signed.intact());
        assert!(
            signed.text().contains("UNSIGNED report.md"),
            "{}",
            signed.text()
        );
        // Not vouched for is not altered: the verdict says which (issue 39).
        assert!(!signed.text().contains("ALTERED"), "{}", signed.text());
        assert!(
            (signed.text()).contains("NOT SIGNED by the key given: report.md"),
            "{}",
            signed.text()
        );

        // An unknown file, and a seal whose hash is not the one beside it.
        let h = folder(&[("imu.csv", "1"), ("report.md", "new"), ("x", "")]);
        let r = verify_seal(Some(&json), Some(&hash), &h, None);
        assert!(r.text().contains("! UNKNOWN  x"), "{}", r.text());
        let r = verify_seal(Some(&json.replace("t1", "t2")), Some(&hash), &g, None);
        assert!(!r.intact());
    }

    #[test]
    fn an_approval_covers_signer_role_time_and_every_file_not_what_is_added_later() {
        let f = folder(&[("imu.csv", "1"), ("results.json", "{}")]);
        let lab = SigningKey::from_bytes(&[9; 32]);
        let mut seal = Seal::new("t0", f.iter().map(|(p, b)| (p.as_str(), b.as_slice())));
        seal.approve("A. Metrologist", "Head of laboratory", "t1", &lab);
        assert_eq!(seal.approval_problem(), None);
        let a = seal.approval.clone().unwrap();
        assert_eq!(a.key_fingerprint, key_fingerprint(&lab.verifying_key()));
        assert!(a.key_fingerprint.starts_with("SHA256:") && a.key_fingerprint.len() == 71);
        let json = seal.to_json();
        let r = verify_seal(Some(&json), Some(&Seal::hash_line(&json)), &f, None);
        assert!(r.intact(), "{}", r.text());
        assert!(
            r.text()
                .contains("approval by A. Metrologist (Head of laboratory) at t1")
        );

        // Another name, role or time under the same signature: refused.
        let mut forged = seal.clone();
        forged.approval.as_mut().unwrap().signer = "Someone Else".into();
        assert!(forged.approval_problem().is_some());
        let json = forged.to_json();
        let r = verify_seal(Some(&json), Some(&Seal::hash_line(&json)), &f, None);
        assert!(!r.intact());
        assert!(
            r.text().contains("! UNSIGNED approval by Someone Else"),
            "{}",
            r.text()
        );

        // A file added after the approval is not approved, and leaves it standing.
        let mut later = seal.clone();
        later.add("t2", "ratecal report", &[("report.md", b"x")]);
        assert_eq!(later.approval_problem(), None);
        assert_eq!(later.approved_additions(), Some(0));
        let mut g = f.clone();
        g.insert("report.md".into(), b"x".to_vec());
        let json = later.to_json();
        let r = verify_seal(Some(&json), Some(&Seal::hash_line(&json)), &g, None);
        assert!(r.intact(), "{}", r.text());
        assert!(
            r.text().contains("after the approval: not approved"),
            "{}",
            r.text()
        );
        // Claiming to cover the later addition breaks it.
        later.approval.as_mut().unwrap().additions = Some(1);
        assert!(later.approval_problem().is_some());
    }
}
