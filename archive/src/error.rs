//! Errors of the archive, each a diagnostic with a stable code and a help line.

use miette::Diagnostic;
use std::path::PathBuf;
use thiserror::Error;

/// Everything that can go wrong in the archive.
#[derive(Debug, Error, Diagnostic)]
pub enum ArchiveError {
    /// The database could not be reached or created.
    #[error("cannot open the archive {location}: {message}")]
    #[diagnostic(
        code(archive::open),
        help(
            "give --archive a folder (created if needed) or a postgres:// URL, or set RATECAL_ARCHIVE"
        )
    )]
    Open {
        /// Where.
        location: String,
        /// Why.
        message: String,
    },
    /// A query failed.
    #[error("the archive database failed: {0}")]
    #[diagnostic(
        code(archive::database),
        help("nothing half-added is visible; run `ratecal archive check` to confirm")
    )]
    Database(#[from] sqlx::Error),
    /// The schema could not be migrated.
    #[error("cannot bring the archive schema up to date: {0}")]
    #[diagnostic(
        code(archive::migrate),
        help("the archive may have been written by a newer ratecal; use that version")
    )]
    Migrate(#[from] sqlx::migrate::MigrateError),
    /// A file could not be read or written.
    #[error("{}: {message}", path.display())]
    #[diagnostic(
        code(archive::io),
        help("check that the path exists and that you may read and write it")
    )]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        message: String,
    },
    /// The folder is not a run folder `ratecal run` wrote.
    #[error("{} is not a run folder: {why}", path.display())]
    #[diagnostic(
        code(archive::not_a_run),
        help("give the folder `ratecal run --out` wrote (it holds manifest.yaml)")
    )]
    NotARun {
        /// The folder.
        path: PathBuf,
        /// Why.
        why: String,
    },
    /// The folder holds no archive.
    #[error("{} holds no archive", .0.display())]
    #[diagnostic(
        code(archive::no_archive),
        help(
            "give --archive the archive's folder or URL (or set RATECAL_ARCHIVE); `ratecal archive add RUN` creates one"
        )
    )]
    NoArchive(PathBuf),
    /// No run has this id.
    #[error("no run {0} in the archive")]
    #[diagnostic(
        code(archive::no_such_run),
        help("`ratecal archive list` shows the ids (a unique prefix is enough)")
    )]
    NoSuchRun(String),
    /// Several runs start with this id.
    #[error("{0} names several runs: {1}")]
    #[diagnostic(code(archive::ambiguous), help("give more characters of the id"))]
    Ambiguous(String, String),
    /// A stored file the index names is gone.
    #[error("stored file {0} is missing from the archive")]
    #[diagnostic(
        code(archive::missing_file),
        help("run `ratecal archive check`, then restore the archive from a backup")
    )]
    MissingFile(String),
    /// A date on the command line does not parse.
    #[error("{0:?} is not a date")]
    #[diagnostic(
        code(archive::bad_date),
        help("write dates as YYYY-MM-DD or YYYY-MM-DDTHH:MM:SSZ")
    )]
    BadDate(String),
    /// The destination of an export or backup already holds something.
    #[error("{} is not empty", .0.display())]
    #[diagnostic(
        code(archive::destination_not_empty),
        help("give a new or empty folder")
    )]
    NotEmpty(PathBuf),
}

impl ArchiveError {
    /// An IO error on a path.
    pub fn io(path: impl Into<PathBuf>, e: std::io::Error) -> Self {
        ArchiveError::Io {
            path: path.into(),
            message: e.to_string(),
        }
    }
}
