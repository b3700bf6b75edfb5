//! Traceability of a run folder: the hashes a run recorded against what the folder holds
//! now. The CLI reads the files and hands them in; a file that is missing, changed, or no
//! longer parses is "altered".

use ratecal_recording::Manifest;

/// Lowercase hex SHA-256 of bytes: the recording crate's, which every seal uses.
pub use ratecal_recording::sha256_hex;

/// What a file in the run folder is now, as far as its recorded hash goes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Actual {
    /// Its hash now (of the bytes, or of the canonical text for a procedure).
    Hash(String),
    /// Not there (or unreadable).
    Missing,
    /// There, but it no longer parses (a procedure copy, the manifest): why.
    Unparsable(String),
}

/// The verdict on one file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Status {
    /// Hash as recorded.
    Intact,
    /// Hash differs.
    Altered {
        /// Recorded hash.
        expected: String,
        /// Hash now.
        actual: String,
    },
    /// The file is gone.
    Missing,
    /// The file no longer parses.
    Unparsable(String),
    /// The file is in the folder but not in the seal.
    Unknown,
    /// Not signed by the given key: why.
    Unsigned(String),
    /// In the folder but not readable as a regular file (a dangling symlink, a loop, a
    /// FIFO...): why.
    Unreadable(String),
}

/// One file checked against its recorded hash.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FileCheck {
    /// File name in the run folder (or what it is: `procedure copy (name.rcal)`).
    pub file: String,
    /// Verdict.
    pub status: Status,
}

/// Compares one file's recorded hash with what it is now.
pub fn check_file(file: &str, expected: &str, actual: Actual) -> FileCheck {
    let status = match actual {
        Actual::Hash(h) if h.eq_ignore_ascii_case(expected) => Status::Intact,
        Actual::Hash(h) => Status::Altered {
            expected: expected.to_string(),
            actual: h,
        },
        Actual::Missing => Status::Missing,
        Actual::Unparsable(why) => Status::Unparsable(why),
    };
    FileCheck {
        file: file.to_string(),
        status,
    }
}

/// The result of verifying a run folder.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct VerifyReport {
    /// Every check, in the order made.
    pub checks: Vec<FileCheck>,
}

impl VerifyReport {
    /// Whether every checked file is intact (and something was checked).
    pub fn intact(&self) -> bool {
        !self.checks.is_empty() && self.checks.iter().all(|c| c.status == Status::Intact)
    }

    /// The files that were altered, missing or no longer parse.
    pub fn altered(&self) -> impl Iterator<Item = &FileCheck> {
        self.checks.iter().filter(|c| c.status != Status::Intact)
    }

    /// The names of the files [`altered`](Self::altered) lists, comma-separated: what a
    /// refusal names.
    pub fn altered_names(&self) -> String {
        let names: Vec<&str> = self.altered().map(|c| c.file.as_str()).collect();
        names.join(", ")
    }

    /// A report for people: one line per file, then the verdict.
    pub fn text(&self) -> String {
        let mut s = String::new();
        for c in &self.checks {
            let line = match &c.status {
                Status::Intact => format!("  intact   {}\n", c.file),
                Status::Altered { expected, actual } => {
                    format!(
                        "! ALTERED  {}: recorded sha256 {expected}, now {actual}\n",
                        c.file
                    )
                }
                Status::Missing => format!("! ALTERED  {}: missing\n", c.file),
                Status::Unparsable(why) => {
                    format!("! ALTERED  {}: no longer parses ({why})\n", c.file)
                }
                Status::Unknown => format!("! UNKNOWN  {}: not in the seal\n", c.file),
                Status::Unsigned(why) => format!("! UNSIGNED {}: {why}\n", c.file),
                Status::Unreadable(why) => format!("! UNREADABLE {}: {why}\n", c.file),
            };
            s.push_str(&line);
        }
        // Not signed by the key asked for is not altered: the files may all be intact.
        let unsigned = |c: &&FileCheck| matches!(c.status, Status::Unsigned(_));
        let names: Vec<&str> = (self.altered().filter(|c| !unsigned(c)))
            .map(|c| c.file.as_str())
            .collect();
        let intact = self.checks.iter().filter(|c| c.status == Status::Intact);
        if names.is_empty() {
            s.push_str(&format!(
                "intact: {} file(s) match the hashes recorded by the run\n",
                intact.count()
            ));
        } else {
            s.push_str(&format!("ALTERED since the run: {}\n", names.join(", ")));
        }
        let unsigned: Vec<&str> = (self.checks.iter().filter(unsigned))
            .map(|c| c.file.as_str())
            .collect();
        if !unsigned.is_empty() {
            s.push_str(&format!(
                "NOT SIGNED by the key given: {}\n",
                unsigned.join(", ")
            ));
        }
        s
    }
}

/// Checks every data file the manifest lists in `run.files_sha256` (`read` returns a
/// file's bytes, `None` when it is missing), then the procedure copy against
/// `procedure.sha256` (`procedure`: the copy's name and its canonical hash or why it does
/// not parse) and the station copy against `run.station_sha256` (`station`: name and bytes).
pub fn verify_run(
    manifest: &Manifest,
    mut read: impl FnMut(&str) -> Option<Vec<u8>>,
    procedure: Option<(String, Actual)>,
    station: Option<(String, Option<Vec<u8>>)>,
) -> VerifyReport {
    let mut report = VerifyReport::default();
    if let Some(run) = &manifest.run {
        for (name, expected) in &run.files_sha256 {
            let actual = read(name).map_or(Actual::Missing, |b| Actual::Hash(sha256_hex(&b)));
            report.checks.push(check_file(name, expected, actual));
        }
    }
    if let (Some(p), Some((name, actual))) = (&manifest.procedure, procedure) {
        report.checks.push(check_file(
            &format!("{name} (procedure {} {})", p.name, p.version),
            &p.sha256,
            actual,
        ));
    }
    let station_sha = manifest
        .run
        .as_ref()
        .and_then(|r| r.station_sha256.as_ref());
    if let (Some(expected), Some((name, bytes))) = (station_sha, station) {
        let actual = bytes.map_or(Actual::Missing, |b| Actual::Hash(sha256_hex(&b)));
        report
            .checks
            .push(check_file(&format!("{name} (station)"), expected, actual));
    }
    report
}
