//! `ratecal run --resume RUN_DIR`: finishes whatever state an interruption left
//! (docs/run-folders.md). A run stopped while recording continues in place from its last
//! completed step; a run that ended but was never sealed is analysed, reported and sealed
//! when its streams still match the journal's running hash; a sealed aborted run continues
//! on staged copies of its files, committed over the sealed ones only when the rest has been
//! recorded, so that a crash meanwhile leaves the sealed recording as it was. Refused when a
//! copy (procedure, station file, an import) no longer has the hash the run recorded, or
//! when the folder no longer matches its seal: the rest of a run must follow what its start
//! followed.

use super::{Prepared, imports, setup};
use miette::{Report, miette};
use ratecal_folder::lock::FolderLock;
use ratecal_folder::names::{IMU, JOURNAL, MANIFEST, PROCEDURE, STATION, TABLE};
use ratecal_folder::names::{SEAL_FILE, SEAL_HASH_FILE};
use ratecal_folder::state::{State, state_of};
use ratecal_recording::commit::{
    Intent, PENDING_DIR, Recovered, commit, crash_point, pending_dir, recover, sync_dir,
};
use ratecal_recording::{
    Manifest, RecordingWriter, ResumeRecord, parse_manifest, rfc3339, sha256_hex,
};
use ratecal_run::{JournalEntry, JournalEvent, RunOptions, resume_point};
use std::path::{Path, PathBuf};

/// The files a resumed sealed run continues on staged copies of.
const STAGED: [&str; 4] = [IMU, TABLE, JOURNAL, MANIFEST];

/// What `--resume` does with a folder.
pub enum Resume {
    /// Record the rest of the run.
    Run(Box<Prepared>),
    /// A run that ended but was never sealed: analyse, report and seal it.
    Seal {
        /// The plan it ran.
        plan: Box<ratecal_plan::Plan>,
        /// Its status (`completed`, `aborted`, `failed`).
        status: String,
    },
    /// An interrupted change was carried out and left the run sealed: nothing more to do.
    Finished,
}

/// Finishes an interrupted change, then says what to do with the folder, holding its lock.
pub fn prepare(dir: &Path) -> Result<(Resume, FolderLock), Report> {
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
    let lock = ratecal_folder::lock::acquire(dir, &ratecal_folder::sealing::command_line())?;
    let recovered = recover(dir).map_err(io)?;
    let finished = matches!(recovered, Recovered::RolledForward(_));
    match recovered {
        Recovered::Clean => {}
        Recovered::RolledBack => outln!(
            "{}: an interrupted resume left staged files; dropped (the sealed run is as it was)",
            dir.display()
        ),
        Recovered::RolledForward(i) => outln!(
            "{}: finished an interrupted change ({})",
            dir.display(),
            i.moves.join(", ")
        ),
    }
    let state = state_of(dir);
    let resume = match state {
        State::Sealed if finished => {
            outln!(
                "{}: the interrupted change is finished and the run is sealed: nothing to resume",
                dir.display()
            );
            Resume::Finished
        }
        State::Sealed => {
            return Err(miette!(
                help = format!(
                    "`ratecal verify {}` checks it",
                    ratecal_folder::shell::quoted(dir)
                ),
                "{} is a completed run, sealed: nothing to resume",
                dir.display()
            ));
        }
        State::Other | State::Committing => {
            return Err(io(std::io::Error::other(format!(
                "{} is not a run ratecal recorded ({})",
                dir.display(),
                state.name()
            ))));
        }
        State::RecordedUnsealed(status) => {
            unaltered_streams(dir)?;
            let text = std::fs::read_to_string(dir.join(MANIFEST)).map_err(io)?;
            let manifest = parse_manifest(MANIFEST, &text).map_err(Report::new)?;
            same_inputs(dir, &manifest)?;
            let dry_run = manifest.run.as_ref().is_some_and(|r| r.dry_run);
            let st = setup::station(Some(&dir.join(STATION)), dry_run)?;
            let pr = setup::procedure(&dir.join(PROCEDURE), &st.station, Some(dir))?;
            outln!(
                "{}: a run that ended ({status}) but was never sealed; its streams match the \
                 journal's running hash: analysing, reporting and sealing it",
                dir.display()
            );
            Resume::Seal {
                plan: Box::new(pr.plan),
                status,
            }
        }
        State::Recording => Resume::Run(Box::new(continue_run(dir, None)?)),
        State::AbortedSealed(_) => {
            unaltered(dir)?;
            let stage = stage(dir).map_err(io)?;
            Resume::Run(Box::new(continue_run(dir, Some(stage))?))
        }
    };
    Ok((resume, lock))
}

/// Copies the files a resume appends to into the pending folder (the sealed ones stay as
/// they are until the commit).
fn stage(dir: &Path) -> std::io::Result<PathBuf> {
    let pending = pending_dir(dir)?;
    for name in STAGED {
        let to = pending.join(name);
        // Streamed, never through a link planted in the pending folder.
        let mut from = std::fs::File::open(dir.join(name))?;
        let mut into = ratecal_recording::commit::open_nofollow(&to, true, false)?;
        std::io::copy(&mut from, &mut into)?;
        into.sync_all()?;
    }
    sync_dir(&pending)?;
    crash_point("after-stage");
    Ok(pending)
}

/// Replaces the sealed files by the staged ones (the resumed run recorded and closed): one
/// committed change that also removes the old seal, which no longer covers them.
pub fn commit_staged(dir: &Path) -> std::io::Result<()> {
    let intent = Intent {
        moves: STAGED.iter().map(|s| s.to_string()).collect(),
        removes: vec![SEAL_FILE.into(), SEAL_HASH_FILE.into()],
    };
    // The intent is also on record in the journal that replaces the sealed one.
    let entry = JournalEntry {
        t: 0.0,
        step: None,
        event: JournalEvent::Commit {
            moves: intent.moves.clone(),
            removes: intent.removes.clone(),
        },
    };
    let line = serde_json::to_string(&entry).map_err(std::io::Error::other)?;
    let journal = dir.join(PENDING_DIR).join(JOURNAL);
    let mut f = ratecal_recording::commit::open_with_nofollow(
        std::fs::OpenOptions::new().append(true),
        &journal,
    )?;
    std::io::Write::write_all(&mut f, format!("{line}\n").as_bytes())?;
    f.sync_all()?;
    commit(dir, &intent)
}

/// Drops a staged resume (it failed): the sealed run stays as it was.
pub fn drop_staged(dir: &Path) {
    let _ = std::fs::remove_dir_all(dir.join(PENDING_DIR));
}

/// Opens the rest of a run from its last completed step: in place (`stage` `None`: a run
/// stopped while recording, never sealed) or on the staged copies.
fn continue_run(dir: &Path, stage: Option<PathBuf>) -> Result<Prepared, Report> {
    let io = |e: std::io::Error| {
        miette!(
            help = "--resume takes a run folder written by `ratecal run`",
            "cannot resume {}: {e}",
            dir.display()
        )
    };
    let write_dir = stage.clone().unwrap_or_else(|| dir.to_path_buf());
    let journal = std::fs::read_to_string(write_dir.join(JOURNAL)).map_err(io)?;
    let point = resume_point(&journal);
    // Checked before anything in the folder is opened for writing.
    let text = std::fs::read_to_string(write_dir.join(MANIFEST)).map_err(io)?;
    let manifest = parse_manifest(MANIFEST, &text).map_err(Report::new)?;
    same_inputs(dir, &manifest)?;
    let (mut writer, last_t) = RecordingWriter::append(&write_dir, stage.is_some())
        .map_err(|e| altered_stream(dir, &e.to_string()))?;
    let dry_run = writer.manifest().run.as_ref().is_some_and(|r| r.dry_run);
    let seed = writer
        .manifest()
        .run
        .as_ref()
        .and_then(|r| r.seed)
        .unwrap_or(1);
    let st = setup::station(Some(&dir.join(STATION)), dry_run)?;
    let pr = setup::procedure(&dir.join(PROCEDURE), &st.station, Some(dir))?;
    let cut_tail = writer.cut_tails().clone();
    let m = writer.manifest_mut();
    m.segments.truncate(point.segments);
    let last_pose = m
        .segments
        .iter()
        .rev()
        .find(|s| s.kind == ratecal_recording::SegmentKind::Static)
        .cloned();
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
            cut_tail,
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
        run.write_failure = None;
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
        last_pose,
        ..RunOptions::default()
    };
    Ok(Prepared {
        dir: dir.to_path_buf(),
        plan: pr.plan,
        station: st.station,
        writer,
        opts,
        seed,
        staged: stage.is_some(),
    })
}

/// A stream that no longer matches the journal's running hash: altered, not continued or
/// sealed.
fn altered_stream(dir: &Path, why: &str) -> Report {
    miette!(
        code = "run::resume_altered",
        help = "the streams are not as they were recorded; nothing was sealed: start a new run",
        "{} was altered since it was recorded ({why}): not resumed",
        dir.display()
    )
}

/// A run that ended without a seal is sealed only when its streams are as recorded.
fn unaltered_streams(dir: &Path) -> Result<(), Report> {
    match ratecal_recording::chain::check_folder(dir) {
        Ok(Ok(())) => Ok(()),
        Ok(Err(why)) => Err(altered_stream(dir, &why)),
        Err(e) => Err(altered_stream(dir, &e.to_string())),
    }
}

/// A sealed folder (an aborted run is sealed) must still match its seal.
fn unaltered(dir: &Path) -> Result<(), Report> {
    if std::fs::read_to_string(dir.join(SEAL_FILE)).is_err() {
        return Ok(());
    }
    let report = ratecal_folder::verify::verify_folder(dir, None)?;
    if report.intact() {
        return Ok(());
    }
    Err(miette!(
        code = "run::resume_altered",
        help = format!(
            "`ratecal verify {}` shows what changed; start a new run",
            ratecal_folder::shell::quoted(dir)
        ),
        "{} was altered since it was sealed ({}): not resumed",
        dir.display(),
        report.altered_names()
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
        let canon = read(PROCEDURE)
            .and_then(|b| String::from_utf8(b).ok())
            .and_then(|t| ratecal_grammar::canonical(&t).ok())
            .map(|c| c.sha256);
        compare(PROCEDURE, &p.sha256, canon);
    }
    if let Some(run) = &m.run {
        if let Some(s) = &run.station_sha256 {
            compare(STATION, s, read(STATION).map(|b| sha256_hex(&b)));
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
