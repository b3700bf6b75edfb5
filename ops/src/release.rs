//! Releasing a procedure version (`ratecal release FOLDER@VERSION --signer NAME --key KEY`):
//! the line for it in `versions.lock`, signed with the lab's key (the seal's signing code),
//! and what `check`, `log` and `run` read of a release: whether a version file is released,
//! by whom, and whether its signature holds.

use crate::procedure::{ProcedureFile, report};
use miette::{Report, miette};
use ratecal_grammar::Diagnostic;
use ratecal_plan::versions::{
    self, LOCK_FILE, LockEntry, LockSignature, Version, lock_line, parse_lock, release_message,
};
use std::path::Path;

/// Whether (and how) a version file is released.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Release {
    /// Not in a procedure folder (no `versions.lock` beside it): no release rules apply.
    Loose,
    /// Its folder's lock does not list it: a draft.
    Draft,
    /// Listed with a hash only (an older release): valid, unsigned.
    Unsigned,
    /// Listed and signed by this signer, the signature holding.
    Signed {
        /// Who released it.
        signer: String,
    },
}

/// A lock entry's signature: `None` when it holds (or there is none), else why not.
pub fn signature_problem(e: &LockEntry) -> Option<String> {
    let s = e.signed.as_ref()?;
    ratecal_folder::seal::text_signature_problem(
        &s.public_key,
        &s.signature,
        &release_message(&e.version, &e.sha256, &s.signer),
    )
}

/// How `log` describes an entry: `signed by NAME (SHA256:...)`, `unsigned`, or the problem.
pub fn describe(e: &LockEntry) -> String {
    match (&e.signed, signature_problem(e)) {
        (None, _) => "unsigned".into(),
        (Some(s), None) => format!("signed by {}", s.signer),
        (Some(_), Some(p)) => format!("BAD SIGNATURE: {p}"),
    }
}

/// `versions::bad_signature` for every signed line of a lock whose signature fails.
pub fn bad_signatures(lock_path: &str, lock_text: &str) -> Vec<Diagnostic> {
    let (entries, _) = parse_lock(lock_path, lock_text);
    let src = ratecal_grammar::source(lock_path, lock_text);
    entries
        .iter()
        .filter_map(|e| {
            let why = signature_problem(e)?;
            let (start, len) = e.span;
            Some(
                Diagnostic::error(
                    "versions::bad_signature",
                    format!("the release of {} is not signed as it says: {why}", e.version),
                )
                .label(
                    ratecal_grammar::ast::Span::new(start, start + len),
                    "this release line",
                )
                .help("release lines are written by `ratecal release`, never by hand: restore the line, or release again under a new version")
                .with_source(&src),
            )
        })
        .collect()
}

/// Whether the version file `file` is released, from the lock beside it.
pub fn release_of(file: &ProcedureFile) -> Release {
    let Some(dir) = file.path.parent() else {
        return Release::Loose;
    };
    let Ok(lock) = std::fs::read_to_string(dir.join(LOCK_FILE)) else {
        return Release::Loose;
    };
    let name = file
        .path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let Some(v) = versions::version_of_file_name(&name) else {
        return Release::Loose;
    };
    let (entries, _) = parse_lock(LOCK_FILE, &lock);
    match entries
        .iter()
        .find(|e| Version::parse(&e.version).as_ref() == Some(&v))
    {
        None => Release::Draft,
        Some(e) => match &e.signed {
            None => Release::Unsigned,
            Some(s) => Release::Signed {
                signer: s.signer.clone(),
            },
        },
    }
}

/// `versions::unreleased` (warning) for a version file however it was named, `None` when
/// it is released or not in a procedure folder.
pub fn unreleased_warning(file: &ProcedureFile) -> Option<Diagnostic> {
    let dir = file.path.parent()?;
    let lock = std::fs::read_to_string(dir.join(LOCK_FILE)).ok()?;
    let name = file.path.file_name()?.to_string_lossy().into_owned();
    versions::unreleased_file(&file.display, &name, &file.text, &lock)
}

/// What `check` says of a version file named by its path or `folder@version`: that it is
/// a draft (a warning), or that its release line's signature fails (an error).
pub fn file_diagnostics(file: &ProcedureFile) -> Vec<Diagnostic> {
    if let Some(w) = unreleased_warning(file) {
        return vec![w];
    }
    let Some(dir) = file.path.parent() else {
        return Vec::new();
    };
    let Ok(lock) = std::fs::read_to_string(dir.join(LOCK_FILE)) else {
        return Vec::new();
    };
    let version = file
        .path
        .file_name()
        .and_then(|n| versions::version_of_file_name(&n.to_string_lossy()))
        .map(|v| v.to_string())
        .unwrap_or_default();
    let path = dir.join(LOCK_FILE).display().to_string();
    bad_signatures(&path, &lock)
        .into_iter()
        .filter(|d| d.message.contains(&format!("release of {version} ")))
        .collect()
}

/// The newest released version file of a procedure folder (by the lock), `None` when it
/// releases none.
pub fn newest_released(dir: &Path) -> Option<std::path::PathBuf> {
    let lock = std::fs::read_to_string(dir.join(LOCK_FILE)).ok()?;
    let (entries, _) = parse_lock(LOCK_FILE, &lock);
    let files = crate::versions::version_files(dir).ok()?;
    files
        .into_iter()
        .rev()
        .find(|(v, _)| {
            entries
                .iter()
                .any(|e| Version::parse(&e.version).as_ref() == Some(v))
        })
        .map(|(_, p)| p)
}

/// Releases `spec` (`folder@version`): checks it, refuses a version already released or
/// not above the newest release, and appends its signed line to the folder's lock (written
/// whole, then renamed into place). Returns the line written.
pub fn release(spec: &str, signer: &str, key: &Path) -> Result<String, Report> {
    let Some((dir, version)) = spec.rsplit_once('@') else {
        return Err(miette!(
            code = "release::usage",
            help = "name the version: `ratecal release procedures/imu-2d-standard@1.2.0 ...`",
            "`{spec}` names no version"
        ));
    };
    let dir = Path::new(dir);
    let signer = signer.trim();
    if signer.is_empty() || signer.contains(['\n', '\r']) {
        return Err(miette!(
            code = "release::signer",
            help = "give the name of who releases it, on one line",
            "the signer's name is empty"
        ));
    }
    let key = ratecal_folder::keys::signing_key(key)?;
    let file = crate::procedure::read(spec).map_err(|d| {
        report(&d);
        miette!("{spec}: nothing released")
    })?;
    let Some(loaded) = crate::procedure::load_text(&file.display, &file.text) else {
        return Err(miette!(
            code = "release::does_not_check",
            help = "fix the errors above, then release",
            "{}: does not check; nothing released",
            file.display
        ));
    };
    if loaded.plan.version != version {
        return Err(miette!(
            code = "release::name_mismatch",
            help = "name the file after the version it declares",
            "{} declares version {}",
            file.display,
            loaded.plan.version
        ));
    }
    let lock_path = dir.join(LOCK_FILE);
    let lock_text =
        std::fs::read_to_string(&lock_path).unwrap_or_else(|_| versions::render_lock(&[]));
    let (entries, errors) = parse_lock(&lock_path.display().to_string(), &lock_text);
    if let Some(e) = errors.first() {
        report(e);
        return Err(miette!(
            "{}: fix the lock first; nothing released",
            lock_path.display()
        ));
    }
    let v = Version::parse(version).ok_or_else(|| miette!("`{version}` is not a version"))?;
    if let Some(e) = entries
        .iter()
        .find(|e| Version::parse(&e.version).as_ref() == Some(&v))
    {
        return Err(miette!(
            code = "release::already_released",
            help = "a released version never changes: release a change under a new, higher version",
            "{version} is already released ({})",
            describe(e)
        ));
    }
    if let Some(top) = entries
        .iter()
        .filter_map(|e| Version::parse(&e.version))
        .max()
        && v <= top
    {
        return Err(miette!(
            code = "release::not_increasing",
            help = "release versions in increasing order",
            "{version} is not above the newest release, {top}"
        ));
    }
    let message = release_message(version, &loaded.sha256, signer);
    let (public_key, signature) = ratecal_folder::seal::sign_text(&key, &message);
    let line = lock_line(
        version,
        &loaded.sha256,
        Some(&LockSignature {
            public_key,
            signature,
            signer: signer.to_string(),
        }),
    );
    let mut text = lock_text;
    if !text.is_empty() && !text.ends_with('\n') {
        text.push('\n');
    }
    text.push_str(&line);
    let tmp = dir.join(format!(".{LOCK_FILE}.tmp"));
    std::fs::write(&tmp, &text)
        .and_then(|()| std::fs::rename(&tmp, &lock_path))
        .map_err(|e| miette!("cannot write {}: {e}", lock_path.display()))?;
    Ok(line)
}
