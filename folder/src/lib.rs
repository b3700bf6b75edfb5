//! The run folder (docs/run-folders.md): the names of its files, the one reader every
//! command uses, its states after a crash, the lock of its one writer, its seal (written,
//! added to, approved) and its verification against that seal.
//!
//! Every command that writes a run folder goes through here: it takes the [`lock`], writes
//! through [`sealing`] (files and seal replaced in one committed change, so a crash leaves
//! the old folder or the new one), and a command that publishes from a folder first asks
//! [`verify::require_intact`].

pub mod hashes;
pub mod keys;
pub mod lock;
pub mod names;
pub mod outputs;
pub mod read;
pub mod seal;
pub mod sealing;
pub mod shell;
pub mod state;
pub mod verify;

pub use lock::FolderLock;
pub use read::{ReadError, RunFolder};
pub use state::{State, state_of};
