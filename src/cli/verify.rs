//! `ratecal verify RUN_DIR [--key lab.pub]`: checks every file of a run folder against the
//! seal the run wrote last (`seal.json`, whose own hash is in `seal.sha256`): each file
//! altered, missing or unknown to the seal is named. With `--key`, the seal must also be
//! signed by that key. A ratecal run folder that was never sealed (a crash before its seal,
//! docs/run-folders.md) is told apart from an altered one: its streams are checked against
//! the journal's running hash. Exit 0 intact; 1 altered, unknown files, a malformed seal, or
//! not signed by the key; 4 never sealed (or a change left unfinished by a crash); 2 error
//! (no such run folder, unreadable key).

use ratecal_folder::names::SEAL_FILE;
use ratecal_folder::verify::{self, Unsealed, verify_folder};
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

/// A ratecal run folder without a seal, or with a change a crash left unfinished: named with
/// its state (exit 4), or altered when its streams no longer match the journal (exit 1).
/// `None` for every other folder.
fn unsealed(dir: &Path) -> Option<ExitCode> {
    let help = format!(
        "help: `ratecal run --resume {}` finishes it and seals it",
        ratecal_folder::shell::quoted(dir)
    );
    match verify::unsealed(dir)? {
        Unsealed::Committing => {
            outln!(
                "UNFINISHED {}: a change was committed but not carried out (a crash); \
                 its seal is not yet in place",
                dir.display()
            );
            errln!("{help}");
            Some(ExitCode::from(4))
        }
        Unsealed::Altered(why) => {
            outln!(
                "ALTERED since it was recorded: {why} ({} was never sealed)",
                dir.display()
            );
            Some(ExitCode::from(1))
        }
        Unsealed::NeverSealed { state, what } => {
            outln!(
                "NEVER SEALED {} ({state}): {what}; its streams match the journal's running hash",
                dir.display()
            );
            errln!("{help}");
            Some(ExitCode::from(4))
        }
    }
}

/// Runs the subcommand.
pub fn main(args: Args) -> ExitCode {
    let dir = &args.run_dir;
    let key = match args
        .key
        .as_deref()
        .map(ratecal_folder::keys::verifying_key)
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
