//! The archive as other commands use it: a run added when it ends, and a unit's history
//! for a report's conclusions.

use miette::Report;
use ratecal_archive::trend::TrendOptions;
use ratecal_archive::{Archive, Location};
use std::path::Path;

/// Verifies one run folder, then adds it: the line that says what happened.
pub async fn add_one(archive: &Archive, dir: &Path) -> Result<String, Report> {
    let report = ratecal_folder::verify::verify_folder(dir, None)?;
    if !report.intact() {
        return Err(miette::miette!(
            code = "archive::altered",
            help = "the archive keeps runs as they were recorded; archive the original folder",
            "{} was altered since the run; not archived:\n{}",
            dir.display(),
            report.text().trim_end()
        ));
    }
    let added = archive.add(dir).await?;
    Ok(if added.same_recording {
        format!(
            "{} is not approved and its recording is already archived as {} (one calibration, \
             one entry): not added again",
            dir.display(),
            added.id
        )
    } else if added.new {
        format!(
            "archived {} as {} ({} file(s)){}",
            dir.display(),
            added.id,
            added.files,
            if added.replaced.is_empty() {
                String::new()
            } else {
                format!(
                    ", replacing the unapproved entry {} of the same recording",
                    added.replaced.join(", ")
                )
            }
        )
    } else {
        format!("{} is already archived as {}", dir.display(), added.id)
    })
}

/// The unit's trend across the calibrations the configured archive holds (`--archive` or
/// `RATECAL_ARCHIVE`), as `archive trend --format json` gives it, for a report's
/// conclusions; `None` without an archive, without a serial, or when it cannot be read (a
/// report never fails for want of its history: a warning says why).
pub fn trend_json(archive: Option<&str>, serial: Option<&str>) -> Option<serde_json::Value> {
    let serial = serial.filter(|s| !s.is_empty())?;
    if !Location::configured(archive) {
        return None;
    }
    let loc = Location::resolve(archive, None);
    let rt = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .ok()?;
    let opt = TrendOptions {
        params: Vec::new(),
        include_dry_runs: false,
        confidence: 0.95,
    };
    let res = rt.block_on(async {
        let a = Archive::open_existing(&loc).await?;
        let t = a.trend(serial, &opt).await;
        a.close().await;
        t
    });
    match res {
        Ok(t) => serde_json::to_value(&t).ok(),
        Err(e) => {
            errln!("warning: the report leaves out the archive's history of {serial}:\n{e:?}");
            None
        }
    }
}

/// `ratecal run`'s hook: adds the finished run when an archive is named (`--archive` or
/// `RATECAL_ARCHIVE`); a failure is a warning, never the run's exit code.
pub fn after_run(archive: Option<&str>, dir: &Path) {
    if !Location::configured(archive) {
        return;
    }
    let loc = Location::resolve(archive, None);
    let Ok(rt) = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
    else {
        errln!("warning: the run was not archived (cannot start the runtime)");
        return;
    };
    let res = rt.block_on(async {
        let a = Archive::open(&loc).await?;
        let line = add_one(&a, dir).await;
        a.close().await;
        line
    });
    match res {
        Ok(line) => outln!("{line} in {}", loc.display()),
        Err(e) => errln!("warning: the run was not archived:\n{e:?}"),
    }
}
