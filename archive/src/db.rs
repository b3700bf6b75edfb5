//! Opening an archive: the connection pool (sqlx `Any`), the schema migration, the file store.

use crate::store::Store;
use crate::{ArchiveError, Location, Result};
use sqlx::any::{AnyPoolOptions, install_default_drivers};
use sqlx::migrate::{Migration, MigrationType, Migrator};
use sqlx::{AnyPool, SqlSafeStr};
use std::time::Duration;

/// The database behind an archive.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Backend {
    /// Embedded SQLite file `index.sqlite`.
    Sqlite,
    /// A PostgreSQL server.
    Postgres,
}

/// An open archive.
pub struct Archive {
    pub(crate) pool: AnyPool,
    pub(crate) backend: Backend,
    pub(crate) store: Store,
    location: String,
}

/// The schema migrations, in order (embedded: the binary carries its schema).
fn migrator() -> Migrator {
    Migrator::with_migrations(vec![
        Migration::new(
            1,
            "schema".into(),
            MigrationType::Simple,
            include_str!("../migrations/0001_schema.sql").into_sql_str(),
            false,
        ),
        Migration::new(
            2,
            "certificates".into(),
            MigrationType::Simple,
            include_str!("../migrations/0002_certificates.sql").into_sql_str(),
            false,
        ),
        Migration::new(
            3,
            "certificate content".into(),
            MigrationType::Simple,
            include_str!("../migrations/0003_certificate_content.sql").into_sql_str(),
            false,
        ),
        Migration::new(
            4,
            "explained".into(),
            MigrationType::Simple,
            include_str!("../migrations/0004_explained.sql").into_sql_str(),
            false,
        ),
    ])
}

impl Archive {
    /// Opens an archive that exists (a folder must hold `index.sqlite`): for commands that
    /// only read, so that a mistyped `--archive` is an error, not a new empty archive.
    pub async fn open_existing(loc: &Location) -> Result<Self> {
        if let Location::Folder(dir) = loc
            && !dir.join("index.sqlite").is_file()
        {
            return Err(ArchiveError::NoArchive(dir.clone()));
        }
        Self::open(loc).await
    }

    /// Opens (creating if needed) the archive at `loc` and brings its schema up to date.
    pub async fn open(loc: &Location) -> Result<Self> {
        install_default_drivers();
        let open_err = |message: String| ArchiveError::Open {
            location: loc.display(),
            message,
        };
        let (url, backend, store) = match loc {
            Location::Folder(dir) => {
                std::fs::create_dir_all(dir.join("files")).map_err(|e| open_err(e.to_string()))?;
                let db = dir.join("index.sqlite");
                let url = format!("sqlite://{}?mode=rwc", db.display());
                (url, Backend::Sqlite, Store::Folder(dir.join("files")))
            }
            Location::Server { url, files } => {
                let store = match files {
                    Some(f) => {
                        std::fs::create_dir_all(f).map_err(|e| open_err(e.to_string()))?;
                        Store::Folder(f.clone())
                    }
                    None => Store::Database,
                };
                (url.clone(), Backend::Postgres, store)
            }
        };
        let pool = AnyPoolOptions::new()
            .max_connections(4)
            .acquire_timeout(Duration::from_secs(30))
            .after_connect(move |conn, _| {
                Box::pin(async move {
                    if backend == Backend::Sqlite {
                        // Several stations (processes) may add at once: wait for the lock.
                        sqlx::query("PRAGMA busy_timeout = 30000")
                            .execute(&mut *conn)
                            .await?;
                        sqlx::query("PRAGMA foreign_keys = ON")
                            .execute(&mut *conn)
                            .await?;
                    }
                    Ok(())
                })
            })
            .connect(&url)
            .await
            .map_err(|e| open_err(e.to_string()))?;
        if backend == Backend::Sqlite {
            // Readers (backup, list) never block a writer; persistent in the file. Another
            // process switching it at the same moment is fine to ignore.
            let _ = sqlx::query("PRAGMA journal_mode = WAL")
                .execute(&pool)
                .await;
        }
        migrate(&pool).await?;
        Ok(Archive {
            pool,
            backend,
            store,
            location: loc.display(),
        })
    }

    /// The backend in use.
    pub fn backend(&self) -> Backend {
        self.backend
    }

    /// Where the archive is, as a person would name it.
    pub fn location(&self) -> &str {
        &self.location
    }

    /// Closes the pool (waits for connections to finish).
    pub async fn close(self) {
        self.pool.close().await;
    }
}

/// Runs the migrator; two processes opening a fresh SQLite archive at once may race on the
/// first migration (SQLite has no migration lock), so a failure is retried after the other
/// one committed.
async fn migrate(pool: &AnyPool) -> Result<()> {
    let m = migrator();
    let mut last = None;
    for attempt in 0..5u64 {
        match m.run(pool).await {
            Ok(()) => return Ok(()),
            Err(e) => {
                last = Some(e);
                tokio::time::sleep(Duration::from_millis(50 * (attempt + 1))).await;
            }
        }
    }
    Err(last
        .map(ArchiveError::from)
        .unwrap_or_else(|| ArchiveError::Open {
            location: String::new(),
            message: "migration failed".into(),
        }))
}
