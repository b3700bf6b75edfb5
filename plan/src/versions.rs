//! Rules of a procedure folder: one file per version (`<version>.rcal`) and `versions.lock`,
//! which records each released version's SHA-256 over its canonical text. A released
//! version never changes; version numbers only increase.
//!
//! `versions.lock` is plain text, one released version a line, oldest first:
//! ```text
//! # comment
//! 1.0.0 5f1c...64 hex digits...
//! ```

use ratecal_grammar::ast::Span;
use ratecal_grammar::{Diagnostic, Source};
use std::cmp::Ordering;

/// Name of the lock file in a procedure folder.
pub const LOCK_FILE: &str = "versions.lock";

/// Extension of a procedure version file.
pub const EXTENSION: &str = "rcal";

/// A semantic version `MAJOR.MINOR.PATCH[-PRE]`, ordered as semver orders them (a
/// pre-release comes before its release; pre-release tags compare as text).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Version {
    /// Major, minor, patch.
    pub numbers: [u64; 3],
    /// Pre-release tag (`rc.1`), if any.
    pub pre: Option<String>,
}

impl Version {
    /// Parses `1.2.3` or `1.2.3-rc.1`; `None` if it is not a semantic version.
    pub fn parse(s: &str) -> Option<Version> {
        let (core, pre) = match s.split_once('-') {
            Some((c, p)) if !p.is_empty() => (c, Some(p.to_string())),
            Some(_) => return None,
            None => (s, None),
        };
        let mut it = core.split('.');
        let mut numbers = [0u64; 3];
        for n in &mut numbers {
            let part = it.next()?;
            if part.is_empty()
                || !part.bytes().all(|b| b.is_ascii_digit())
                || (part.len() > 1 && part.starts_with('0'))
            {
                return None;
            }
            *n = part.parse().ok()?;
        }
        it.next().is_none().then_some(Version { numbers, pre })
    }
}

impl Ord for Version {
    fn cmp(&self, other: &Self) -> Ordering {
        self.numbers
            .cmp(&other.numbers)
            .then_with(|| match (&self.pre, &other.pre) {
                (None, None) => Ordering::Equal,
                (None, Some(_)) => Ordering::Greater,
                (Some(_), None) => Ordering::Less,
                (Some(a), Some(b)) => a.cmp(b),
            })
    }
}

impl PartialOrd for Version {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl std::fmt::Display for Version {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let [a, b, c] = self.numbers;
        write!(f, "{a}.{b}.{c}")?;
        if let Some(p) = &self.pre {
            write!(f, "-{p}")?;
        }
        Ok(())
    }
}

/// The version a file name stands for (`1.1.0.rcal` -> `1.1.0`).
pub fn version_of_file_name(name: &str) -> Option<Version> {
    Version::parse(name.strip_suffix(EXTENSION)?.strip_suffix('.')?)
}

/// One released version recorded in `versions.lock`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LockEntry {
    /// Version as written.
    pub version: String,
    /// Lowercase hex SHA-256 of the canonical text.
    pub sha256: String,
    /// Byte range of the line in the lock text.
    pub span: (usize, usize),
    /// Who released it and with which key, for a line `ratecal release` wrote; `None` for
    /// an older hash-only line (still a release: unsigned).
    pub signed: Option<LockSignature>,
}

/// The signature of a release line: the signer's Ed25519 public key and signature over
/// [`release_message`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LockSignature {
    /// Lowercase hex of the 32-byte public key.
    pub public_key: String,
    /// Lowercase hex of the 64-byte signature.
    pub signature: String,
    /// The signer's name (the rest of the line).
    pub signer: String,
}

/// What a release signs: the folder's procedure version, its canonical hash and the signer.
pub fn release_message(version: &str, sha256: &str, signer: &str) -> String {
    format!("ratecal release\nversion {version}\nsha256 {sha256}\nsigner {signer}\n")
}

/// A line of `versions.lock`: `<version> <sha256>`, and for a signed release
/// ` <public key hex> <signature hex> <signer>`.
pub fn lock_line(version: &str, sha256: &str, signed: Option<&LockSignature>) -> String {
    match signed {
        None => format!("{version} {sha256}\n"),
        Some(s) => format!(
            "{version} {sha256} {} {} {}\n",
            s.public_key, s.signature, s.signer
        ),
    }
}

fn is_hex(s: &str, len: usize) -> bool {
    s.len() == len
        && s.bytes()
            .all(|b| b.is_ascii_digit() || (b'a'..=b'f').contains(&b))
}

/// Reads `versions.lock`: its entries, and a diagnostic per malformed line.
pub fn parse_lock(path: &str, text: &str) -> (Vec<LockEntry>, Vec<Diagnostic>) {
    let src = source(path, text);
    let mut entries = Vec::new();
    let mut errors = Vec::new();
    let mut offset = 0;
    for line in text.split_inclusive('\n') {
        let start = offset;
        offset += line.len();
        let content = line.trim_end_matches(['\n', '\r']);
        let trimmed = content.trim();
        if trimmed.is_empty() || trimmed.starts_with('#') {
            continue;
        }
        let lead = content.len() - content.trim_start().len();
        let span = (start + lead, trimmed.len());
        let fields: Vec<&str> = trimmed.split_whitespace().collect();
        let head =
            fields.len() >= 2 && Version::parse(fields[0]).is_some() && is_hex(fields[1], 64);
        let signed = if fields.len() >= 5 && is_hex(fields[2], 64) && is_hex(fields[3], 128) {
            // The signer is the rest of the line after the signature, spaces kept.
            let sig_end = trimmed.find(fields[3]).map_or(0, |k| k + fields[3].len());
            Some(LockSignature {
                public_key: fields[2].into(),
                signature: fields[3].into(),
                signer: trimmed[sig_end..].trim().to_string(),
            })
        } else {
            None
        };
        if head && (fields.len() == 2 || signed.is_some()) {
            entries.push(LockEntry {
                version: fields[0].into(),
                sha256: fields[1].into(),
                span,
                signed,
            });
        } else {
            errors.push(bad_lock_line(&src, span));
        }
    }
    (entries, errors)
}

/// Writes a `versions.lock` for released versions `(version, sha256)`, in the given order.
pub fn render_lock(entries: &[(String, String)]) -> String {
    let mut s = String::from(
        "# SHA-256 of the canonical (formatted) text of each released version, oldest first.\n\
         # A released version never changes: release a change under a new, higher version.\n",
    );
    for (v, h) in entries {
        s.push_str(&format!("{v} {h}\n"));
    }
    s
}

/// A version file of a procedure folder as the CLI hands it in.
#[derive(Debug, Clone)]
pub struct VersionFile {
    /// Path for messages (`procedures/imu-2d-standard/1.1.0.rcal`).
    pub path: String,
    /// File name (`1.1.0.rcal`).
    pub file_name: String,
    /// Its text (to point at the declared version).
    pub text: String,
    /// The version the procedure declares, when it parsed.
    pub declared: Option<String>,
    /// SHA-256 of its canonical text, when it parsed.
    pub sha256: Option<String>,
}

/// Everything in a procedure folder, as the CLI read it.
#[derive(Debug, Clone, Default)]
pub struct FolderData {
    /// Folder path for messages.
    pub path: String,
    /// Version files (names ending in `.rcal`).
    pub files: Vec<VersionFile>,
    /// `versions.lock` text, if present.
    pub lock: Option<String>,
    /// Names of anything else in the folder.
    pub others: Vec<String>,
}

fn source(path: &str, text: &str) -> Source {
    ratecal_grammar::source(path, text)
}

fn span((start, len): (usize, usize)) -> Span {
    Span::new(start, start + len)
}

/// `versions::released_changed`: a released version's canonical text no longer has the
/// recorded hash.
fn released_changed(
    lock: &Source,
    at: (usize, usize),
    version: &str,
    file: &str,
    actual: &str,
) -> Diagnostic {
    Diagnostic::error("versions::released_changed", format!("released version {version} changed without a new version number"))
        .label(span(at), "recorded here")
        .help(format!(
            "a released version never changes: restore {file} as released, or release the change under a new, higher version (its hash is {actual})"
        ))
        .with_source(lock)
}

/// `versions::not_increasing`: a version not above the one before it.
fn not_increasing(src: &Source, at: (usize, usize), version: &str, previous: &str) -> Diagnostic {
    Diagnostic::error(
        "versions::not_increasing",
        format!("version {version} does not increase: it must be higher than {previous}"),
    )
    .label(span(at), format!("not above {previous}"))
    .help(format!(
        "version numbers only increase: give the change a version higher than {previous}"
    ))
    .with_source(src)
}

/// `versions::release_missing`: a released version's file is gone.
fn release_missing(lock: &Source, at: (usize, usize), version: &str, file: &str) -> Diagnostic {
    Diagnostic::error(
        "versions::release_missing",
        format!("released version {version} has no file {file}"),
    )
    .label(span(at), "released here")
    .help(format!(
        "a released version stays in its folder: restore {file}"
    ))
    .with_source(lock)
}

/// `versions::name_mismatch`: the file name and the declared version disagree.
fn name_mismatch(src: &Source, at: (usize, usize), file: &str, declared: &str) -> Diagnostic {
    Diagnostic::error("versions::name_mismatch", format!("{file} declares version {declared}"))
        .label(span(at), "the file name says otherwise")
        .help(format!("name the file after its version ({declared}.{EXTENSION}), or change the version it declares"))
        .with_source(src)
}

/// `versions::stray_file`: neither a version file nor the lock.
fn stray_file(folder: &str, file: &str) -> Diagnostic {
    Diagnostic::error(
        "versions::stray_file",
        format!("{folder} holds {file}, which is not a version file"),
    )
    .help(format!(
        "a procedure folder holds only <version>.{EXTENSION} files and {LOCK_FILE}"
    ))
    .with_source(&source(&format!("{folder}/{file}"), ""))
}

/// `versions::bad_lock_line`: a lock line that is not `<version> <sha256>`.
fn bad_lock_line(lock: &Source, at: (usize, usize)) -> Diagnostic {
    Diagnostic::error(
        "versions::bad_lock_line",
        format!("malformed line in {LOCK_FILE}"),
    )
    .label(span(at), "expected `<version> <sha256>` [`<key> <signature> <signer>`]")
    .help("each line is `<version> <64 lowercase hex digits>` (`ratecal release` adds the key, signature and signer) or a # comment; write release lines with `ratecal release FOLDER@VERSION --signer NAME --key KEY`")
    .with_source(lock)
}

/// `versions::unreleased` (warning): a version file not in the lock.
fn unreleased(src: &Source, at: (usize, usize), version: &str, sha256: &str) -> Diagnostic {
    Diagnostic::warning(
        "versions::unreleased",
        format!("version {version} is not released (not in {LOCK_FILE})"),
    )
    .label(span(at), "a draft")
    .help(format!(
        "release it with `ratecal release FOLDER@{version} --signer NAME --key lab.key` (its canonical hash is {sha256})"
    ))
    .with_source(src)
}

/// `versions::unreleased` (warning) for a version file named any way (a path, or
/// `folder@version`): its folder's lock `lock_text` does not list it. `None` when it is
/// released (or its name is not a version's).
pub fn unreleased_file(
    path: &str,
    file_name: &str,
    text: &str,
    lock_text: &str,
) -> Option<Diagnostic> {
    let version = version_of_file_name(file_name)?;
    let (entries, _) = parse_lock(LOCK_FILE, lock_text);
    if entries
        .iter()
        .any(|e| Version::parse(&e.version).as_ref() == Some(&version))
    {
        return None;
    }
    let sha = ratecal_grammar::canonical(text).ok()?.sha256;
    let v = version.to_string();
    Some(unreleased(
        &source(path, text),
        version_span(text, &v),
        &v,
        &sha,
    ))
}

/// `versions::no_lock` (warning): no lock at all.
fn no_lock(folder: &str) -> Diagnostic {
    Diagnostic::warning(
        "versions::no_lock",
        format!("{folder} has no {LOCK_FILE}: no version is released"),
    )
    .help(format!(
        "release versions by listing `<version> <sha256>` lines in {LOCK_FILE}"
    ))
    .with_source(&source(&format!("{folder}/{LOCK_FILE}"), ""))
}

/// Where `version` is written in a procedure's text (its first occurrence after the
/// word `version`), for pointing at it.
fn version_span(text: &str, version: &str) -> (usize, usize) {
    let at = text
        .find("version")
        .and_then(|k| text[k..].find(version).map(|j| k + j));
    at.map_or((0, 0), |k| (k, version.len()))
}

/// Checks the rules of a procedure folder: every file is a version file or the lock; each
/// file declares the version its name says; each released version is present and its
/// canonical hash is the recorded one; the lock lists versions in increasing order; an
/// unreleased version is above every released one (warning: not released yet). Files that
/// did not parse (no `sha256`) are left to the checker's own diagnostics.
pub fn check_versions(folder: &FolderData) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    for f in &folder.others {
        out.push(stray_file(&folder.path, f));
    }
    for f in &folder.files {
        match (version_of_file_name(&f.file_name), &f.declared) {
            (None, _) => out.push(stray_file(&folder.path, &f.file_name)),
            (Some(v), Some(d)) if Version::parse(d).as_ref() != Some(&v) => {
                let src = source(&f.path, &f.text);
                out.push(name_mismatch(
                    &src,
                    version_span(&f.text, d),
                    &f.file_name,
                    d,
                ));
            }
            _ => {}
        }
    }
    let Some(lock_text) = &folder.lock else {
        out.push(no_lock(&folder.path));
        return out;
    };
    let lock_path = format!("{}/{LOCK_FILE}", folder.path.trim_end_matches('/'));
    let lock = source(&lock_path, lock_text);
    let (entries, errors) = parse_lock(&lock_path, lock_text);
    out.extend(errors);
    let mut newest: Option<(Version, &str)> = None;
    for e in &entries {
        let Some(v) = Version::parse(&e.version) else {
            continue;
        };
        if let Some((prev, prev_s)) = &newest
            && v <= *prev
        {
            out.push(not_increasing(&lock, e.span, &e.version, prev_s));
            continue;
        }
        newest = Some((v.clone(), &e.version));
        let file = folder
            .files
            .iter()
            .find(|f| version_of_file_name(&f.file_name).as_ref() == Some(&v));
        match file {
            None => out.push(release_missing(
                &lock,
                e.span,
                &e.version,
                &format!("{}.{EXTENSION}", e.version),
            )),
            Some(f) => match &f.sha256 {
                Some(h) if *h != e.sha256 => {
                    out.push(released_changed(&lock, e.span, &e.version, &f.file_name, h))
                }
                _ => {}
            },
        }
    }
    for f in &folder.files {
        let Some(v) = version_of_file_name(&f.file_name) else {
            continue;
        };
        if entries
            .iter()
            .any(|e| Version::parse(&e.version).as_ref() == Some(&v))
        {
            continue;
        }
        let src = source(&f.path, &f.text);
        let at = version_span(&f.text, &v.to_string());
        match &newest {
            Some((top, top_s)) if v <= *top => {
                out.push(not_increasing(&src, at, &v.to_string(), top_s))
            }
            _ => {
                if let Some(h) = &f.sha256 {
                    out.push(unreleased(&src, at, &v.to_string(), h));
                }
            }
        }
    }
    out
}

/// `check::changed_after_release`: `text`, the version file `file_name` of a procedure
/// folder whose lock is `lock_text`, was released with another canonical hash. `None` when
/// the version is not released, or is released as it stands.
pub fn changed_after_release(
    path: &str,
    file_name: &str,
    text: &str,
    lock_text: &str,
) -> Option<Diagnostic> {
    let version = version_of_file_name(file_name)?;
    let (entries, _) = parse_lock(LOCK_FILE, lock_text);
    let entry = entries
        .iter()
        .find(|e| Version::parse(&e.version).as_ref() == Some(&version))?;
    let now = ratecal_grammar::canonical(text).ok()?.sha256;
    if now == entry.sha256 {
        return None;
    }
    let v = version.to_string();
    Some(
        Diagnostic::error(
            "check::changed_after_release",
            format!("version {v} was changed after its release"),
        )
        .label(
            span(version_span(text, &v)),
            format!("released as {}, now {now}", entry.sha256),
        )
        .help(format!(
            "release a new version: copy the change to a higher version file and add it to {LOCK_FILE} (--allow-changed runs it anyway, and the run records it)"
        ))
        .with_source(&source(path, text)),
    )
}
