//! `archive backup DEST`: a consistent copy as a folder archive (SQLite index + file store)
//! that another machine opens with `--archive DEST`, whatever the source backend.

use crate::ingest::{Folder, IndexFacts, LimitRow, ParamRow};
use crate::{Archive, ArchiveError, Backend, Location, Result};
use ratecal_folder::hashes::sha256_hex;
use sqlx::Row;
use std::collections::HashMap;
use std::path::Path;

impl Archive {
    /// Copies the archive into the new or empty folder `dest`; returns runs and files copied.
    pub async fn backup(&self, dest: &Path) -> Result<(usize, usize)> {
        if dest.exists()
            && std::fs::read_dir(dest)
                .map_err(|e| ArchiveError::io(dest, e))?
                .next()
                .is_some()
        {
            return Err(ArchiveError::NotEmpty(dest.to_path_buf()));
        }
        let folders = self.snapshot().await?;
        let target = Archive::open(&Location::Folder(dest.to_path_buf())).await?;
        // Files first (stored files never change, so copying after the snapshot is safe),
        // then the index in one transaction.
        let mut copied = std::collections::HashSet::new();
        for f in &folders {
            for (path, sha, _) in &f.files {
                if !copied.insert(sha.clone()) {
                    continue;
                }
                let bytes = self
                    .store
                    .get(&self.pool, sha)
                    .await?
                    .filter(|b| sha256_hex(b) == *sha)
                    .ok_or_else(|| ArchiveError::MissingFile(format!("{path} ({sha})")))?;
                target.store.put(&target.pool, sha, &bytes).await?;
            }
        }
        target.insert_many(&folders).await?;
        target.close().await;
        Ok((folders.len(), copied.len()))
    }

    /// Every run's index rows, read in one transaction (one consistent view).
    async fn snapshot(&self) -> Result<Vec<Folder>> {
        let mut tx = self.pool.begin().await?;
        if self.backend == Backend::Postgres {
            sqlx::query("SET TRANSACTION ISOLATION LEVEL REPEATABLE READ, READ ONLY")
                .execute(&mut *tx)
                .await?;
        }
        let runs = sqlx::query(
            "SELECT id, name, serial, model, procedure, version, procedure_sha256, station, \
             operator, started, ended, status, dry_run, verdict, temperature_c, humidity_pct, \
             pressure_kpa, vibration_g, imu FROM runs ORDER BY started, id",
        )
        .fetch_all(&mut *tx)
        .await?;
        let files: Vec<(String, String, String, i64)> = sqlx::query_as(
            "SELECT run_id, path, sha256, size FROM run_files ORDER BY run_id, path",
        )
        .fetch_all(&mut *tx)
        .await?;
        let params: Vec<(String, String, f64, f64, String)> =
            sqlx::query_as("SELECT run_id, name, value, u, unit FROM parameters")
                .fetch_all(&mut *tx)
                .await?;
        let limits: Vec<(String, String, String, f64, String)> =
            sqlx::query_as("SELECT run_id, quantity, op, limit_value, unit FROM limits")
                .fetch_all(&mut *tx)
                .await?;
        tx.commit().await?;
        let mut by_id: HashMap<String, Folder> = HashMap::new();
        let mut order = Vec::new();
        for r in runs {
            let facts = facts_of(&r)?;
            order.push(facts.id.clone());
            let id = facts.id.clone();
            by_id.insert(
                id,
                Folder {
                    dir: Default::default(),
                    files: Vec::new(),
                    facts,
                },
            );
        }
        for (run, path, sha, size) in files {
            if let Some(f) = by_id.get_mut(&run) {
                f.files.push((path, sha, size as u64));
            }
        }
        for (run, name, value, u, unit) in params {
            if let Some(f) = by_id.get_mut(&run) {
                f.facts.parameters.push(ParamRow {
                    name,
                    value,
                    u,
                    unit,
                });
            }
        }
        for (run, quantity, op, limit, unit) in limits {
            if let Some(f) = by_id.get_mut(&run) {
                f.facts.limits.push(LimitRow {
                    quantity,
                    op,
                    limit,
                    unit,
                });
            }
        }
        Ok(order
            .into_iter()
            .filter_map(|id| by_id.remove(&id))
            .collect())
    }
}

/// The index facts of a `runs` row selected in the column order of [`Archive::snapshot`].
fn facts_of(r: &sqlx::any::AnyRow) -> Result<IndexFacts> {
    Ok(IndexFacts {
        id: r.try_get(0)?,
        name: r.try_get(1)?,
        serial: r.try_get(2)?,
        model: r.try_get(3)?,
        procedure: r.try_get(4)?,
        version: r.try_get(5)?,
        procedure_sha256: r.try_get(6)?,
        station: r.try_get(7)?,
        operator: r.try_get(8)?,
        started: r.try_get(9)?,
        ended: r.try_get(10)?,
        status: r.try_get(11)?,
        dry_run: r.try_get::<i64, _>(12)? != 0,
        verdict: r.try_get(13)?,
        environment: [
            r.try_get(14)?,
            r.try_get(15)?,
            r.try_get(16)?,
            r.try_get(17)?,
        ],
        imu: r.try_get(18)?,
        parameters: Vec::new(),
        limits: Vec::new(),
    })
}
