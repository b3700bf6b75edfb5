//! `ratecal run --resume RUN_DIR`: continues an interrupted run from its last completed step,
//! with the copies the run folder keeps. Refused when a copy (procedure, station file, an
//! import) no longer has the hash the run recorded, or when the folder no longer matches its
//! seal: the rest of a run must follow what its start followed.

use super::{Prepared, imports, setup};
use crate::cli::lock::FolderLock;
use miette::{Report, miette};
use ratecal_engine::audit::seal::{SEAL_FILE, SEAL_HASH_FILE, verify_hashes};
use ratecal_engine::recording::{
    Manifest, RecordingWriter, ResumeRecord, parse_manifest, rfc3339, sha256_hex,
};
use ratecal_engine::run::{RunOptions, resume_point};
use std::path::Path;

/// Prepares the rest of an interrupted run, holding the folder's lock.
pub fn prepare(dir: &Path) -> Result<(Prepared, FolderLock), Report> {
    let io = |e: std::io::Error| {
        miette!(
            help = "--resume takes a run folder written by `ratecal run`",
            "cannot resume {}: {e}",
            dir.display()
        )
    };
    if !dir.is_dir() {
        return Err(io(std::io::ErrorKind::NotFound.into()));
    }
    // Taken before the folder's state is read: a second resume is refused, not interleaved.
    let lock = crate::cli::lock::acquire(dir, &crate::cli::seal::command_line())?;
    let journal = std::fs::read_to_string(dir.join("journal.jsonl")).map_err(io)?;
    let point = resume_point(&journal);
    if point.completed {
        return Err(miette!(
            "{} is a completed run: nothing to resume",
            dir.display()
        ));
    }
    unaltered(dir)?;
    // Checked before anything in the folder is opened for writing.
    let text = std::fs::read_to_string(dir.join("manifest.yaml")).map_err(io)?;
    let manifest = parse_manifest("manifest.yaml", &text).map_err(Report::new)?;
    same_inputs(dir, &manifest)?;
    let (mut writer, last_t) = RecordingWriter::append(dir).map_err(io)?;
    let dry_run = writer.manifest().run.as_ref().is_some_and(|r| r.dry_run);
    let seed = writer
        .manifest()
        .run
        .as_ref()
        .and_then(|r| r.seed)
        .unwrap_or(1);
    let st = setup::station(Some(&dir.join("station.yaml")), dry_run)?;
    let pr = setup::procedure(&dir.join("procedure.rcal"), &st.station, Some(dir))?;
    let m = writer.manifest_mut();
    m.segments.truncate(point.segments);
    if let Some(run) = m.run.as_mut() {
        let reason = match (&run.abort, &run.failure) {
            (Some(a), _) => Some(format!("{} ({})", a.rule, a.values)),
            (None, Some(f)) => Some(f.clone()),
            (None, None) => None,
        };
        let resumed = ResumeRecord {
            interrupted_status: run.status.clone(),
            reason,
            t: run.abort.as_ref().map(|a| a.t).or(last_t),
            step: run.abort.as_ref().and_then(|a| a.step.clone()),
            ended: run.ended.clone(),
            resumed: rfc3339(std::time::SystemTime::now()),
            from_step: point.next_step,
        };
        outln!(
            "resuming {} from step {} (interrupted: {}{})",
            dir.display(),
            point.next_step + 1,
            resumed.interrupted_status,
            resumed
                .reason
                .as_ref()
                .map(|r| format!(", {r}"))
                .unwrap_or_default()
        );
        run.resumes.push(resumed);
        run.status = "running".into();
        run.abort = None;
        run.failure = None;
        run.ended = None;
        // The data files are hashed again when the run ends; the import copies stand.
        run.files_sha256
            .retain(|name, _| name.starts_with(&format!("{}/", imports::IMPORTS_DIR)));
    }
    writer.checkpoint().map_err(io)?;
    let opts = RunOptions {
        start_step: point.next_step,
        resume_segments: point.segments,
        // Time keeps increasing across the interruption (1 s gap).
        t_offset: last_t.map_or(0.0, |t| t + 1.0),
        ..RunOptions::default()
    };
    let prep = Prepared {
        dir: dir.to_path_buf(),
        plan: pr.plan,
        station: st.station,
        writer,
        opts,
        seed,
    };
    Ok((prep, lock))
}

/// A sealed folder (an aborted run is sealed) must still match its seal.
fn unaltered(dir: &Path) -> Result<(), Report> {
    let Ok(seal) = std::fs::read_to_string(dir.join(SEAL_FILE)) else {
        return Ok(());
    };
    let hash = std::fs::read_to_string(dir.join(SEAL_HASH_FILE)).ok();
    let files = crate::cli::seal::folder_files(dir)
        .map_err(|e| miette!("cannot read {}: {e}", dir.display()))?;
    let report = verify_hashes(Some(&seal), hash.as_deref(), &files, None);
    if report.intact() {
        return Ok(());
    }
    let names: Vec<&str> = report.altered().map(|c| c.file.as_str()).collect();
    Err(miette!(
        code = "run::resume_altered",
        help = format!(
            "`ratecal verify {}` shows what changed; start a new run",
            dir.display()
        ),
        "{} was altered since it was sealed ({}): not resumed",
        dir.display(),
        names.join(", ")
    ))
}

/// The procedure, station file and imports must hash as the run recorded them.
fn same_inputs(dir: &Path, m: &Manifest) -> Result<(), Report> {
    let mut changed = Vec::new();
    let mut compare = |file: &str, recorded: &str, now: Option<String>| {
        let now = now.unwrap_or_else(|| "missing".into());
        if !now.eq_ignore_ascii_case(recorded) {
            changed.push(format!("{file}: recorded sha256 {recorded}, now {now}"));
        }
    };
    let read = |name: &str| std::fs::read(dir.join(name)).ok();
    if let Some(p) = &m.procedure {
        let canon = read("procedure.rcal")
            .and_then(|b| String::from_utf8(b).ok())
            .and_then(|t| ratecal_grammar::canonical(&t).ok())
            .map(|c| c.sha256);
        compare("procedure.rcal", &p.sha256, canon);
    }
    if let Some(run) = &m.run {
        if let Some(s) = &run.station_sha256 {
            compare(
                "station.yaml",
                s,
                read("station.yaml").map(|b| sha256_hex(&b)),
            );
        }
        let prefix = format!("{}/", imports::IMPORTS_DIR);
        for (name, sha) in run
            .files_sha256
            .iter()
            .filter(|(n, _)| n.starts_with(&prefix))
        {
            compare(name, sha, read(name).map(|b| sha256_hex(&b)));
        }
    }
    if changed.is_empty() {
        return Ok(());
    }
    Err(miette!(
        code = "run::resume_changed",
        help = "a run continues with what it started with: restore the file, or start a new run",
        "{} changed since the run started: not resumed\n  {}",
        dir.display(),
        changed.join("\n  ")
    ))
}
