//! Inputs are read-only to outputs (issue 38): no `--out`, `--write-twin`,
//! `--draft-effects` or certificate path may name a run folder's recording, a file its seal
//! holds as recorded, the seal itself, or its lock or scratch. Checked before anything is
//! computed or written, by path (the file need not exist yet) and by identity (a hard link
//! or a symlink to one of them elsewhere).

use crate::names::{
    EXPLAIN, IMU, JOURNAL, LOCK_FILE, MANIFEST, PLAN, PROCEDURE, RESULTS, SEAL_FILE,
    SEAL_HASH_FILE, STATION, TABLE,
};
use crate::seal::Seal;
use miette::{Report, miette};
use ratecal_recording::commit::PENDING_DIR;
use std::path::{Path, PathBuf};

/// What ratecal derives from a recording and may write again: a sealed folder's copy of
/// one is replaced as an addition to its seal.
fn derived(name: &str) -> bool {
    [RESULTS, PLAN, EXPLAIN].contains(&name)
        || name.starts_with("report")
        || name.starts_with("explain-")
        || name.starts_with("certificate")
        || name.ends_with(".effect")
        || name.ends_with(".svg")
}

/// The files of run folder `dir` no output may replace, by name: the recording and its
/// run's inputs, the seal, the lock and scratch, and every other file the seal holds as
/// recorded (not one ratecal derived or added later).
fn inputs_of(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = [
        MANIFEST,
        IMU,
        TABLE,
        JOURNAL,
        PROCEDURE,
        STATION,
        SEAL_FILE,
        SEAL_HASH_FILE,
        LOCK_FILE,
        PENDING_DIR,
    ]
    .map(String::from)
    .to_vec();
    if let Some(seal) = std::fs::read_to_string(dir.join(SEAL_FILE))
        .ok()
        .and_then(|t| serde_json::from_str::<Seal>(&t).ok())
    {
        let added = |n: &str| seal.added.iter().any(|a| a.files.contains_key(n));
        names.extend(
            seal.files
                .keys()
                .filter(|n| !derived(n) && !added(n))
                .cloned(),
        );
    }
    names
}

fn is_run_folder(dir: &Path) -> bool {
    dir.join(MANIFEST).exists() || dir.join(SEAL_FILE).exists()
}

/// The folder `path` is in (`.` for a bare name).
fn parent(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// Whether `a` and `b` are one file (same device and inode; a symlink followed).
fn same_file(a: &Path, b: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        match (std::fs::metadata(a), std::fs::metadata(b)) {
            (Ok(x), Ok(y)) => x.dev() == y.dev() && x.ino() == y.ino(),
            _ => false,
        }
    }
    #[cfg(not(unix))]
    {
        match (std::fs::canonicalize(a), std::fs::canonicalize(b)) {
            (Ok(x), Ok(y)) => x == y,
            _ => false,
        }
    }
}

/// Refuses `out` (an output path of `what`, e.g. `--out`) when it names an input of the run
/// folder it lies in or of one of the run folders `runs` the command reads: nothing may be
/// written then.
pub fn refuse_inputs(out: &Path, what: &str, runs: &[&Path]) -> Result<(), Report> {
    let out_dir = parent(out);
    let mut dirs: Vec<PathBuf> = runs.iter().map(|p| p.to_path_buf()).collect();
    dirs.push(out_dir.clone());
    let out_name = out.file_name();
    let out_canon_dir = std::fs::canonicalize(&out_dir).ok();
    for dir in dirs.iter().filter(|d| is_run_folder(d)) {
        let canon = std::fs::canonicalize(dir).ok();
        for name in inputs_of(dir) {
            let input = dir.join(&name);
            let by_path = out_canon_dir.is_some()
                && out_canon_dir == canon
                && out_name.is_some_and(|n| n.to_string_lossy() == name.as_str());
            if by_path || same_file(out, &input) {
                return Err(miette!(
                    code = "run_folder::output_is_input",
                    help = "write the output elsewhere (another file name, or a folder outside \
                            the run): a run folder's recording, seal and recorded files are \
                            never replaced",
                    "{what} \"{}\" is \"{}\" of the run folder \"{}\": an output never replaces \
                     an input, nothing was written",
                    out.display(),
                    name,
                    dir.display()
                ));
            }
        }
    }
    Ok(())
}
