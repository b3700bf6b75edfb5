//! `ratecal log FOLDER`: every version of a procedure folder, oldest first, with the
//! SHA-256 of its canonical text, whether `versions.lock` records it as released, and a
//! one-line summary of its semantic changes from the version before. Exit 0, or 2 when
//! the folder or one of its versions cannot be read or checked.

use ratecal_audit::versions::{self, FolderData, LOCK_FILE, Version, VersionFile};
use ratecal_audit::{diff, render};
use ratecal_grammar::ast::TopItem;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Arguments of `ratecal log`.
#[derive(clap::Args)]
pub struct Args {
    /// Procedure folder (one `<version>.rcal` per version and `versions.lock`).
    folder: PathBuf,
}

/// Version files of a folder, sorted by version.
pub(crate) fn version_files(folder: &Path) -> std::io::Result<Vec<(Version, PathBuf)>> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(folder)? {
        let path = entry?.path();
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        if let Some(v) = versions::version_of_file_name(&name) {
            out.push((v, path));
        }
    }
    out.sort_by(|a, b| a.0.cmp(&b.0));
    Ok(out)
}

/// Reads a procedure folder for the version rules: each version file's declared version
/// and canonical hash, `versions.lock`, and anything else present.
pub(crate) fn folder_data(folder: &Path) -> std::io::Result<FolderData> {
    let mut data = FolderData {
        path: folder.display().to_string(),
        ..FolderData::default()
    };
    let mut names: Vec<String> = std::fs::read_dir(folder)?
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    for name in names {
        let path = folder.join(&name);
        if name == LOCK_FILE {
            data.lock = std::fs::read_to_string(&path).ok();
        } else if name.ends_with(&format!(".{}", versions::EXTENSION)) {
            let text = String::from_utf8_lossy(&std::fs::read(&path)?).into_owned();
            let file = ratecal_grammar::parse(&text).ok();
            let declared = file.and_then(|f| {
                f.body.items.into_iter().find_map(|i| match i.node {
                    TopItem::Procedure(p) => Some(p.version.node),
                    _ => None,
                })
            });
            let sha256 = ratecal_grammar::canonical(&text).ok().map(|c| c.sha256);
            data.files.push(VersionFile {
                path: path.display().to_string(),
                file_name: name,
                text,
                declared,
                sha256,
            });
        } else {
            data.others.push(name);
        }
    }
    Ok(data)
}

/// The version rules of a procedure folder (`ratecal check FOLDER` calls this).
pub(crate) fn check_folder(folder: &Path) -> Vec<ratecal_grammar::Diagnostic> {
    match folder_data(folder) {
        Ok(data) => versions::check_versions(&data),
        Err(e) => vec![
            ratecal_grammar::Diagnostic::error(
                "io::read",
                format!("cannot read `{}`: {e}", folder.display()),
            )
            .help("give a procedure folder"),
        ],
    }
}

/// Runs the subcommand.
pub fn main(args: Args) -> ExitCode {
    let folder = &args.folder;
    let files = match version_files(folder) {
        Ok(f) if !f.is_empty() => f,
        Ok(_) | Err(_) => {
            let e = miette::miette!(
                code = "log::not_a_procedure_folder",
                help =
                    "give a folder holding <version>.rcal files, e.g. procedures/imu-2d-standard",
                "{} holds no procedure versions",
                folder.display()
            );
            errln!("{e:?}");
            return ExitCode::from(2);
        }
    };
    let lock_text = std::fs::read_to_string(folder.join(LOCK_FILE)).ok();
    let lock = lock_text
        .as_deref()
        .map(|t| versions::parse_lock(LOCK_FILE, t).0)
        .unwrap_or_default();
    let mut previous: Option<super::diff::Loaded> = None;
    let mut failed = false;
    outln!("{}", folder.display());
    for (version, path) in files {
        let display = path.display().to_string();
        let loaded = std::fs::read(&path)
            .ok()
            .and_then(|b| super::diff::load_text(&display, &String::from_utf8_lossy(&b)));
        let Some(loaded) = loaded else {
            outln!(
                "{:<8} {:<64}  (does not check: see the errors above)",
                version.to_string(),
                "-"
            );
            failed = true;
            continue;
        };
        let status = match lock
            .iter()
            .find(|e| Version::parse(&e.version).as_ref() == Some(&version))
        {
            Some(e) if e.sha256 == loaded.sha256 => "released",
            Some(_) => "CHANGED AFTER RELEASE",
            None => "unreleased",
        };
        let summary = match &previous {
            None => "first version".to_string(),
            Some(p) => render::summary(&diff(&p.plan, &loaded.plan)),
        };
        outln!(
            "{:<8} {}  {status:<10}  {summary}",
            version.to_string(),
            loaded.sha256
        );
        previous = Some(loaded);
    }
    if failed {
        ExitCode::from(2)
    } else {
        ExitCode::SUCCESS
    }
}
