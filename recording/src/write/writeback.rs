//! The disk's writes of a stream started early, beside the run.
//!
//! A 1 kHz stream grows by about 80 KB per simulated second: hundreds of MB in a dry run's
//! hour, which the checkpoint's `fsync` would otherwise write while the run waits for it.
//! Every [`WRITEBACK`] bytes the stream asks a thread of its own to sync the file, on a
//! descriptor opened separately: the kernel reports a failed write to every open file
//! description that syncs after it (errseq), so the checkpoint's own `fsync` still sees any
//! error and the folder's promises (docs/run-folders.md) are unchanged. The early sync only
//! moves the disk's work to a time the run is busy with something else.

use std::fs::{File, OpenOptions};
use std::path::Path;
use std::sync::mpsc::{self, SyncSender};
use std::thread::JoinHandle;

/// Bytes written between two early syncs.
pub(crate) const WRITEBACK: u64 = 16 << 20;

/// A thread that syncs one file when asked; asks that find it busy are merged.
pub(crate) struct Writeback {
    tx: Option<SyncSender<()>>,
    thread: Option<JoinHandle<()>>,
}

impl Writeback {
    /// `None` when the file cannot be opened again or the thread not started: the
    /// checkpoints then write everything, as without it.
    pub(crate) fn start(path: &Path) -> Option<Self> {
        let file = crate::commit::open_with_nofollow(OpenOptions::new().append(true), path).ok()?;
        let (tx, rx) = mpsc::sync_channel::<()>(1);
        let thread = std::thread::Builder::new()
            .name("recording-writeback".into())
            .spawn(move || sync_when_asked(&file, &rx))
            .ok()?;
        Some(Writeback {
            tx: Some(tx),
            thread: Some(thread),
        })
    }

    /// Asks for a sync without waiting; merged with one already asked for.
    pub(crate) fn ask(&self) {
        if let Some(tx) = &self.tx {
            let _ = tx.try_send(());
        }
    }
}

fn sync_when_asked(file: &File, rx: &mpsc::Receiver<()>) {
    for () in rx {
        // An error here is seen again by the checkpoint's sync (see the module's note).
        if file.sync_data().is_err() {
            return;
        }
    }
}

impl Drop for Writeback {
    fn drop(&mut self) {
        self.tx = None;
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}
