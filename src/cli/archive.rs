//! `ratecal archive ...`: the calibration archive (add, list, show, export, trend, backup,
//! check), kept in a folder (SQLite + file store) or on a PostgreSQL server. Exit codes: 0
//! ok, 1 an error, a refused run or (check) an inconsistent archive, 2 usage.

use clap::{Subcommand, ValueEnum};
use miette::Report;
use ratecal_archive::trend::TrendOptions;
use ratecal_archive::{Archive, Filter, Location};
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `ratecal archive`.
#[derive(clap::Args)]
pub struct Args {
    /// Archive folder or postgres:// URL (default: $RATECAL_ARCHIVE, else ./archive/).
    #[arg(long, global = true, value_name = "DIR_OR_URL")]
    archive: Option<String>,
    /// With a postgres:// archive: keep the stored files in this shared folder instead of
    /// the database.
    #[arg(long, global = true, value_name = "DIR")]
    archive_files: Option<PathBuf>,
    #[command(subcommand)]
    command: Command,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum Format {
    Table,
    Json,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum TrendFormat {
    Table,
    Json,
    Svg,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum VerdictArg {
    Pass,
    Fail,
    Incomplete,
    Aborted,
    /// No acceptance check was evaluated (`not_judged`).
    NotJudged,
}

#[derive(Subcommand)]
enum Command {
    /// Store and index run folders (each verified first; adding twice changes nothing).
    Add {
        /// Run folders.
        #[arg(required = true)]
        runs: Vec<PathBuf>,
    },
    /// List archived runs, oldest first (dry runs only with --include-dry-runs).
    List {
        #[arg(long)]
        serial: Option<String>,
        #[arg(long)]
        model: Option<String>,
        #[arg(long)]
        procedure: Option<String>,
        /// Started on or after (YYYY-MM-DD or RFC 3339).
        #[arg(long)]
        since: Option<String>,
        /// Started on or before (a date includes the whole day).
        #[arg(long)]
        until: Option<String>,
        #[arg(long, value_enum)]
        verdict: Option<VerdictArg>,
        #[arg(long)]
        include_dry_runs: bool,
        #[arg(long, value_enum, default_value_t = Format::Table)]
        format: Format,
    },
    /// Everything the archive holds about one run (id, unique id prefix, or run name).
    Show {
        id: String,
        #[arg(long, value_enum, default_value_t = Format::Table)]
        format: Format,
    },
    /// Give a run folder back, byte for byte (`ratecal verify` passes on it).
    Export {
        id: String,
        /// New or empty folder.
        dir: PathBuf,
    },
    /// Parameters of one unit across its calibrations: drift and recalibration interval.
    Trend {
        serial: String,
        /// Parameter (dotted name); repeat for several; every parameter without it.
        #[arg(long = "param")]
        params: Vec<String>,
        /// Confidence of the recalibration interval (one-sided).
        #[arg(long, default_value_t = 0.95)]
        confidence: f64,
        #[arg(long)]
        include_dry_runs: bool,
        #[arg(long, value_enum, default_value_t = TrendFormat::Table)]
        format: TrendFormat,
        /// Print the recommended recalibration date (ISO/IEC 17025 7.8.4.3: only when
        /// agreed with the customer), when the history allows one.
        #[arg(long)]
        recommend_interval: bool,
    },
    /// A consistent copy (a folder archive) another machine can open.
    Backup {
        /// New or empty folder.
        dest: PathBuf,
    },
    /// Recompute every stored file's hash; check every index row points at stored files.
    Check {
        #[arg(long, value_enum, default_value_t = Format::Table)]
        format: Format,
        /// Remove the unfinished writes a killed `archive add` left (`files/tmp/`).
        #[arg(long)]
        fix: bool,
    },
}

/// Runs the subcommand.
pub fn main(args: Args) -> ExitCode {
    let loc = Location::resolve(args.archive.as_deref(), args.archive_files.clone());
    let rt = match tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
    {
        Ok(rt) => rt,
        Err(e) => {
            errln!("{:?}", miette::miette!("cannot start the runtime: {e}"));
            return ExitCode::from(1);
        }
    };
    match rt.block_on(run(&loc, args.command)) {
        Ok(code) => code,
        Err(report) => {
            errln!("{report:?}");
            ExitCode::from(1)
        }
    }
}

async fn run(loc: &Location, cmd: Command) -> Result<ExitCode, Report> {
    if let Command::Trend { confidence, .. } = &cmd
        && !(confidence.is_finite() && *confidence > 0.5 && *confidence < 1.0)
    {
        return Err(miette::miette!(
            code = "archive::bad_confidence",
            help = "give a probability between 0.5 and 1, e.g. --confidence 0.95",
            "--confidence {confidence} is not a confidence level"
        ));
    }
    // Only `add` creates an archive; a command that reads needs one that exists.
    let archive = if matches!(cmd, Command::Add { .. }) {
        Archive::open(loc).await?
    } else {
        Archive::open_existing(loc).await?
    };
    let code = match cmd {
        Command::Add { runs } => add(&archive, &runs).await,
        Command::List {
            serial,
            model,
            procedure,
            since,
            until,
            verdict,
            include_dry_runs,
            format,
        } => {
            let f = Filter {
                serial,
                model,
                procedure,
                since: since.map(|d| date_arg(&d)).transpose()?,
                until: until.map(|d| date_arg(&d)).transpose()?,
                verdict: verdict.map(|v| verdict_name(v).to_string()),
                include_dry_runs,
            };
            let runs = archive.list(&f).await?;
            match format {
                Format::Json => outln!("{}", to_json(&runs)?),
                Format::Table => {
                    let all = Filter {
                        include_dry_runs: true,
                        ..f.clone()
                    };
                    let hidden = archive.list(&all).await?.len() - runs.len();
                    out!("{}", ratecal_archive::list_table(&runs, hidden))
                }
            }
            ExitCode::SUCCESS
        }
        Command::Show { id, format } => {
            let d = archive.show(&id).await?;
            match format {
                Format::Json => outln!("{}", to_json(&d)?),
                Format::Table => out!("{}", ratecal_archive::show_text(&d)),
            }
            ExitCode::SUCCESS
        }
        Command::Export { id, dir } => {
            let (id, n) = archive.export(&id, &dir).await?;
            outln!("exported run {id}: {n} file(s) to {}", dir.display());
            ExitCode::SUCCESS
        }
        Command::Trend {
            serial,
            params,
            confidence,
            include_dry_runs,
            format,
            recommend_interval,
        } => {
            let opt = TrendOptions {
                params,
                include_dry_runs,
                confidence,
            };
            let t = archive.trend(&serial, &opt).await?;
            match format {
                TrendFormat::Json => outln!("{}", to_json(&t)?),
                TrendFormat::Table => out!("{}", t.text()),
                TrendFormat::Svg => out!("{}", t.svg()),
            }
            if recommend_interval {
                match t.recommended_interval() {
                    Some((_, line)) if format == TrendFormat::Table => outln!("{line}"),
                    Some((_, line)) => errln!("{line}"),
                    None => errln!(
                        "no recommended recalibration: the history determines no drift \
                         against an acceptance limit"
                    ),
                }
            }
            ExitCode::SUCCESS
        }
        Command::Backup { dest } => {
            let (runs, files) = archive.backup(&dest).await?;
            outln!(
                "backup: {runs} run(s), {files} stored file(s) in {} (open it with --archive {})",
                dest.display(),
                dest.display()
            );
            ExitCode::SUCCESS
        }
        Command::Check { format, fix } => {
            let r = archive.check_fix(fix).await?;
            match format {
                Format::Json => outln!("{}", to_json(&r)?),
                Format::Table => out!("{}", r.text()),
            }
            if r.ok() {
                ExitCode::SUCCESS
            } else {
                ExitCode::from(1)
            }
        }
    };
    archive.close().await;
    Ok(code)
}

/// Verifies then adds each run folder; a refused folder does not stop the others.
async fn add(archive: &Archive, runs: &[PathBuf]) -> ExitCode {
    let mut ok = true;
    for dir in runs {
        match ratecal_ops::archive::add_one(archive, dir).await {
            Ok(line) => outln!("{line}"),
            Err(e) => {
                ok = false;
                errln!("{e:?}");
            }
        }
    }
    if ok {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    }
}

fn verdict_name(v: VerdictArg) -> &'static str {
    match v {
        VerdictArg::Pass => "pass",
        VerdictArg::Fail => "fail",
        VerdictArg::Incomplete => "incomplete",
        VerdictArg::Aborted => "aborted",
        VerdictArg::NotJudged => "not_judged",
    }
}

/// A `--since`/`--until` date, checked; kept as written (compared as UTC text).
fn date_arg(d: &str) -> Result<String, Report> {
    match ratecal_archive::days_from_iso(d) {
        Some(_) => Ok(d.to_string()),
        None => Err(ratecal_archive::ArchiveError::BadDate(d.to_string()).into()),
    }
}

fn to_json<T: serde::Serialize>(v: &T) -> Result<String, Report> {
    serde_json::to_string_pretty(v).map_err(|e| miette::miette!("cannot write JSON: {e}"))
}
