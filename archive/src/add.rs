//! Adding a run: its files first (each stored whole under its hash), then its index rows in
//! one transaction, so a run is either wholly visible or not at all.
//!
//! One calibration, one entry: a run's archive id is the hash of its files, so approving
//! an archived run (which rewrites its seal) gives the folder another id. Adding the
//! approved folder replaces the unapproved entry of the same recording (the same
//! `manifest.yaml` and `imu.csv`) in the transaction that indexes it, and an unapproved
//! folder whose recording the archive holds already is not added again.

use crate::ingest::{self, Folder};
use crate::store::Store;
use crate::{Archive, ArchiveError, Result};
use ratecal_folder::names::{IMU, MANIFEST, SEAL_FILE};
use ratecal_folder::seal::Seal;
use std::path::Path;

/// What adding a run did.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Added {
    /// The run's archive id.
    pub id: String,
    /// False when the archive already held it (nothing changed).
    pub new: bool,
    /// Files stored (new and already present).
    pub files: usize,
    /// The unapproved entries of the same recording this approved folder replaced.
    pub replaced: Vec<String>,
    /// An unapproved folder not added because the archive holds its recording already
    /// (as `id`): true.
    pub same_recording: bool,
}

impl Archive {
    /// Stores and indexes the run folder `dir` (verify it first); adding it again changes nothing.
    pub async fn add(&self, dir: &Path) -> Result<Added> {
        let folder = ingest::read(dir)?;
        self.add_folder(&folder).await
    }

    /// Stores and indexes a folder already read.
    pub async fn add_folder(&self, folder: &Folder) -> Result<Added> {
        // What a killed add left unfinished goes first (never named by the index).
        self.store.remove_leftovers();
        let id = folder.facts.id.clone();
        let files = folder.files.len();
        if self.exists(&id).await? {
            return Ok(Added {
                id,
                new: false,
                files,
                replaced: Vec::new(),
                same_recording: false,
            });
        }
        let same = self.same_recording(folder).await?;
        let mut replaced = Vec::new();
        if approved(&std::fs::read(folder.dir.join(SEAL_FILE)).unwrap_or_default()) {
            for (other, approved) in same {
                if !approved && !self.has_certificate(&other).await? {
                    replaced.push(other);
                }
            }
        } else if let Some((other, _)) = same.into_iter().next() {
            return Ok(Added {
                id: other,
                new: false,
                files,
                replaced: Vec::new(),
                same_recording: true,
            });
        }
        for (path, sha, _) in &folder.files {
            if self.store.has(&self.pool, sha).await? {
                continue;
            }
            let full = folder.dir.join(path);
            // Copied streaming and hashed on the way; refused when the folder changed since
            // it was read (and verified).
            if !self.store.put_file(&self.pool, sha, &full).await? {
                return Err(ArchiveError::NotARun {
                    path: folder.dir.clone(),
                    why: format!("{path} changed while it was being added"),
                });
            }
        }
        ratecal_recording::commit::crash_point("archive-after-files");
        let new = if replaced.is_empty() {
            self.insert_index(folder).await?
        } else {
            let mut tx = self.pool.begin().await?;
            for other in &replaced {
                for sql in [
                    "DELETE FROM explained WHERE run_id = $1",
                    "DELETE FROM run_files WHERE run_id = $1",
                    "DELETE FROM parameters WHERE run_id = $1",
                    "DELETE FROM limits WHERE run_id = $1",
                    "DELETE FROM runs WHERE id = $1",
                ] {
                    sqlx::query(sql).bind(other).execute(&mut *tx).await?;
                }
            }
            let new = insert_rows(&mut tx, folder).await?;
            tx.commit().await?;
            new
        };
        Ok(Added {
            id,
            new,
            files,
            replaced,
            same_recording: false,
        })
    }

    /// The entries holding the same recording as `folder` (its `manifest.yaml` and
    /// `imu.csv`), other than itself, each with whether its seal holds an approval.
    async fn same_recording(&self, folder: &Folder) -> Result<Vec<(String, bool)>> {
        let sha = |name: &str| {
            folder
                .files
                .iter()
                .find(|(p, _, _)| p == name)
                .map(|(_, s, _)| s.clone())
        };
        let (Some(manifest), Some(imu)) = (sha(MANIFEST), sha(IMU)) else {
            return Ok(Vec::new());
        };
        let rows: Vec<(String, Option<String>)> = sqlx::query_as(
            "SELECT m.run_id, s.sha256 FROM run_files m \
             JOIN run_files i ON i.run_id = m.run_id AND i.path = $4 \
             LEFT JOIN run_files s ON s.run_id = m.run_id AND s.path = $5 \
             WHERE m.path = $6 AND m.sha256 = $1 AND i.sha256 = $2 \
             AND m.run_id <> $3 ORDER BY m.run_id",
        )
        .bind(&manifest)
        .bind(&imu)
        .bind(&folder.facts.id)
        .bind(IMU)
        .bind(SEAL_FILE)
        .bind(MANIFEST)
        .fetch_all(&self.pool)
        .await?;
        let mut out = Vec::with_capacity(rows.len());
        for (id, seal) in rows {
            let bytes = match seal {
                Some(sha) => self.store.get(&self.pool, &sha).await?.unwrap_or_default(),
                None => Vec::new(),
            };
            out.push((id, approved(&bytes)));
        }
        Ok(out)
    }

    /// Whether a certificate was issued from entry `id` (it is then never replaced).
    async fn has_certificate(&self, id: &str) -> Result<bool> {
        let row: Option<(String,)> =
            sqlx::query_as("SELECT number FROM certificates WHERE run_id = $1")
                .bind(id)
                .fetch_optional(&self.pool)
                .await?;
        Ok(row.is_some())
    }

    /// Whether the archive holds run `id`.
    pub async fn exists(&self, id: &str) -> Result<bool> {
        let row: Option<(String,)> = sqlx::query_as("SELECT id FROM runs WHERE id = $1")
            .bind(id)
            .fetch_optional(&self.pool)
            .await?;
        Ok(row.is_some())
    }

    /// Writes the index rows of a run in one transaction (false: it was already there).
    /// Public for bulk loading (benchmarks): the caller answers for the stored files.
    pub async fn insert_index(&self, folder: &Folder) -> Result<bool> {
        let mut tx = self.pool.begin().await?;
        let new = insert_rows(&mut tx, folder).await?;
        if new {
            tx.commit().await?;
        } else {
            tx.rollback().await?;
        }
        Ok(new)
    }

    /// Writes the index rows of many runs in one transaction (bulk loading, backups); the
    /// caller answers for the stored files. Returns how many were new.
    pub async fn insert_many(&self, folders: &[Folder]) -> Result<usize> {
        let mut tx = self.pool.begin().await?;
        let mut n = 0;
        for f in folders {
            n += usize::from(insert_rows(&mut tx, f).await?);
        }
        tx.commit().await?;
        Ok(n)
    }

    /// The folder store's root, if files are kept in a folder.
    pub fn files_folder(&self) -> Option<&Path> {
        match &self.store {
            Store::Folder(p) => Some(p),
            Store::Database => None,
        }
    }
}

/// Whether the seal `bytes` (`seal.json`) holds an approval (`ratecal approve`).
fn approved(bytes: &[u8]) -> bool {
    serde_json::from_slice::<Seal>(bytes).is_ok_and(|s| s.approval.is_some())
}

/// Inserts one run's rows; false when the run is already indexed (nothing written).
async fn insert_rows(tx: &mut sqlx::Transaction<'_, sqlx::Any>, folder: &Folder) -> Result<bool> {
    let f = &folder.facts;
    // The first statement writes, so SQLite takes its write lock at once (and waits
    // for another station's add instead of failing on a stale read snapshot).
    let done = sqlx::query(
        "INSERT INTO runs (id, name, serial, model, procedure, version, procedure_sha256, \
             station, operator, started, ended, status, dry_run, verdict, temperature_c, \
             humidity_pct, pressure_kpa, vibration_g, imu, added) VALUES ($1, $2, $3, $4, $5, \
             $6, $7, $8, $9, $10, $11, $12, $13, $14, $15, $16, $17, $18, $19, $20) \
             ON CONFLICT (id) DO NOTHING",
    )
    .bind(&f.id)
    .bind(&f.name)
    .bind(&f.serial)
    .bind(&f.model)
    .bind(&f.procedure)
    .bind(&f.version)
    .bind(&f.procedure_sha256)
    .bind(&f.station)
    .bind(f.operator.clone())
    .bind(&f.started)
    .bind(f.ended.clone())
    .bind(&f.status)
    .bind(i64::from(f.dry_run))
    .bind(&f.verdict)
    .bind(f.environment[0])
    .bind(f.environment[1])
    .bind(f.environment[2])
    .bind(f.environment[3])
    .bind(&f.imu)
    .bind(crate::dates::now_rfc3339())
    .execute(&mut **tx)
    .await?;
    if done.rows_affected() == 0 {
        return Ok(false);
    }
    for (path, sha, size) in &folder.files {
        sqlx::query("INSERT INTO run_files (run_id, path, sha256, size) VALUES ($1, $2, $3, $4)")
            .bind(&f.id)
            .bind(path)
            .bind(sha)
            .bind(*size as i64)
            .execute(&mut **tx)
            .await?;
    }
    for p in &f.parameters {
        sqlx::query(
            "INSERT INTO parameters (run_id, name, value, u, unit) VALUES ($1, $2, $3, $4, $5)",
        )
        .bind(&f.id)
        .bind(&p.name)
        .bind(p.value)
        .bind(p.u)
        .bind(&p.unit)
        .execute(&mut **tx)
        .await?;
    }
    for l in &f.limits {
        sqlx::query("INSERT INTO limits (run_id, quantity, op, limit_value, unit) VALUES ($1, $2, $3, $4, $5)")
                .bind(&f.id)
                .bind(&l.quantity)
                .bind(&l.op)
                .bind(l.limit)
                .bind(&l.unit)
                .execute(&mut **tx)
                .await?;
    }
    Ok(true)
}
