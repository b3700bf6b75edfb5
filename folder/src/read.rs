//! The one reader of a run folder: its manifest, results, plan, station copy, seal and
//! explain output, each by the name `names` gives it, each error located in the file it is
//! about. Report, certificate, archive, explain and the twin read a folder through this.

use crate::names::{EXPLAIN, MANIFEST, PLAN, RESULTS, SEAL_FILE, STATION};
use crate::seal::Seal;
use miette::{Diagnostic, NamedSource, SourceSpan};
use ratecal_plan::Plan;
use ratecal_recording::{Manifest, parse_manifest};
use serde::de::DeserializeOwned;
use std::path::{Path, PathBuf};

/// A file of a run folder that cannot be read, or whose JSON does not parse.
#[derive(Debug, thiserror::Error, Diagnostic)]
pub enum ReadError {
    /// Missing or unreadable.
    #[error("cannot read {path}: {message}")]
    #[diagnostic(code(run_folder::io), help("{help}"))]
    Io {
        /// The file.
        path: String,
        /// Why.
        message: String,
        /// What to do.
        help: String,
    },
    /// Not the JSON it should be, located.
    #[error(transparent)]
    #[diagnostic(transparent)]
    Json(Box<JsonError>),
}

/// A run folder's JSON file that does not parse, located.
#[derive(Debug, thiserror::Error, Diagnostic)]
#[error("{file} is not valid JSON: {message}")]
#[diagnostic(code(run_folder::json), help("{help}"))]
pub struct JsonError {
    /// The file.
    pub file: String,
    /// Why.
    pub message: String,
    /// What writes it.
    pub help: String,
    /// Its text.
    #[source_code]
    pub src: NamedSource<String>,
    /// Where.
    #[label("{message}")]
    pub span: SourceSpan,
}

impl ReadError {
    /// A file that cannot be read (or is not what it should be), with what to do.
    pub fn io(path: &Path, e: impl std::fmt::Display, help: &str) -> Self {
        ReadError::Io {
            path: path.display().to_string(),
            message: e.to_string(),
            help: help.into(),
        }
    }

    /// JSON that does not parse, located at serde's line and column.
    pub fn json(path: &Path, text: &str, e: &serde_json::Error, help: &str) -> Self {
        let offset: usize = text
            .split_inclusive('\n')
            .take(e.line().saturating_sub(1))
            .map(str::len)
            .sum::<usize>()
            + e.column().saturating_sub(1);
        let file = path.display().to_string();
        ReadError::Json(Box::new(JsonError {
            file: file.clone(),
            message: e.to_string(),
            help: help.into(),
            src: NamedSource::new(file, text.to_string()),
            span: (offset.min(text.len()), 1).into(),
        }))
    }
}

/// A run folder to read.
#[derive(Debug, Clone, Copy)]
pub struct RunFolder<'a> {
    dir: &'a Path,
}

impl<'a> RunFolder<'a> {
    /// The folder at `dir` (nothing is read yet).
    pub fn new(dir: &'a Path) -> Self {
        RunFolder { dir }
    }

    /// The path of its file `name`.
    pub fn path(&self, name: &str) -> PathBuf {
        self.dir.join(name)
    }

    /// The text of its file `name`, read only when it is a regular file (symlinks followed):
    /// a FIFO in its place would block, a device never end.
    pub fn read(&self, name: &str) -> std::io::Result<String> {
        let path = self.path(name);
        ratecal_recording::regular(&path)?;
        std::fs::read_to_string(path)
    }

    /// The text of its file `name`; `help` says what to do when it cannot be read.
    pub fn text(&self, name: &str, help: &str) -> Result<String, ReadError> {
        self.read(name)
            .map_err(|e| ReadError::io(&self.path(name), e, help))
    }

    /// `results.json`, parsed as `T` (the typed results or plain JSON).
    pub fn results<T: DeserializeOwned>(&self) -> Result<T, ReadError> {
        let path = self.path(RESULTS);
        let text = self.text(
            RESULTS,
            "run `ratecal analyze RUN_DIR` first to write results.json",
        )?;
        serde_json::from_str(&text).map_err(|e| {
            ReadError::json(
                &path,
                &text,
                &e,
                "results.json is written by `ratecal analyze RUN_DIR`",
            )
        })
    }

    /// The manifest's text and the manifest, validated (spec/recording-format.md); errors
    /// are located in its text.
    pub fn manifest(&self, help: &str) -> miette::Result<(String, Manifest)> {
        let path = self.path(MANIFEST);
        let text = self.text(MANIFEST, help)?;
        let manifest = parse_manifest(&path.display().to_string(), &text)?;
        Ok((text, manifest))
    }

    /// The manifest when there is one that parses; `None` otherwise (never an error).
    pub fn manifest_quiet(&self) -> Option<Manifest> {
        let text = self.read(MANIFEST).ok()?;
        parse_manifest(MANIFEST, &text).ok()
    }

    /// The checked plan the run saved beside its results, if any (and it parses).
    pub fn plan(&self) -> Option<Plan> {
        let text = self.read(PLAN).ok()?;
        serde_json::from_str(&text).ok()
    }

    /// `plan.json` when present; an error located in it when it does not parse.
    pub fn plan_checked(&self) -> Result<Option<Plan>, ReadError> {
        let path = self.path(PLAN);
        match self.read(PLAN) {
            Ok(text) => serde_json::from_str(&text).map(Some).map_err(|e| {
                ReadError::json(&path, &text, &e, "plan.json is written by `ratecal run`")
            }),
            Err(_) => Ok(None),
        }
    }

    /// The copy of the station file the run used: its path (as shown) and text.
    pub fn station_text(&self) -> Result<(String, String), ReadError> {
        let text = self.text(STATION, "a run folder keeps a copy of its station file")?;
        Ok((self.path(STATION).display().to_string(), text))
    }

    /// The seal when the folder holds one that parses.
    pub fn seal(&self) -> Option<Seal> {
        let text = self.read(SEAL_FILE).ok()?;
        serde_json::from_str(&text).ok()
    }

    /// What `ratecal explain` kept beside the run, if it parses.
    pub fn explain(&self) -> Option<serde_json::Value> {
        let text = self.read(EXPLAIN).ok()?;
        serde_json::from_str(&text).ok()
    }

    /// The IMU serial the manifest names (a YAML number such as `1234` too).
    pub fn serial_of(manifest: &serde_json::Value) -> Option<String> {
        match manifest.get("imu")?.get("serial")? {
            serde_json::Value::String(s) => Some(s.clone()),
            serde_json::Value::Number(n) => Some(n.to_string()),
            _ => None,
        }
    }
}
