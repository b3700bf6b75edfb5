//! `ratecal log FOLDER`: every version of a procedure folder, oldest first, with the
//! SHA-256 of its canonical text, whether `versions.lock` records it as released (signed by
//! whom, its signature verified, or unsigned for an older hash-only line), and a one-line
//! summary of its semantic changes from the version before. Exit 0, or 2 when the folder
//! or one of its versions cannot be read or checked, or a release's signature fails.

use ratecal_audit::versions::{self, LOCK_FILE, Version};
use ratecal_audit::{diff, render};
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `ratecal log`.
#[derive(clap::Args)]
pub struct Args {
    /// Procedure folder (one `<version>.rcal` per version and `versions.lock`).
    folder: PathBuf,
}

/// Runs the subcommand.
pub fn main(args: Args) -> ExitCode {
    let folder = &args.folder;
    let files = match ratecal_ops::versions::version_files(folder) {
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
    let mut previous: Option<ratecal_ops::procedure::Loaded> = None;
    let mut failed = false;
    outln!("{}", folder.display());
    for (version, path) in files {
        let display = path.display().to_string();
        let loaded = std::fs::read(&path).ok().and_then(|b| {
            ratecal_ops::procedure::load_text(&display, &String::from_utf8_lossy(&b))
        });
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
            Some(e) if e.sha256 == loaded.sha256 => {
                let how = ratecal_ops::release::describe(e);
                failed |= how.starts_with("BAD SIGNATURE");
                format!("released ({how})")
            }
            Some(_) => "CHANGED AFTER RELEASE".to_string(),
            None => "unreleased (draft)".to_string(),
        };
        let summary = match &previous {
            None => "first version".to_string(),
            Some(p) => render::summary(&diff(&p.plan, &loaded.plan)),
        };
        outln!(
            "{:<8} {}  {status:<22}  {summary}",
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
