//! The state a run folder is in (docs/run-folders.md): every change of state is one atomic
//! rename, so a crash at any moment leaves one of these, and `run --resume` knows what to do
//! with each.

use crate::names::{SEAL_FILE, SEAL_HASH_FILE};
use crate::read::RunFolder;
use ratecal_recording::commit::pending_intent;
use std::path::Path;

/// A run folder's state.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum State {
    /// The run is recording, or stopped (a crash) while recording: `status: running`.
    Recording,
    /// The run ended (`status` completed, aborted or failed) but was never sealed: a crash
    /// during the analysis, the reports or the seal.
    RecordedUnsealed(String),
    /// A completed run, sealed.
    Sealed,
    /// An aborted (or failed) run, sealed: `run --resume` continues it.
    AbortedSealed(String),
    /// A change (a seal, a resume's streams) was committed but not yet carried out: any
    /// writer of the folder finishes it first.
    Committing,
    /// Not a run ratecal recorded (no `run` section in the manifest, or no manifest).
    Other,
}

impl State {
    /// The state's name as docs/run-folders.md and the commands give it.
    pub fn name(&self) -> &'static str {
        match self {
            State::Recording => "recording",
            State::RecordedUnsealed(_) => "recorded-unsealed",
            State::Sealed => "sealed",
            State::AbortedSealed(_) => "aborted-sealed",
            State::Committing => "committing",
            State::Other => "not a ratecal run",
        }
    }
}

/// The state of run folder `dir`, from its files (nothing is written).
pub fn state_of(dir: &Path) -> State {
    if pending_intent(dir).is_some() {
        return State::Committing;
    }
    let status = RunFolder::new(dir)
        .manifest_quiet()
        .and_then(|m| m.run.map(|r| r.status));
    // A seal's hash without the seal: the seal was removed (a commit that removes or adds
    // both is in the committing state until done), which `verify` calls altered.
    let there = |name: &str| std::fs::symlink_metadata(dir.join(name)).is_ok();
    let sealed = there(SEAL_FILE) || there(SEAL_HASH_FILE);
    match (status, sealed) {
        (None, _) => State::Other,
        (Some(s), false) if s == "running" => State::Recording,
        (Some(s), false) => State::RecordedUnsealed(s),
        (Some(s), true) if s == "completed" => State::Sealed,
        (Some(s), true) => State::AbortedSealed(s),
    }
}
