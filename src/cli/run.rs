//! `ratecal run`: runs a procedure on a station (simulated with `--dry-run` or without a
//! station), records the run folder, then analyses it. Exit codes (spec/cli.md): 0 completed
//! and no acceptance check failed, 3 an acceptance check failed, 4 aborted, 1 input error,
//! 2 usage.

mod check;
mod imports;
mod progress;
mod setup;

use miette::Report;
use ratecal_engine::recording::sha256_hex;
use ratecal_engine::recording::{Columns, RecordingWriter};
use ratecal_engine::run::{
    JournalEntry, JournalEvent, RunOptions, RunOutcome, RunSink, RunStatus, execute, resume_point,
};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// Arguments of `ratecal run`.
#[derive(clap::Args)]
pub struct Args {
    /// Procedure file, or procedure folder (its latest version).
    #[arg(required_unless_present = "resume")]
    procedure: Option<PathBuf>,
    /// Station file (YAML); the embedded default simulated station without it.
    #[arg(long)]
    station: Option<PathBuf>,
    /// Run folder to create (default: runs/<procedure>-<UTC timestamp>).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Simulate the station (table and IMU) whatever drivers the station file names.
    #[arg(long)]
    dry_run: bool,
    /// Seed of the simulated station.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Continue an interrupted run from its last completed step (procedure and station
    /// come from the run folder).
    #[arg(long, value_name = "RUN_DIR", conflicts_with_all = ["procedure", "station", "out"])]
    resume: Option<PathBuf>,
    /// Operator name, recorded in the manifest.
    #[arg(long)]
    operator: Option<String>,
}

/// Reads a station file (for `ratecal emulate`: every driver simulated, faults kept).
pub fn station_file(path: &Path) -> Result<setup::LoadedStation, Report> {
    setup::station(Some(path), true)
}

/// Runs the subcommand.
pub fn main(args: Args) -> ExitCode {
    match run(args) {
        Ok(code) => code,
        Err(report) => {
            eprintln!("{report:?}");
            ExitCode::from(1)
        }
    }
}

/// Everything the interpreter needs, prepared.
struct Prepared {
    dir: PathBuf,
    plan: ratecal_engine::plan::Plan,
    station: ratecal_drivers::Station,
    writer: RecordingWriter,
    opts: RunOptions,
    seed: u64,
}

fn run(args: Args) -> Result<ExitCode, Report> {
    let prep = match &args.resume {
        Some(dir) => prepare_resume(dir)?,
        None => prepare_new(&args)?,
    };
    let Prepared {
        dir,
        plan,
        station,
        mut writer,
        mut opts,
        seed,
    } = prep;
    let simulated = station.describe().simulated;
    if let Some(t) = link_timeout_s(&station) {
        // A link that comes back within its timeout must not trip the stall check first.
        opts.stall_timeout_s = opts.stall_timeout_s.max(t + 0.5);
    }
    let cancel = Arc::new(AtomicBool::new(false));
    opts.cancel = Some(cancel.clone());
    let mut bar = progress::Bar::new(plan.estimated_duration_s, simulated);

    // Ctrl-C (and SIGTERM) take the abort path: the table is brought to a safe stop and
    // every sample so far is kept. The handler is a thread of its own, so that a simulated
    // run needs no IO driver.
    let flag = cancel.clone();
    if let Err(e) = ctrlc::set_handler(move || flag.store(true, Ordering::Relaxed)) {
        eprintln!("warning: Ctrl-C will not stop the run cleanly: {e}");
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
                &mut bar,
                &opts,
            )
            .await,
        )
    })?;
    bar.finish();
    let wall = wall.elapsed().as_secs_f64();
    let outcome = outcome
        .map_err(|e| miette::miette!("cannot close the recording in {}: {e}", dir.display()))?;
    Ok(finish(&dir, &plan, &outcome, wall, simulated))
}

/// The longest timeout of a station's hardware links, s.
fn link_timeout_s(station: &ratecal_drivers::Station) -> Option<f64> {
    use ratecal_drivers::station::{ImuDriverSpec as I, TableDriverSpec as T};
    let table = match &station.table.driver {
        T::Tcp { timeout, .. } | T::Serial { timeout, .. } => Some(timeout.0),
        T::Sim | T::Replay { .. } => None,
    };
    let imu = match &station.imu.driver {
        I::Tcp { timeout, .. } | I::Serial { timeout, .. } => Some(timeout.0),
        I::Sim | I::Replay { .. } => None,
    };
    table.into_iter().chain(imu).reduce(f64::max)
}

fn prepare_new(args: &Args) -> Result<Prepared, Report> {
    let st = setup::station(args.station.as_deref(), args.dry_run)?;
    let proc_path = setup::procedure_file(args.procedure.as_deref().unwrap_or(Path::new(".")))?;
    let pr = setup::procedure(&proc_path, &st.station, None)?;
    let dir = args
        .out
        .clone()
        .unwrap_or_else(|| setup::default_out(&pr.plan.name));
    if dir.join("manifest.yaml").exists() {
        return Err(miette::miette!(
            help = "choose another --out, or continue it with --resume",
            "{} already holds a run",
            dir.display()
        ));
    }
    let io =
        |e: std::io::Error| miette::miette!("cannot write the run folder {}: {e}", dir.display());
    std::fs::create_dir_all(&dir).map_err(io)?;
    std::fs::write(dir.join("procedure.rcal"), &pr.text).map_err(io)?;
    pr.imports.save(&dir).map_err(io)?;
    std::fs::write(dir.join("station.yaml"), &st.yaml).map_err(io)?;
    let facts = setup::RunFacts {
        dir: &dir,
        dry_run: args.dry_run || args.station.is_none(),
        seed: args.seed,
        operator: args.operator.clone(),
    };
    let manifest = setup::manifest(&st, &pr, &facts);
    let columns = Columns {
        imu_temp: true,
        ambient: st.station.temperature.report_ambient,
    };
    let writer = RecordingWriter::create(&dir, manifest, columns).map_err(io)?;
    Ok(Prepared {
        dir,
        plan: pr.plan,
        station: st.station,
        writer,
        opts: RunOptions::default(),
        seed: args.seed,
    })
}

fn prepare_resume(dir: &Path) -> Result<Prepared, Report> {
    let io = |e: std::io::Error| {
        miette::miette!(
            help = "--resume takes a run folder written by `ratecal run`",
            "cannot resume {}: {e}",
            dir.display()
        )
    };
    let journal = std::fs::read_to_string(dir.join("journal.jsonl")).map_err(io)?;
    let point = resume_point(&journal);
    if point.completed {
        return Err(miette::miette!(
            "{} is a completed run: nothing to resume",
            dir.display()
        ));
    }
    let (mut writer, last_t) = RecordingWriter::append(dir).map_err(io)?;
    let dry_run = writer.manifest().run.as_ref().is_some_and(|r| r.dry_run);
    let seed = writer
        .manifest()
        .run
        .as_ref()
        .and_then(|r| r.seed)
        .unwrap_or(1);
    let st = setup::station(Some(&dir.join("station.yaml")), dry_run)?;
    let station_sha = sha256_hex(st.yaml.as_bytes());
    let pr = setup::procedure(&dir.join("procedure.rcal"), &st.station, Some(dir))?;
    let mut changed_station = None;
    let m = writer.manifest_mut();
    m.segments.truncate(point.segments);
    if let Some(run) = m.run.as_mut() {
        run.status = "running".into();
        run.abort = None;
        run.ended = None;
        // An operator may fix the station file before resuming (a fault rehearsal, a
        // repaired table): the resumed part runs with the new file, the journal keeps both.
        if let Some(old) = run.station_sha256.replace(station_sha.clone())
            && old != station_sha
        {
            changed_station = Some((old, station_sha.clone()));
        }
        // The data files are hashed again when the run ends; the import copies stand.
        run.files_sha256
            .retain(|name, _| name.starts_with(&format!("{}/", imports::IMPORTS_DIR)));
    }
    writer.checkpoint().map_err(io)?;
    if let Some((old, new)) = changed_station {
        eprintln!("station.yaml changed since the interrupted part: the rest runs with it");
        let entry = JournalEntry {
            t: last_t.unwrap_or(0.0),
            step: None,
            event: JournalEvent::Warning {
                rule: "station.yaml changed before the resume".into(),
                values: format!("sha256 {old} -> {new}"),
            },
        };
        writer.journal(&entry).map_err(io)?;
    }
    let opts = RunOptions {
        start_step: point.next_step,
        resume_segments: point.segments,
        // Time keeps increasing across the interruption (1 s gap).
        t_offset: last_t.map_or(0.0, |t| t + 1.0),
        ..RunOptions::default()
    };
    Ok(Prepared {
        dir: dir.to_path_buf(),
        plan: pr.plan,
        station: st.station,
        writer,
        opts,
        seed,
    })
}

/// Analysis of a completed run, summary, exit code.
fn finish(
    dir: &Path,
    plan: &ratecal_engine::plan::Plan,
    out: &RunOutcome,
    wall_s: f64,
    simulated: bool,
) -> ExitCode {
    let run_s = out.t_end - out.t_start;
    println!("run folder: {}", dir.display());
    let clock = if simulated { "simulated" } else { "run" };
    println!(
        "duration: {} {clock}, {:.1} s real ({:.0}x)",
        progress::hms(run_s),
        wall_s,
        run_s / wall_s.max(1e-9)
    );
    println!(
        "steps: {}/{}, segments: {}, warnings: {}",
        out.steps_completed,
        plan.steps.len(),
        out.segments,
        out.warnings.len()
    );
    if let Some(sync) = &out.sync {
        for (name, l) in [("imu", &sync.imu), ("table", &sync.table)] {
            if let Some(l) = l {
                println!(
                    "{name} link: {} samples, {} corrupted (skipped), {} lost, {} reconnects, delay {:.2}/{:.2}/{:.2} ms (min/mean/max)",
                    l.samples,
                    l.corrupted,
                    l.lost,
                    l.reconnects,
                    l.latency_min_ms,
                    l.latency_mean_ms,
                    l.latency_max_ms
                );
            }
        }
        if let Some(skew) = sync.table_minus_imu_s {
            println!(
                "table-to-IMU sync: table stamps {:+.3} ms relative to the IMU's (estimate)",
                skew * 1e3
            );
        }
    }
    match &out.status {
        RunStatus::Aborted(a) => {
            println!(
                "ABORTED at t = {:.3} s{}: {}",
                a.t,
                a.step
                    .as_ref()
                    .map(|s| format!(" in step {s}"))
                    .unwrap_or_default(),
                a.rule
            );
            println!("  {}", a.values);
            println!(
                "the recording holds every sample up to the safe stop; continue with `ratecal run --resume {}`",
                dir.display()
            );
            ExitCode::from(4)
        }
        RunStatus::Completed => analyze(dir, plan),
    }
}

/// Runs the analysis stage on the fresh recording and writes `results.json`.
fn analyze(dir: &Path, plan: &ratecal_engine::plan::Plan) -> ExitCode {
    let rec = match ratecal_engine::recording::read(dir) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("{:?}", Report::new(e));
            return ExitCode::from(1);
        }
    };
    let results = ratecal_engine::fit::analyze(&rec, Some(plan));
    if let Err(e) = std::fs::write(dir.join("results.json"), results.to_json()) {
        eprintln!("cannot write results.json: {e}");
        return ExitCode::from(1);
    }
    use ratecal_engine::results::Verdict;
    for a in &results.acceptance {
        let v = match a.verdict {
            Verdict::Pass => "pass",
            Verdict::Fail => "FAIL",
            Verdict::Indeterminate => "indeterminate",
            Verdict::NotEvaluated => "not evaluated",
        };
        let value = a
            .value
            .map_or_else(|| "-".to_string(), |x| format!("{x:.6}"));
        println!(
            "  {v:>13}  {} = {value} {} (limit {} {} {})",
            a.quantity, a.unit, a.op, a.limit, a.unit
        );
    }
    println!("results: {}", dir.join("results.json").display());
    // The checked plan beside the results lets `ratecal report` describe the process later.
    if let Ok(json) = serde_json::to_string_pretty(plan) {
        let _ = std::fs::write(dir.join("plan.json"), json);
    }
    let input = ratecal_engine::render::ReportInput::from_run(
        &results,
        &rec.manifest,
        Some(plan),
        Some(&rec),
        env!("CARGO_PKG_VERSION"),
    );
    match super::report::write_reports(dir, &input, None) {
        Ok(paths) => {
            for p in paths {
                println!("report: {}", p.display());
            }
        }
        Err(e) => {
            eprintln!("{e:?}");
            return ExitCode::from(1);
        }
    }
    if results.has_failure() {
        ExitCode::from(3)
    } else {
        ExitCode::from(0)
    }
}
