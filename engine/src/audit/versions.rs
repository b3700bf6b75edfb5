//! Rules of a procedure folder: one file per version (`<version>.rcal`) and `versions.lock`,
//! which records each released version's SHA-256 over its canonical text. A released
//! version never changes; version numbers only increase.
//!
//! `versions.lock` is plain text, one released version a line, oldest first:
//! ```text
//! # comment
//! 1.0.0 5f1c...64 hex digits...
//! ```

use miette::{Diagnostic, NamedSource, SourceSpan};
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
}

/// Reads `versions.lock`: its entries, and a diagnostic per malformed line.
pub fn parse_lock(path: &str, text: &str) -> (Vec<LockEntry>, Vec<VersionDiagnostic>) {
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
        let ok = fields.len() == 2
            && Version::parse(fields[0]).is_some()
            && fields[1].len() == 64
            && fields[1]
                .bytes()
                .all(|b| b.is_ascii_digit() || (b'a'..=b'f').contains(&b));
        if ok {
            entries.push(LockEntry {
                version: fields[0].into(),
                sha256: fields[1].into(),
                span,
            });
        } else {
            errors.push(VersionDiagnostic::BadLockLine {
                src: source(path, text),
                span: span.into(),
            });
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

fn source(path: &str, text: &str) -> NamedSource<String> {
    NamedSource::new(path, text.to_string())
}

/// A broken rule of a procedure folder.
#[derive(Debug, thiserror::Error, Diagnostic)]
pub enum VersionDiagnostic {
    /// A released version's canonical text no longer has the recorded hash.
    #[error("released version {version} changed without a new version number")]
    #[diagnostic(
        code(versions::released_changed),
        help(
            "a released version never changes: restore {file} as released, or release the change under a new, higher version (its hash is {actual})"
        )
    )]
    ReleasedChanged {
        /// Version.
        version: String,
        /// The version file.
        file: String,
        /// Its hash now.
        actual: String,
        /// The lock.
        #[source_code]
        src: NamedSource<String>,
        /// The lock line.
        #[label("recorded here")]
        span: SourceSpan,
    },
    /// Lock entries out of order, or a new version not above the last release.
    #[error("version {version} does not increase: it must be higher than {previous}")]
    #[diagnostic(
        code(versions::not_increasing),
        help("version numbers only increase: give the change a version higher than {previous}")
    )]
    NotIncreasing {
        /// The offending version.
        version: String,
        /// The version it must exceed.
        previous: String,
        /// The lock or the version file.
        #[source_code]
        src: NamedSource<String>,
        /// Where the version is written.
        #[label("not above {previous}")]
        span: SourceSpan,
    },
    /// A released version's file is gone.
    #[error("released version {version} has no file {file}")]
    #[diagnostic(
        code(versions::release_missing),
        help("a released version stays in its folder: restore {file}")
    )]
    ReleaseMissing {
        /// Version.
        version: String,
        /// Expected file name.
        file: String,
        /// The lock.
        #[source_code]
        src: NamedSource<String>,
        /// The lock line.
        #[label("released here")]
        span: SourceSpan,
    },
    /// The file name and the version inside disagree.
    #[error("{file} declares version {declared}")]
    #[diagnostic(
        code(versions::name_mismatch),
        help(
            "name the file after its version: {declared}.rcal, or change the version it declares"
        )
    )]
    NameMismatch {
        /// File name.
        file: String,
        /// Declared version.
        declared: String,
        /// The version file.
        #[source_code]
        src: NamedSource<String>,
        /// The declared version.
        #[label("the file name says otherwise")]
        span: SourceSpan,
    },
    /// Something that is neither a version file nor the lock.
    #[error("{folder} holds {file}, which is not a version file")]
    #[diagnostic(
        code(versions::stray_file),
        help("a procedure folder holds only <version>.rcal files and versions.lock")
    )]
    StrayFile {
        /// Folder.
        folder: String,
        /// File name.
        file: String,
    },
    /// A lock line that is not `<version> <sha256>`.
    #[error("malformed line in versions.lock")]
    #[diagnostic(
        code(versions::bad_lock_line),
        help("each line is `<version> <64 lowercase hex digits>` or a # comment")
    )]
    BadLockLine {
        /// The lock.
        #[source_code]
        src: NamedSource<String>,
        /// The line.
        #[label("expected `<version> <sha256>`")]
        span: SourceSpan,
    },
    /// A version file not in the lock: a draft, not released.
    #[error("version {version} is not released (not in versions.lock)")]
    #[diagnostic(
        code(versions::unreleased),
        severity(Warning),
        help("to release it, add this line to versions.lock: {version} {sha256}")
    )]
    Unreleased {
        /// Version.
        version: String,
        /// Its canonical hash.
        sha256: String,
    },
    /// No lock at all.
    #[error("{folder} has no versions.lock: no version is released")]
    #[diagnostic(
        code(versions::no_lock),
        severity(Warning),
        help("release versions by listing `<version> <sha256>` lines in versions.lock")
    )]
    NoLock {
        /// Folder.
        folder: String,
    },
}

/// Where `version` is written in a procedure's text (its first occurrence after the
/// word `version`), for pointing at it.
fn version_span(text: &str, version: &str) -> SourceSpan {
    let at = text
        .find("version")
        .and_then(|k| text[k..].find(version).map(|j| k + j));
    at.map_or((0, 0).into(), |k| (k, version.len()).into())
}

/// Checks the rules of a procedure folder: every file is a version file or the lock; each
/// file declares the version its name says; each released version is present and its
/// canonical hash is the recorded one; the lock lists versions in increasing order; an
/// unreleased version is above every released one (warning: not released yet). Files that
/// did not parse (no `sha256`) are left to the checker's own diagnostics.
pub fn check_versions(folder: &FolderData) -> Vec<VersionDiagnostic> {
    let mut out = Vec::new();
    for f in &folder.others {
        out.push(VersionDiagnostic::StrayFile {
            folder: folder.path.clone(),
            file: f.clone(),
        });
    }
    for f in &folder.files {
        match (version_of_file_name(&f.file_name), &f.declared) {
            (None, _) => out.push(VersionDiagnostic::StrayFile {
                folder: folder.path.clone(),
                file: f.file_name.clone(),
            }),
            (Some(v), Some(d)) if Version::parse(d).as_ref() != Some(&v) => {
                out.push(VersionDiagnostic::NameMismatch {
                    file: f.file_name.clone(),
                    declared: d.clone(),
                    src: source(&f.path, &f.text),
                    span: version_span(&f.text, d),
                })
            }
            _ => {}
        }
    }
    let Some(lock_text) = &folder.lock else {
        out.push(VersionDiagnostic::NoLock {
            folder: folder.path.clone(),
        });
        return out;
    };
    let lock_path = format!("{}/{LOCK_FILE}", folder.path.trim_end_matches('/'));
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
            out.push(VersionDiagnostic::NotIncreasing {
                version: e.version.clone(),
                previous: prev_s.to_string(),
                src: source(&lock_path, lock_text),
                span: e.span.into(),
            });
            continue;
        }
        newest = Some((v.clone(), &e.version));
        let file = folder
            .files
            .iter()
            .find(|f| version_of_file_name(&f.file_name).as_ref() == Some(&v));
        match file {
            None => out.push(VersionDiagnostic::ReleaseMissing {
                version: e.version.clone(),
                file: format!("{}.{EXTENSION}", e.version),
                src: source(&lock_path, lock_text),
                span: e.span.into(),
            }),
            Some(f) => match &f.sha256 {
                Some(h) if *h != e.sha256 => out.push(VersionDiagnostic::ReleasedChanged {
                    version: e.version.clone(),
                    file: f.file_name.clone(),
                    actual: h.clone(),
                    src: source(&lock_path, lock_text),
                    span: e.span.into(),
                }),
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
        match &newest {
            Some((top, top_s)) if v <= *top => out.push(VersionDiagnostic::NotIncreasing {
                version: v.to_string(),
                previous: top_s.to_string(),
                src: source(&f.path, &f.text),
                span: version_span(&f.text, &v.to_string()),
            }),
            _ => {
                if let Some(h) = &f.sha256 {
                    out.push(VersionDiagnostic::Unreleased {
                        version: v.to_string(),
                        sha256: h.clone(),
                    });
                }
            }
        }
    }
    out
}
