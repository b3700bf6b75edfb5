//! The calibration archive: every run folder stored whole under its files' SHA-256 and
//! indexed (IMU serial and model, procedure, dates, environment, verdict, parameters), in an
//! embedded SQLite database beside a content-addressed file store, or on a lab's PostgreSQL
//! server. One query layer (sqlx's `Any` driver, portable SQL) serves both backends; the
//! schema is migrated by sqlx's migrator.
//!
//! ```text
//! run folder ─ ingest::read ─► Folder (files + index facts)
//!            ─ Archive::add  ─► files stored first, then the index rows in one transaction
//! index      ─ list / show / export / trend / backup / check
//! ```
//!
//! The CLI verifies a folder (`ratecal verify`) before it hands it to [`Archive::add`].

mod add;
mod backup;
mod certificate;
mod check;
mod dates;
mod db;
mod error;
mod explained;
mod export;
mod ingest;
mod location;
mod query;
mod store;
mod text;
pub mod trend;

pub use add::Added;
pub use certificate::{Content, Issued, Reservation};
pub use check::CheckReport;
pub use dates::{days_from_iso, iso_date};
pub use db::{Archive, Backend};
pub use error::ArchiveError;
pub use ingest::read as read_folder;
pub use ingest::{Folder, IndexFacts, LimitRow, ParamRow};
pub use location::Location;
pub use query::{Filter, RunDetail, RunSummary, StoredFile};
pub use text::{list_table, show_text};

/// Result of archive operations.
pub type Result<T> = std::result::Result<T, ArchiveError>;
