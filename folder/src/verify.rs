//! Checking a run folder against its seal: every file, the seal's own hash, the signature;
//! the refusal of a command that would publish from a folder that fails it; and what a
//! folder that was never sealed is (its streams against the journal's running hash).

use crate::hashes::{FileCheck, Status, VerifyReport};
use crate::names::{IMU, JOURNAL, MANIFEST, TABLE};
use crate::names::{SEAL_FILE, SEAL_HASH_FILE};
use crate::read::RunFolder;
use crate::seal::verify_hashes;
use crate::state::{State, state_of};
use ed25519_dalek::VerifyingKey;
use std::path::Path;

/// Every file of a run folder against its seal (and its signature with `key`): what
/// `ratecal verify` and `ratecal archive add` check. Errs when `dir` is no run folder.
pub fn verify_folder(
    dir: &Path,
    key: Option<&VerifyingKey>,
) -> Result<VerifyReport, miette::Report> {
    // A dangling or looping manifest.yaml is still there: `verify` names it, unreadable.
    let there = |name: &str| std::fs::symlink_metadata(dir.join(name)).is_ok();
    let is_run = dir.is_dir() && (there(MANIFEST) || there(SEAL_FILE));
    let files = match crate::sealing::folder_files(dir) {
        Ok(f) if is_run => f,
        Ok(_) | Err(_) => {
            return Err(miette::miette!(
                code = "verify::not_a_run",
                help = "give the folder `ratecal run --out` wrote",
                "{} is not a run folder (no manifest.yaml, no seal.json)",
                dir.display()
            ));
        }
    };
    // Read only when regular: a FIFO in their place would block (it is named unreadable).
    let read = |name: &str| {
        let p = dir.join(name);
        ratecal_recording::regular(&p)
            .ok()
            .and_then(|()| std::fs::read_to_string(p).ok())
    };
    let seal = read(SEAL_FILE);
    let seal_hash = read(SEAL_HASH_FILE);
    Ok(verify_hashes(
        seal.as_deref(),
        seal_hash.as_deref(),
        &files,
        key,
    ))
}

/// Why a command that reads a run folder to publish from it (`report`, `explain`) refuses it:
/// its seal fails, or a ratecal run folder was never sealed. `Ok` for an intact folder and
/// for a recording another system wrote (no seal, no `run` section in its manifest).
pub fn require_intact(dir: &Path, command: &str) -> Result<(), miette::Report> {
    require_intact_replacing(dir, command, &[])
}

/// [`require_intact`] of a folder into which files `replacing` are about to be written:
/// an earlier addition's copy of one of them (an output, never a recorded input) may be
/// missing or changed, since it is written again and nothing is computed from it.
pub fn require_intact_replacing(
    dir: &Path,
    command: &str,
    replacing: &[&str],
) -> Result<(), miette::Report> {
    let sealed = std::fs::symlink_metadata(dir.join(SEAL_FILE)).is_ok();
    if !sealed {
        let ratecal_run = RunFolder::new(dir)
            .manifest_quiet()
            .is_some_and(|m| m.run.is_some());
        if !ratecal_run {
            return Ok(());
        }
        return Err(miette::miette!(
            code = "verify::never_sealed",
            help = format!(
                "a run seals its folder when it ends; finish it with `ratecal run --resume {}`",
                crate::shell::quoted(dir)
            ),
            "{} was never sealed: no {command} from it (nothing shows it unaltered)",
            dir.display()
        ));
    }
    let report = verify_folder(dir, None)?;
    let Some(failing) = fails_seal(&report, replacing) else {
        return Ok(());
    };
    Err(miette::miette!(
        code = "verify::altered",
        help = format!(
            "`ratecal verify {}` shows what changed; nothing was added to its seal",
            crate::shell::quoted(dir)
        ),
        "{} fails its seal ({}): no {command} from it",
        dir.display(),
        failing
    ))
}

/// What fails the seal in `report` (the files, comma-separated), but for an earlier
/// addition's copy of a file in `replacing` that is missing or changed; `None` when the
/// folder is intact (and something was checked).
pub fn fails_seal(report: &VerifyReport, replacing: &[&str]) -> Option<String> {
    let failing: Vec<&str> = (report.altered())
        .filter(|c| !replaced_now(c, replacing))
        .map(|c| c.file.as_str())
        .collect();
    (report.checks.is_empty() || !failing.is_empty()).then(|| failing.join(", "))
}

fn replaced_now(c: &FileCheck, names: &[&str]) -> bool {
    let name = c.file.split(" (").next().unwrap_or(&c.file);
    names.contains(&name)
        && c.file.contains("(written by `")
        && matches!(c.status, Status::Missing | Status::Altered { .. })
}

/// What a ratecal run folder without a seal is (docs/run-folders.md).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Unsealed {
    /// A change was committed but not carried out (a crash): its seal is not yet in place.
    Committing,
    /// Its streams no longer match the journal: why.
    Altered(String),
    /// Never sealed, its streams as the journal recorded them: the state's name and what
    /// happened, in words.
    NeverSealed {
        /// The state's name (`recording`, `recorded-unsealed`).
        state: &'static str,
        /// What happened.
        what: String,
    },
}

/// A ratecal run folder without a seal, or with a change a crash left unfinished, checked
/// against its journal. `None` for every other folder.
pub fn unsealed(dir: &Path) -> Option<Unsealed> {
    let state = state_of(dir);
    let tail_ok = match &state {
        State::Committing => return Some(Unsealed::Committing),
        State::Recording => true,
        State::RecordedUnsealed(_) => false,
        _ => return None,
    };
    let check = if tail_ok {
        streams_match(dir)
    } else {
        ratecal_recording::chain::check_folder(dir).unwrap_or_else(|e| Err(e.to_string()))
    };
    if let Err(why) = check {
        return Some(Unsealed::Altered(why));
    }
    let what = match &state {
        State::Recording => "it stopped while recording (or is recording now)".to_string(),
        State::RecordedUnsealed(s) => format!("the run ended ({s}) but its seal was never written"),
        _ => unreachable!("handled above"),
    };
    Some(Unsealed::NeverSealed {
        state: state.name(),
        what,
    })
}

/// A run still recording: every block the journal recorded is as written (a tail after the
/// last record is allowed: `--resume` cuts it).
fn streams_match(dir: &Path) -> Result<(), String> {
    use ratecal_recording::chain::{check_stream, journal_blocks};
    let blocks = journal_blocks(&dir.join(JOURNAL)).map_err(|e| e.to_string())?;
    for name in [IMU, TABLE] {
        let records = blocks.get(name).map(Vec::as_slice).unwrap_or_default();
        check_stream(&dir.join(name), records).map_err(|e| format!("{name}: {e}"))??;
    }
    Ok(())
}
