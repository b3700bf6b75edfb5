//! `ratecal verify RUN_DIR`: recomputes the hashes a run recorded in its manifest (each
//! data file of `run.files_sha256`, the procedure copy's canonical text against
//! `procedure.sha256`, the station copy against `run.station_sha256`) and says whether
//! anything was altered since the run. Exit 0 intact, 1 altered (naming what), 2 error
//! (no such folder, or nothing recorded to verify against).

use miette::IntoDiagnostic;
use ratecal_engine::audit::verify::{self, Actual};
use ratecal_engine::recording::Manifest;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Arguments of `ratecal verify`.
#[derive(clap::Args)]
pub struct Args {
    /// Run folder (holds manifest.yaml).
    run_dir: PathBuf,
}

/// Why a folder cannot be verified at all.
pub enum Unverifiable {
    /// No readable manifest.yaml.
    NotARun(miette::Report),
    /// The manifest records no hashes.
    NothingRecorded(miette::Report),
}

impl Unverifiable {
    /// The diagnostic.
    pub fn report(self) -> miette::Report {
        match self {
            Unverifiable::NotARun(r) | Unverifiable::NothingRecorded(r) => r,
        }
    }
}

/// Checks a run folder as `ratecal verify` does (also used by `ratecal archive add`).
pub fn verify_folder(dir: &Path) -> Result<verify::VerifyReport, Unverifiable> {
    let manifest_path = dir.join("manifest.yaml");
    let Ok(manifest_text) = std::fs::read_to_string(&manifest_path) else {
        return Err(Unverifiable::NotARun(miette::miette!(
            code = "verify::not_a_run",
            help = "give the folder `ratecal run --out` wrote",
            "{} is not a run folder (no readable manifest.yaml)",
            dir.display()
        )));
    };
    let manifest: Manifest = match serde_saphyr::from_str(&manifest_text) {
        Ok(m) => m,
        Err(e) => {
            // The manifest holds the hashes: if it no longer parses, it was altered.
            let check = verify::check_file(
                "manifest.yaml",
                "",
                Actual::Unparsable(first_line(&e.to_string()).to_string()),
            );
            return Ok(verify::VerifyReport {
                checks: vec![check],
            });
        }
    };
    let procedure = manifest.procedure.as_ref().map(|_| procedure_copy(dir));
    let station = manifest
        .run
        .as_ref()
        .and_then(|r| r.station_sha256.as_ref())
        .map(|_| station_copy(dir));
    let read = |name: &str| std::fs::read(dir.join(name)).ok();
    let report = verify::verify_run(&manifest, read, procedure, station);
    if report.checks.is_empty() {
        return Err(Unverifiable::NothingRecorded(miette::miette!(
            code = "verify::nothing_recorded",
            help = "ratecal records the hashes when a run ends; a recording from another system, \
                    or a run that did not end, cannot be verified",
            "{} records no hashes to verify against",
            manifest_path.display()
        )));
    }
    Ok(report)
}

/// Runs the subcommand.
pub fn main(args: Args) -> ExitCode {
    match verify_folder(&args.run_dir) {
        Err(e) => {
            eprintln!("{:?}", e.report());
            ExitCode::from(2)
        }
        Ok(report) => {
            print!("{}", report.text());
            if report.intact() {
                ExitCode::SUCCESS
            } else {
                ExitCode::from(1)
            }
        }
    }
}

fn first_line(s: &str) -> &str {
    s.lines().next().unwrap_or("")
}

/// Files of the run folder with an extension, sorted by name.
fn files_with_extension(dir: &Path, ext: &str) -> Vec<PathBuf> {
    let mut out: Vec<PathBuf> = std::fs::read_dir(dir)
        .into_diagnostic()
        .map(|rd| {
            rd.flatten()
                .map(|e| e.path())
                .filter(|p| p.extension().is_some_and(|e| e == ext))
                .collect()
        })
        .unwrap_or_default();
    out.sort();
    out
}

fn file_name(p: &Path) -> String {
    p.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// The procedure copy the run keeps (`*.rcal` in the folder) and its canonical hash.
fn procedure_copy(dir: &Path) -> (String, Actual) {
    let ext = ratecal_engine::audit::versions::EXTENSION;
    let Some(path) = files_with_extension(dir, ext).into_iter().next() else {
        return (format!("procedure copy (*.{ext})"), Actual::Missing);
    };
    let actual = match std::fs::read_to_string(&path) {
        Err(_) => Actual::Unparsable("not UTF-8 text".into()),
        Ok(text) => match ratecal_grammar::canonical(&text) {
            Ok(c) => Actual::Hash(c.sha256),
            Err(e) => Actual::Unparsable(first_line(&e.to_string()).to_string()),
        },
    };
    (file_name(&path), actual)
}

/// The station copy the run keeps (`station.yaml`, or another `*.yaml` than the manifest).
fn station_copy(dir: &Path) -> (String, Option<Vec<u8>>) {
    let preferred = dir.join("station.yaml");
    let path = if preferred.exists() {
        Some(preferred)
    } else {
        files_with_extension(dir, "yaml")
            .into_iter()
            .find(|p| file_name(p) != "manifest.yaml")
    };
    match path {
        Some(p) => (file_name(&p), std::fs::read(&p).ok()),
        None => ("station.yaml".into(), None),
    }
}
