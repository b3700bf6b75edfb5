//! Giving a run folder back, byte for byte, from the store.

use crate::{Archive, ArchiveError, Result};
use ratecal_folder::hashes::sha256_hex;
use std::path::Path;

impl Archive {
    /// Writes run `key`'s files into `dest` (new or empty); returns the id and file count.
    pub async fn export(&self, key: &str, dest: &Path) -> Result<(String, usize)> {
        let id = self.resolve(key).await?;
        if dest.exists() {
            let mut rd = std::fs::read_dir(dest).map_err(|e| ArchiveError::io(dest, e))?;
            if rd.next().is_some() {
                return Err(ArchiveError::NotEmpty(dest.to_path_buf()));
            }
        }
        let files = self.files_of(&id).await?;
        for f in &files {
            let rel = Path::new(&f.path);
            // Paths come from the index; never write outside the destination.
            if crate::check::leaves_folder(&f.path) {
                return Err(ArchiveError::Io {
                    path: rel.to_path_buf(),
                    message: "stored path leaves the run folder".into(),
                });
            }
            let bytes = self
                .store
                .get(&self.pool, &f.sha256)
                .await?
                .filter(|b| sha256_hex(b) == f.sha256)
                .ok_or_else(|| ArchiveError::MissingFile(format!("{} ({})", f.path, f.sha256)))?;
            let out = dest.join(rel);
            if let Some(parent) = out.parent() {
                std::fs::create_dir_all(parent).map_err(|e| ArchiveError::io(parent, e))?;
            }
            ratecal_recording::commit::write_nofollow(&out, &bytes)
                .map_err(|e| ArchiveError::io(&out, e))?;
        }
        Ok((id, files.len()))
    }
}
