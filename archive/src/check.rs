//! `archive check`: every stored file's hash recomputed, every index row pointing at a
//! stored file.

use crate::{Archive, Result};
use ratecal_folder::hashes::sha256_hex;
use serde::Serialize;

/// What `check` found.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct CheckReport {
    /// Stored files whose hash was recomputed.
    pub files_checked: usize,
    /// Runs in the index.
    pub runs: usize,
    /// Stored files whose content no longer matches their name.
    pub corrupted: Vec<String>,
    /// Index rows naming a file the store does not hold: `run_id path sha256`.
    pub missing: Vec<String>,
    /// Index rows whose path is not a plain relative path in the run's folder (absolute,
    /// `..`, `.` or empty): an export would write outside it, or refuses it. `run_id path`.
    pub outside: Vec<String>,
    /// Stored files no run names (left by an interrupted add; harmless).
    pub unreferenced: usize,
    /// Unfinished writes left by an interrupted add (harmless).
    pub leftovers: usize,
    /// Unfinished writes removed (`check --fix`).
    pub removed: usize,
}

impl CheckReport {
    /// Whether the archive is consistent.
    pub fn ok(&self) -> bool {
        self.corrupted.is_empty() && self.missing.is_empty() && self.outside.is_empty()
    }

    /// A report for people.
    pub fn text(&self) -> String {
        let mut s = String::new();
        for c in &self.corrupted {
            s.push_str(&format!("! CORRUPTED  {c}\n"));
        }
        for m in &self.missing {
            s.push_str(&format!("! MISSING    {m}\n"));
        }
        for o in &self.outside {
            s.push_str(&format!(
                "! OUTSIDE    {o}: the path leaves the run's folder\n"
            ));
        }
        s.push_str(&format!(
            "{} run(s), {} stored file(s) rehashed, {} unreferenced, {} unfinished write(s)\n",
            self.runs, self.files_checked, self.unreferenced, self.leftovers
        ));
        if self.removed > 0 {
            s.push_str(&format!(
                "removed {} unfinished write(s) left by an interrupted add\n",
                self.removed
            ));
        } else if self.leftovers > 0 {
            s.push_str("help: `ratecal archive check --fix` removes the unfinished writes\n");
        }
        s.push_str(if self.ok() {
            "consistent: every stored file matches its hash and every index row points at a stored file\n"
        } else {
            "NOT consistent: restore the files named above from a backup\n"
        });
        s
    }
}

impl Archive {
    /// Rehashes every stored file and checks every index row against the store.
    pub async fn check(&self) -> Result<CheckReport> {
        self.check_fix(false).await
    }

    /// [`Archive::check`]; with `fix`, first removes the unfinished writes a killed add left.
    pub async fn check_fix(&self, fix: bool) -> Result<CheckReport> {
        let mut report = CheckReport::default();
        if fix {
            report.removed = self.store.remove_leftovers().len();
        }
        let stored = self.store.hashes(&self.pool).await?;
        let mut intact = std::collections::HashSet::new();
        for sha in &stored {
            report.files_checked += 1;
            match self.store.get(&self.pool, sha).await? {
                Some(b) if sha256_hex(&b) == *sha => {
                    intact.insert(sha.clone());
                }
                _ => report.corrupted.push(sha.clone()),
            }
        }
        let rows: Vec<(String, String, String)> =
            sqlx::query_as("SELECT run_id, path, sha256 FROM run_files ORDER BY run_id, path")
                .fetch_all(&self.pool)
                .await?;
        let corrupted: std::collections::HashSet<&String> = report.corrupted.iter().collect();
        let mut referenced = std::collections::HashSet::new();
        for (run, path, sha) in &rows {
            referenced.insert(sha.clone());
            if leaves_folder(path) {
                report.outside.push(format!("{run} {path:?}"));
            }
            if !intact.contains(sha) && !corrupted.contains(sha) {
                report.missing.push(format!("{run} {path} {sha}"));
            }
        }
        // Name the runs a corrupted file belongs to.
        for c in report.corrupted.iter_mut() {
            let runs: Vec<String> = rows
                .iter()
                .filter(|(_, _, sha)| sha == c)
                .map(|(run, path, _)| format!("{run}:{path}"))
                .collect();
            if !runs.is_empty() {
                *c = format!("{c} ({})", runs.join(", "));
            }
        }
        report.unreferenced = stored.iter().filter(|s| !referenced.contains(*s)).count();
        report.leftovers = self.store.leftovers().len();
        let n: (i64,) = sqlx::query_as("SELECT COUNT(*) FROM runs")
            .fetch_one(&self.pool)
            .await?;
        report.runs = n.0 as usize;
        Ok(report)
    }
}

/// Whether an index row's `path` is not a plain relative path inside its run's folder
/// (empty, absolute, `.` or `..` in it): `check` names it and `export` never writes it.
pub(crate) fn leaves_folder(path: &str) -> bool {
    use std::path::Component;
    let p = std::path::Path::new(path);
    path.is_empty() || p.components().any(|c| !matches!(c, Component::Normal(_)))
}

#[cfg(test)]
mod tests {
    use super::leaves_folder;

    #[test]
    fn only_plain_relative_paths_stay_in_the_folder() {
        for ok in ["imu.csv", "figures/a.svg"] {
            assert!(!leaves_folder(ok), "{ok}");
        }
        // `./imu.csv` stays in the folder, but no index row ratecal writes has it: export
        // has always refused it, and check names it with the others.
        for bad in ["", "/etc/passwd", "../x", "a/../../b", "a/..", "./imu.csv"] {
            assert!(leaves_folder(bad), "{bad}");
        }
    }
}
