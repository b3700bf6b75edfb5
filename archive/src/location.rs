//! Where an archive lives: a folder (SQLite index + file store) or a PostgreSQL server.

use std::path::PathBuf;

/// The place an archive is kept.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Location {
    /// A folder holding `index.sqlite` and the file store `files/`.
    Folder(PathBuf),
    /// A PostgreSQL URL; stored files go to `files` when given, else into the database.
    Server {
        /// `postgres://...`.
        url: String,
        /// Shared folder for the stored files.
        files: Option<PathBuf>,
    },
}

impl Location {
    /// Reads `--archive` (a folder or a `postgres://` URL), else `RATECAL_ARCHIVE`, else
    /// `./archive/`; `files` is the shared folder for a server's stored files.
    pub fn resolve(arg: Option<&str>, files: Option<PathBuf>) -> Self {
        let env = std::env::var("RATECAL_ARCHIVE")
            .ok()
            .filter(|s| !s.is_empty());
        let text = arg.map(str::to_string).or(env);
        match text {
            Some(t) => Self::parse(&t, files),
            None => Location::Folder(PathBuf::from("archive")),
        }
    }

    /// A folder path or a `postgres://` / `postgresql://` URL.
    pub fn parse(text: &str, files: Option<PathBuf>) -> Self {
        if text.starts_with("postgres://") || text.starts_with("postgresql://") {
            Location::Server {
                url: text.to_string(),
                files,
            }
        } else {
            Location::Folder(PathBuf::from(text))
        }
    }

    /// Whether an archive was named (`--archive` or `RATECAL_ARCHIVE`), for `ratecal run`.
    pub fn configured(arg: Option<&str>) -> bool {
        arg.is_some() || std::env::var("RATECAL_ARCHIVE").is_ok_and(|s| !s.is_empty())
    }

    /// How to name it to a person (a URL without its password).
    pub fn display(&self) -> String {
        match self {
            Location::Folder(p) => p.display().to_string(),
            Location::Server { url, .. } => redact(url),
        }
    }
}

/// A URL with the password replaced by `***`.
fn redact(url: &str) -> String {
    let Some((scheme, rest)) = url.split_once("://") else {
        return url.to_string();
    };
    let Some((auth, host)) = rest.split_once('@') else {
        return url.to_string();
    };
    match auth.split_once(':') {
        Some((user, _)) => format!("{scheme}://{user}:***@{host}"),
        None => url.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn urls_and_folders() {
        assert_eq!(
            Location::parse("/lab/archive", None),
            Location::Folder("/lab/archive".into())
        );
        assert!(matches!(
            Location::parse("postgres://u:p@h/db", None),
            Location::Server { .. }
        ));
        assert_eq!(
            Location::parse("postgres://u:secret@h/db", None).display(),
            "postgres://u:***@h/db"
        );
    }
}
