//! `ratecal run`: runs a procedure on a station (simulated with `--dry-run` or without a
//! station), records the run folder, analyses it, writes the reports and seals the folder.
//! Exit codes (spec/cli.md): 0 the verdict is pass or not_judged (no acceptance check), 3 it
//! is not (a failed check, a check that could not be evaluated, a failed sanity check), 4
//! aborted, 1 input error (or a run that failed: its folder
//! ends with `status: failed`), 2 usage.

use ratecal_folder::names::{MANIFEST, PROCEDURE, STATION};
mod check;
mod finish;
mod imports;
pub mod log;
mod resume;
pub(crate) mod setup;

use ed25519_dalek::SigningKey;
use miette::Report;
use ratecal_folder::lock::FolderLock;
use ratecal_recording::{Columns, RecordingWriter};
use ratecal_run::{Progress, RunOptions, execute};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// What `ratecal run` is asked.
pub struct Request {
    /// Procedure file or folder (absent with `resume`).
    pub procedure: Option<PathBuf>,
    /// Station file; the embedded station without it.
    pub station: Option<PathBuf>,
    /// Run folder to create.
    pub out: Option<PathBuf>,
    /// Simulate the station.
    pub dry_run: bool,
    /// Seed of the simulated station.
    pub seed: u64,
    /// A run folder to continue.
    pub resume: Option<PathBuf>,
    /// Operator name.
    pub operator: Option<String>,
    /// The IMU's serial number for this run.
    pub serial: Option<String>,
    /// The lab's private key, to sign the seal.
    pub sign: Option<PathBuf>,
    /// Run a released version changed after release.
    pub allow_changed: bool,
    /// Run an unreleased version (a draft).
    pub draft: bool,
    /// Archive the run there.
    pub archive: Option<String>,
}

/// What shows the run's progress on the terminal: made once the plan's estimated duration
/// (s) and whether the station is simulated are known.
pub type Display = Box<dyn FnOnce(f64, bool) -> Box<dyn Shown>>;

/// A progress display that is taken down when the run ends.
pub trait Shown: Progress {
    /// Takes the display down.
    fn finish(&mut self);
}

/// `1:02:03` from seconds.
pub fn hms(s: f64) -> String {
    let s = s.max(0.0).round() as u64;
    format!("{}:{:02}:{:02}", s / 3600, s / 60 % 60, s % 60)
}

/// Reads a station file (for `ratecal emulate`: every driver simulated, faults kept).
pub fn station_file(path: &Path) -> Result<setup::LoadedStation, Report> {
    setup::station(Some(path), true)
}

/// Runs (or resumes) the procedure; the exit code of spec/cli.md.
pub fn run(args: Request, display: Display) -> u8 {
    survive_file_size_limit();
    match run_or_resume(args, display) {
        Ok(code) => code,
        Err(report) => {
            errln!("{report:?}");
            1
        }
    }
}

/// A file-size limit (`ulimit -f`) stops a write with SIGXFSZ, whose default action kills
/// the process: with a handler installed the write fails with EFBIG instead, and the run
/// aborts to its safe state like on a full disk. Installed through tokio's safe signal
/// API (the handler outlives the small runtime that installs it).
fn survive_file_size_limit() {
    #[cfg(any(target_os = "linux", target_os = "macos"))]
    {
        const SIGXFSZ: i32 = 25;
        let Ok(rt) = tokio::runtime::Builder::new_current_thread()
            .enable_io()
            .build()
        else {
            return;
        };
        rt.block_on(async {
            use tokio::signal::unix::{SignalKind, signal};
            let _ = signal(SignalKind::from_raw(SIGXFSZ));
        });
    }
}

/// Everything the interpreter needs, prepared.
pub(crate) struct Prepared {
    dir: PathBuf,
    plan: ratecal_plan::Plan,
    station: ratecal_drivers::Station,
    writer: RecordingWriter,
    opts: RunOptions,
    seed: u64,
    /// The writer appends to staged copies (a sealed run resumed), committed at the end.
    staged: bool,
}

fn run_or_resume(args: Request, display: Display) -> Result<u8, Report> {
    // The key is read first: a run is not started only to find it cannot be signed.
    let key = args
        .sign
        .as_deref()
        .map(ratecal_folder::keys::signing_key)
        .transpose()?;
    // The folder's lock is held to the end, the failure record and the seal included.
    let (prep, _lock) = match &args.resume {
        Some(dir) => match resume::prepare(dir)? {
            (resume::Resume::Run(prep), lock) => (*prep, lock),
            (resume::Resume::Seal { plan, status }, _lock) => {
                let code = finish::seal_recorded(
                    dir,
                    &plan,
                    &status,
                    key.as_ref(),
                    args.archive.as_deref(),
                );
                crate::archive::after_run(args.archive.as_deref(), dir);
                return Ok(code);
            }
            (resume::Resume::Finished, _lock) => return Ok(0),
        },
        None => prepare_new(&args)?,
    };
    let dir = prep.dir.clone();
    let staged = prep.staged;
    match execute_prepared(prep, key.as_ref(), args.archive.as_deref(), display) {
        Ok(code) => {
            // Archived once sealed; a failure to archive is a warning, never the run's fate.
            crate::archive::after_run(args.archive.as_deref(), &dir);
            Ok(code)
        }
        Err(report) if staged && ratecal_recording::commit::pending_intent(&dir).is_none() => {
            // The rest of a sealed run failed before it was committed: the sealed run
            // stands as it was.
            resume::drop_staged(&dir);
            errln!(
                "{}: the resumed part was not kept; the folder is as it was sealed",
                dir.display()
            );
            Err(report)
        }
        Err(report) => {
            // The folder exists: it must not be left saying `running`.
            if let Err(e) = finish::mark_failed(&dir, &report.to_string(), key.as_ref()) {
                errln!("cannot record the failure in {}: {e}", dir.display());
            }
            Err(report)
        }
    }
}

fn execute_prepared(
    prep: Prepared,
    key: Option<&SigningKey>,
    archive: Option<&str>,
    display: Display,
) -> Result<u8, Report> {
    let Prepared {
        dir,
        plan,
        station,
        mut writer,
        mut opts,
        seed,
        staged,
    } = prep;
    let simulated = station.describe().simulated;
    if let Some(t) = link_timeout_s(&station) {
        // A link that comes back within its timeout must not trip the stall check first.
        opts.stall_timeout_s = opts.stall_timeout_s.max(t + 0.5);
    }
    let cancel = Arc::new(AtomicBool::new(false));
    opts.cancel = Some(cancel.clone());
    let mut bar = display(plan.estimated_duration_s, simulated);

    // Ctrl-C (and SIGTERM) take the abort path: the table is brought to a safe stop and
    // every sample so far is kept. The handler is a thread of its own, so that a simulated
    // run needs no IO driver.
    let flag = cancel.clone();
    if let Err(e) = ctrlc::set_handler(move || flag.store(true, Ordering::Relaxed)) {
        errln!("warning: Ctrl-C will not stop the run cleanly: {e}");
    }
    // A simulated station runs on the paused (virtual) clock with only the timer (each
    // control tick would otherwise poll the IO driver); hardware in real time with IO.
    let mut builder = tokio::runtime::Builder::new_current_thread();
    if simulated {
        builder.enable_time().start_paused(true);
    } else {
        builder.enable_all();
    }
    let rt = builder
        .build()
        .map_err(|e| miette::miette!("cannot start the runtime: {e}"))?;
    let wall = std::time::Instant::now();
    let outcome = rt.block_on(async {
        // Built inside the runtime: the simulator's clock starts on the (paused) run clock.
        let (mut table, mut imu) = ratecal_drivers::build(&station, seed)
            .map_err(|e| miette::miette!("cannot start the station: {e}"))?;
        Ok::<_, Report>(
            execute(
                &plan,
                table.as_mut(),
                imu.as_mut(),
                &mut writer,
                bar.as_mut(),
                &opts,
            )
            .await,
        )
    });
    // The streams' hashes as written: the seal takes them instead of reading the files again
    // (a staged resume's files are committed first, so those are read).
    let written = if staged {
        Vec::new()
    } else {
        writer.written().to_vec()
    };
    // The segments the manifest kept: a segment whose checkpoint failed after the
    // interpreter handed it over is not the recording's.
    let kept = (writer.manifest().segments.len()).saturating_sub(opts.resume_segments);
    // The recording is closed before anything reads it back (or records a failure).
    drop(writer);
    let outcome = outcome?;
    bar.finish();
    let wall = wall.elapsed().as_secs_f64();
    let mut outcome = outcome
        .map_err(|e| miette::miette!("cannot close the recording in {}: {e}", dir.display()))?;
    outcome.segments = outcome.segments.min(kept);
    if staged {
        // The rest is recorded and closed: it replaces the sealed files in one change.
        resume::commit_staged(&dir).map_err(|e| {
            miette::miette!(
                help = format!(
                    "`ratecal run --resume {}` finishes the change",
                    ratecal_folder::shell::quoted(&dir)
                ),
                "cannot commit the resumed run in {}: {e}",
                dir.display()
            )
        })?;
    }
    let end = finish::End {
        dir: &dir,
        plan: &plan,
        outcome: &outcome,
        wall_s: wall,
        simulated,
        key,
        archive,
        written: &written,
    };
    Ok(end.finish())
}

/// The longest timeout of a station's hardware links, s.
fn link_timeout_s(station: &ratecal_drivers::Station) -> Option<f64> {
    let table = station.table.driver.link_timeout_s();
    let imu = station.imu.driver.link_timeout_s();
    table.into_iter().chain(imu).reduce(f64::max)
}

fn prepare_new(args: &Request) -> Result<(Prepared, FolderLock), Report> {
    let proc_path = setup::procedure_file(
        args.procedure.as_deref().unwrap_or(Path::new(".")),
        args.draft,
    )?;
    let draft = setup::draft(&proc_path, args.draft)?;
    // Without --station the procedure's geometry picks the embedded station.
    let builtin = std::fs::read_to_string(&proc_path)
        .ok()
        .map(|text| setup::builtin_for(&text));
    let mut st = setup::station_for(args.station.as_deref(), args.dry_run, builtin)?;
    if let Some(sn) = &args.serial {
        st.station.imu.serial = sn.clone();
    }
    let changed = setup::released_unchanged(&proc_path, args.allow_changed)?;
    let pr = setup::procedure(&proc_path, &st.station, None)?;
    let dir = args
        .out
        .clone()
        .unwrap_or_else(|| setup::default_out(&pr.plan.name));
    if dir.join(MANIFEST).exists() {
        return Err(miette::miette!(
            help = "choose another --out, or continue it with --resume",
            "{} already holds a run",
            dir.display()
        ));
    }
    let io =
        |e: std::io::Error| miette::miette!("cannot write the run folder {}: {e}", dir.display());
    std::fs::create_dir_all(&dir).map_err(io)?;
    let lock = ratecal_folder::lock::acquire(&dir, &ratecal_folder::sealing::command_line())?;
    // Asked again under the lock: another `run --out` may have started it meanwhile.
    if dir.join(MANIFEST).exists() {
        return Err(miette::miette!(
            help = "choose another --out, or continue it with --resume",
            "{} already holds a run",
            dir.display()
        ));
    }
    ratecal_recording::commit::write_nofollow(&dir.join(PROCEDURE), pr.text.as_bytes())
        .map_err(io)?;
    pr.imports.save(&dir).map_err(io)?;
    ratecal_recording::commit::write_nofollow(&dir.join(STATION), st.yaml.as_bytes())
        .map_err(io)?;
    let facts = setup::RunFacts {
        dir: &dir,
        dry_run: args.dry_run || args.station.is_none(),
        seed: args.seed,
        operator: args.operator.clone(),
        changed_after_release: changed,
        draft,
    };
    let manifest = setup::manifest(&st, &pr, &facts);
    // Hardware links stamp each sample with its host arrival time as well (`t_host`).
    let columns = Columns {
        imu_temp: true,
        ambient: st.station.temperature.report_ambient,
        imu_t_host: st.station.imu.driver.kind.host_arrival,
        table_t_host: st.station.table.driver.kind.host_arrival,
    };
    let writer = RecordingWriter::create(&dir, manifest, columns).map_err(io)?;
    let prep = Prepared {
        dir,
        plan: pr.plan,
        station: st.station,
        writer,
        opts: RunOptions::default(),
        seed: args.seed,
        staged: false,
    };
    Ok((prep, lock))
}
