//! `ratecal verify RUN_DIR [--key lab.pub]`: checks every file of a run folder against the
//! seal the run wrote last (`seal.json`, whose own hash is in `seal.sha256`): each file
//! altered, missing or unknown to the seal is named. With `--key`, the seal must also be
//! signed by that key. A ratecal run folder that was never sealed (a crash before its seal,
//! docs/run-folders.md) is told apart from an altered one: its streams are checked against
//! the journal's running hash. Exit 0 intact; 1 altered, unknown files, a malformed seal, or
//! not signed by the key; 4 never sealed (or a change left unfinished by a crash); 2 error
//! (no such run folder, unreadable key).

use ed25519_dalek::VerifyingKey;
use ratecal_engine::audit::seal::{SEAL_FILE, SEAL_HASH_FILE, verify_hashes};
use ratecal_engine::audit::verify::VerifyReport;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Arguments of `ratecal verify`.
#[derive(clap::Args)]
pub struct Args {
    /// Run folder (holds manifest.yaml and seal.json).
    run_dir: PathBuf,
    /// The lab's public key (`ratecal key new` wrote it): the seal must be signed by it.
    #[arg(long, value_name = "PUB")]
    key: Option<PathBuf>,
}

/// Every file of a run folder against its seal (and its signature with `key`): what
/// `ratecal verify` and `ratecal archive add` check. Errs when `dir` is no run folder.
pub fn verify_folder(
    dir: &Path,
    key: Option<&VerifyingKey>,
) -> Result<VerifyReport, miette::Report> {
    // A dangling or looping manifest.yaml is still there: `verify` names it, unreadable.
    let there = |name: &str| std::fs::symlink_metadata(dir.join(name)).is_ok();
    let is_run = dir.is_dir() && (there("manifest.yaml") || there(SEAL_FILE));
    let files = match super::seal::folder_files(dir) {
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
        ratecal_engine::recording::regular(&p)
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
    let sealed = std::fs::symlink_metadata(dir.join(SEAL_FILE)).is_ok();
    if !sealed {
        let ratecal_run = std::fs::read_to_string(dir.join("manifest.yaml"))
            .ok()
            .and_then(|t| ratecal_engine::recording::parse_manifest("manifest.yaml", &t).ok())
            .is_some_and(|m| m.run.is_some());
        if !ratecal_run {
            return Ok(());
        }
        return Err(miette::miette!(
            code = "verify::never_sealed",
            help = format!(
                "a run seals its folder when it ends; finish it with `ratecal run --resume {}`",
                dir.display()
            ),
            "{} was never sealed: no {command} from it (nothing shows it unaltered)",
            dir.display()
        ));
    }
    let report = verify_folder(dir, None)?;
    if report.intact() {
        return Ok(());
    }
    let names: Vec<&str> = report.altered().map(|c| c.file.as_str()).collect();
    Err(miette::miette!(
        code = "verify::altered",
        help = format!(
            "`ratecal verify {}` shows what changed; nothing was added to its seal",
            dir.display()
        ),
        "{} fails its seal ({}): no {command} from it",
        dir.display(),
        names.join(", ")
    ))
}

/// A ratecal run folder without a seal, or with a change a crash left unfinished: named with
/// its state (exit 4), or altered when its streams no longer match the journal (exit 1).
/// `None` for every other folder.
fn unsealed(dir: &Path) -> Option<ExitCode> {
    use super::run_folder::{State, state_of};
    let state = state_of(dir);
    let help = format!(
        "help: `ratecal run --resume {}` finishes it and seals it",
        dir.display()
    );
    let tail_ok = match &state {
        State::Committing => {
            outln!(
                "UNFINISHED {}: a change was committed but not carried out (a crash); \
                 its seal is not yet in place",
                dir.display()
            );
            errln!("{help}");
            return Some(ExitCode::from(4));
        }
        State::Recording => true,
        State::RecordedUnsealed(_) => false,
        _ => return None,
    };
    let check = if tail_ok {
        streams_match(dir)
    } else {
        ratecal_engine::recording::chain::check_folder(dir).unwrap_or_else(|e| Err(e.to_string()))
    };
    if let Err(why) = check {
        outln!(
            "ALTERED since it was recorded: {why} ({} was never sealed)",
            dir.display()
        );
        return Some(ExitCode::from(1));
    }
    let what = match &state {
        State::Recording => "it stopped while recording (or is recording now)".to_string(),
        State::RecordedUnsealed(s) => format!("the run ended ({s}) but its seal was never written"),
        _ => unreachable!("handled above"),
    };
    outln!(
        "NEVER SEALED {} ({}): {what}; its streams match the journal's running hash",
        dir.display(),
        state.name()
    );
    errln!("{help}");
    Some(ExitCode::from(4))
}

/// A run still recording: every block the journal recorded is as written (a tail after the
/// last record is allowed: `--resume` cuts it).
fn streams_match(dir: &Path) -> Result<(), String> {
    use ratecal_engine::recording::chain::{check_stream, journal_blocks};
    let blocks = journal_blocks(&dir.join("journal.jsonl")).map_err(|e| e.to_string())?;
    for name in ["imu.csv", "table.csv"] {
        let records = blocks.get(name).map(Vec::as_slice).unwrap_or_default();
        check_stream(&dir.join(name), records).map_err(|e| format!("{name}: {e}"))??;
    }
    Ok(())
}

/// Runs the subcommand.
pub fn main(args: Args) -> ExitCode {
    let dir = &args.run_dir;
    let key = match args
        .key
        .as_deref()
        .map(super::seal::verifying_key)
        .transpose()
    {
        Ok(k) => k,
        Err(e) => {
            errln!("{e:?}");
            return ExitCode::from(2);
        }
    };
    if let Some(code) = unsealed(dir) {
        return code;
    }
    let report = match verify_folder(dir, key.as_ref()) {
        Ok(r) => r,
        Err(e) => {
            errln!("{e:?}");
            return ExitCode::from(2);
        }
    };
    outln!("{}", report.text().trim_end());
    if !dir.join(SEAL_FILE).is_file() {
        errln!(
            "help: a run folder is sealed when its run ends; a folder without {SEAL_FILE} \
             cannot be shown to be unaltered"
        );
    }
    if report.intact() {
        if key.is_some() {
            outln!("signed by the given key");
        }
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    }
}
