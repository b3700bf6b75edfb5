//! The files a procedure imports, kept in the run folder beside `procedure.rcal`: the run
//! folder then holds everything that decided the run (an imported file may set its limits),
//! and `--resume` checks the procedure against those copies, not against whatever the lab's
//! files say by then.
//!
//! Each import is stored under `imports/` at its path relative to the procedure's folder,
//! `..` written as `^` (`import "../lab/limits.rcal"` becomes `imports/^/lab/limits.rcal`).

use crate::procedure::FsSources;
use ratecal_check::Sources;
use ratecal_recording::sha256_hex;
use std::cell::RefCell;
use std::collections::{BTreeMap, HashMap};
use std::path::{Component, Path, PathBuf};

/// The folder of a run that holds the imported files.
pub const IMPORTS_DIR: &str = "imports";

/// Where imports are read from.
enum Origin {
    /// The lab's files, relative to the importing file (as `ratecal check` reads them).
    Files,
    /// A run folder's `imports/`.
    RunFolder(PathBuf),
}

/// [`Sources`] that remembers every file it loads by its path relative to the procedure.
pub struct Imports {
    origin: Origin,
    /// Display name of each file loaded so far (the procedure first) -> its relative path.
    relative: RefCell<HashMap<String, PathBuf>>,
    /// Relative path and text of each import, in load order.
    loaded: RefCell<Vec<(PathBuf, String)>>,
}

impl Imports {
    /// Imports of the procedure displayed as `procedure`, read from the lab's files.
    pub fn from_files(procedure: &str) -> Self {
        Self::new(Origin::Files, procedure)
    }

    /// Imports of `run_dir/procedure.rcal` (displayed as `procedure`), read from the run's
    /// copies.
    pub fn from_run(run_dir: &Path, procedure: &str) -> Self {
        Self::new(Origin::RunFolder(run_dir.to_path_buf()), procedure)
    }

    fn new(origin: Origin, procedure: &str) -> Self {
        let relative = HashMap::from([(procedure.to_string(), PathBuf::from("procedure"))]);
        Imports {
            origin,
            relative: RefCell::new(relative),
            loaded: RefCell::new(Vec::new()),
        }
    }

    /// SHA-256 of each saved copy, by its path in the run folder (`imports/^/lab/l.rcal`),
    /// for the manifest's `run.files_sha256`, which `ratecal verify` checks.
    pub fn hashes(&self) -> BTreeMap<String, String> {
        self.loaded
            .borrow()
            .iter()
            .map(|(rel, text)| (run_path(rel), sha256_hex(text.as_bytes())))
            .collect()
    }

    /// Writes a copy of every import loaded so far into `run_dir/imports/`.
    pub fn save(&self, run_dir: &Path) -> std::io::Result<()> {
        for (rel, text) in self.loaded.borrow().iter() {
            let path = run_dir.join(run_path(rel));
            if let Some(parent) = path.parent() {
                std::fs::create_dir_all(parent)?;
            }
            ratecal_recording::commit::write_nofollow(&path, text.as_bytes())?;
        }
        Ok(())
    }
}

impl Sources for Imports {
    fn load(&self, from: &str, name: &str) -> Result<(String, String), String> {
        let base = self
            .relative
            .borrow()
            .get(from)
            .and_then(|p| p.parent().map(Path::to_path_buf))
            .unwrap_or_default();
        let rel = normalize(&base.join(name));
        let (display, text) = match &self.origin {
            Origin::Files => FsSources.load(from, name)?,
            Origin::RunFolder(dir) => {
                let path = dir.join(IMPORTS_DIR).join(encode(&rel));
                match std::fs::read(&path) {
                    Ok(b) => (
                        path.display().to_string(),
                        String::from_utf8_lossy(&b).into_owned(),
                    ),
                    Err(e) => {
                        return Err(format!(
                            "the run folder has no copy of `{name}` ({}: {e})",
                            path.display()
                        ));
                    }
                }
            }
        };
        self.relative
            .borrow_mut()
            .insert(display.clone(), rel.clone());
        self.loaded.borrow_mut().push((rel, text.clone()));
        Ok((display, text))
    }
}

/// Where the copy of the import at `rel` (relative to the procedure) goes in a run folder,
/// `/`-separated on every platform.
fn run_path(rel: &Path) -> String {
    let parts: Vec<_> = encode(rel)
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    format!("{IMPORTS_DIR}/{}", parts.join("/"))
}

/// `a/./b/../c` -> `a/c`; a `..` that climbs above the start is kept.
fn normalize(p: &Path) -> PathBuf {
    let mut out: Vec<Component> = Vec::new();
    for c in p.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir if matches!(out.last(), Some(Component::Normal(_))) => {
                out.pop();
            }
            c => out.push(c),
        }
    }
    out.iter().collect()
}

/// A relative path as stored under `imports/`: `..` becomes `^`, and a root or drive (an
/// absolute import) is dropped.
fn encode(rel: &Path) -> PathBuf {
    rel.components()
        .filter_map(|c| match c {
            Component::ParentDir => Some("^".as_ref()),
            Component::Normal(s) => Some(s),
            _ => None,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_paths_climb_and_encode() {
        assert_eq!(normalize(Path::new("a/./b/../c")), PathBuf::from("a/c"));
        assert_eq!(
            normalize(Path::new("x/../../lab/l.rcal")),
            PathBuf::from("../lab/l.rcal")
        );
        assert_eq!(
            encode(Path::new("../../lab/l.rcal")),
            PathBuf::from("^/^/lab/l.rcal")
        );
        assert_eq!(
            encode(Path::new("/etc/l.rcal")),
            PathBuf::from("etc/l.rcal")
        );
    }

    /// Imports are saved at their place relative to the procedure, nested ones relative to
    /// the file that imports them, and a run folder gives back the same texts.
    #[test]
    fn saved_imports_load_back_from_the_run_folder() {
        let lab = tempfile::tempdir().unwrap();
        let procs = lab.path().join("procedures/p");
        std::fs::create_dir_all(&procs).unwrap();
        std::fs::create_dir_all(lab.path().join("lab")).unwrap();
        std::fs::write(lab.path().join("lab/limits.rcal"), "A").unwrap();
        std::fs::write(lab.path().join("lab/more.rcal"), "B").unwrap();
        let proc_name = procs.join("1.0.0.rcal").display().to_string();
        let files = Imports::from_files(&proc_name);
        let (d1, t1) = files.load(&proc_name, "../../lab/limits.rcal").unwrap();
        let (_, t2) = files.load(&d1, "more.rcal").unwrap();
        assert_eq!((t1.as_str(), t2.as_str()), ("A", "B"));
        assert!(files.load(&proc_name, "absent.rcal").is_err());

        let run = tempfile::tempdir().unwrap();
        files.save(run.path()).unwrap();
        let saved = run.path().join("imports/^/^/lab");
        assert_eq!(
            std::fs::read_to_string(saved.join("more.rcal")).unwrap(),
            "B"
        );

        let copy_name = run.path().join("procedure.rcal").display().to_string();
        let back = Imports::from_run(run.path(), &copy_name);
        let (d1, t1) = back.load(&copy_name, "../../lab/limits.rcal").unwrap();
        let (_, t2) = back.load(&d1, "more.rcal").unwrap();
        assert_eq!((t1.as_str(), t2.as_str()), ("A", "B"));
        let err = back.load(&copy_name, "absent.rcal").unwrap_err();
        assert!(err.contains("no copy of `absent.rcal`"), "{err}");
    }
}
