//! Procedure arguments shared by `check`, `fmt`, `run`, `diff` and `explain`: a file, a
//! folder (its newest version, by `plan::versions`' rule of version numbers) or
//! `folder@version`; reading it, imports from the filesystem, and the checked plan.

use ratecal_check::{CheckOptions, Sources, check_text};
use ratecal_grammar::Diagnostic;
use ratecal_plan::Plan;
use std::path::{Path, PathBuf};

pub use ratecal_plan::versions::EXTENSION;

/// A procedure file read from disk.
#[derive(Debug, Clone)]
pub struct ProcedureFile {
    /// Where it was read.
    pub path: PathBuf,
    /// The name diagnostics show.
    pub display: String,
    /// Its text.
    pub text: String,
}

fn io_error(what: &str, path: &Path, e: &std::io::Error) -> Diagnostic {
    Diagnostic::error(
        "io::read",
        format!("cannot read {what} `{}`: {e}", path.display()),
    )
    .help("give a procedure file, a procedure folder, or folder@version")
}

/// Every version file of a procedure folder, oldest first.
pub fn versions(dir: &Path) -> Result<Vec<(String, PathBuf)>, Diagnostic> {
    let files = crate::versions::version_files(dir).map_err(|e| io_error("folder", dir, &e))?;
    Ok(files.into_iter().map(|(v, p)| (v.to_string(), p)).collect())
}

/// Resolves an argument to a file: a file, a folder's newest released version (its newest
/// version when it releases none), or `folder@version`.
pub fn resolve(arg: &str) -> Result<PathBuf, Diagnostic> {
    resolve_for(arg, false)
}

/// As [`resolve`]; with `draft`, a folder stands for its newest version, released or not.
pub fn resolve_for(arg: &str, draft: bool) -> Result<PathBuf, Diagnostic> {
    let path = Path::new(arg);
    if path.is_file() {
        return Ok(path.to_path_buf());
    }
    if let Some((dir, version)) = arg.rsplit_once('@') {
        let dir = Path::new(dir);
        if dir.is_dir() {
            let file = dir.join(format!("{version}.{EXTENSION}"));
            if file.is_file() {
                return Ok(file);
            }
            let known: Vec<String> = versions(dir)?.into_iter().map(|v| v.0).collect();
            return Err(Diagnostic::error(
                "io::version",
                format!("`{}` has no version {version}", dir.display()),
            )
            .help(format!(
                "versions: {}",
                if known.is_empty() {
                    "none".to_string()
                } else {
                    known.join(", ")
                }
            )));
        }
    }
    if path.is_dir() {
        if !draft && let Some(p) = crate::release::newest_released(path) {
            return Ok(p);
        }
        return match versions(path)?.pop() {
            Some((_, p)) => Ok(p),
            None => Err(Diagnostic::error(
                "io::version",
                format!("`{}` holds no version file", path.display()),
            )
            .help(format!(
                "a procedure folder holds files named <version>.{EXTENSION}, e.g. 1.0.0.{EXTENSION}"
            ))),
        };
    }
    Err(
        Diagnostic::error("io::not_found", format!("no such procedure: `{arg}`"))
            .help("give a procedure file, a procedure folder, or folder@version"),
    )
}

/// Resolves and reads a procedure argument.
pub fn read(arg: &str) -> Result<ProcedureFile, Diagnostic> {
    let path = resolve(arg)?;
    let bytes = std::fs::read(&path).map_err(|e| io_error("file", &path, &e))?;
    // Invalid UTF-8 is replaced rather than refused: the parser then points at it.
    let text = String::from_utf8_lossy(&bytes).into_owned();
    Ok(ProcedureFile {
        display: path.display().to_string(),
        path,
        text,
    })
}

/// Imports resolved relative to the importing file's folder.
pub struct FsSources;

impl Sources for FsSources {
    fn load(&self, from: &str, name: &str) -> Result<(String, String), String> {
        let base = Path::new(from).parent().unwrap_or(Path::new("."));
        let path = base.join(name);
        match std::fs::read(&path) {
            Ok(b) => Ok((
                path.display().to_string(),
                String::from_utf8_lossy(&b).into_owned(),
            )),
            Err(e) => Err(format!("cannot read `{}`: {e}", path.display())),
        }
    }
}

/// Says a diagnostic on standard error.
pub fn report(d: &Diagnostic) {
    crate::console::err(format_args!("{}", d.render()), false);
}

/// Whether a version file was changed after its release (its folder's versions.lock records
/// another hash): refused with `check::changed_after_release` unless `allow`, when it is
/// reported as a warning and described for the manifest (`Ok(Some(..))`).
pub fn released_unchanged(
    file: &ProcedureFile,
    allow: bool,
) -> Result<Option<String>, crate::console::Reported> {
    use ratecal_audit::versions::{LOCK_FILE, changed_after_release};
    let Some(dir) = file.path.parent() else {
        return Ok(None);
    };
    let Ok(lock) = std::fs::read_to_string(dir.join(LOCK_FILE)) else {
        return Ok(None);
    };
    let name = file
        .path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let Some(d) = changed_after_release(&file.display, &name, &file.text, &lock) else {
        return Ok(None);
    };
    if !allow {
        report(&d);
        return Err(crate::console::Reported);
    }
    errln!(
        "warning: {} was changed after its release; run anyway (--allow-changed)",
        file.display
    );
    Ok(Some(format!(
        "{} differs from the text released in {LOCK_FILE}",
        file.display
    )))
}

/// A procedure loaded for auditing.
pub struct Loaded {
    /// Its checked plan.
    pub plan: Plan,
    /// SHA-256 of its canonical text.
    pub sha256: String,
}

/// Resolves `file | folder | folder@version`, reads, checks and hashes a procedure. Its
/// diagnostics go to standard error; `None` when it cannot be used.
pub fn load(spec: &str) -> Option<Loaded> {
    match read(spec) {
        Ok(f) => load_text(&f.display, &f.text),
        Err(d) => {
            report(&d);
            None
        }
    }
}

/// Checks and hashes one procedure text (diagnostics to standard error).
pub fn load_text(display: &str, text: &str) -> Option<Loaded> {
    let checked = match check_text(display, text, &FsSources, &CheckOptions::default()) {
        Ok(c) => c,
        Err(diags) => {
            diags.iter().for_each(report);
            return None;
        }
    };
    let sha256 = match ratecal_grammar::canonical(text) {
        Ok(c) => c.sha256,
        Err(d) => {
            report(&d);
            return None;
        }
    };
    Some(Loaded {
        plan: checked.plan,
        sha256,
    })
}
