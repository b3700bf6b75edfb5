//! A procedure folder on disk (one `<version>.rcal` per version and `versions.lock`): its
//! version files in version order, and what the version rules of `plan::versions` read.

use ratecal_grammar::ast::TopItem;
use ratecal_plan::versions::{self, FolderData, LOCK_FILE, Version, VersionFile};
use std::path::{Path, PathBuf};

/// Version files of a folder, sorted by version.
pub fn version_files(folder: &Path) -> std::io::Result<Vec<(Version, PathBuf)>> {
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
pub fn folder_data(folder: &Path) -> std::io::Result<FolderData> {
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

/// The version rules of a procedure folder (`ratecal check FOLDER` calls this), and the
/// signatures of its release lines.
pub fn check_folder(folder: &Path) -> Vec<ratecal_grammar::Diagnostic> {
    match folder_data(folder) {
        Ok(data) => {
            let mut out = versions::check_versions(&data);
            if let Some(lock) = &data.lock {
                let path = format!("{}/{LOCK_FILE}", data.path.trim_end_matches('/'));
                out.extend(crate::release::bad_signatures(&path, lock));
            }
            out
        }
        Err(e) => vec![
            ratecal_grammar::Diagnostic::error(
                "io::read",
                format!("cannot read `{}`: {e}", folder.display()),
            )
            .help("give a procedure folder"),
        ],
    }
}
