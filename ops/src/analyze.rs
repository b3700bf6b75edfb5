//! `ratecal analyze RUN_DIR... [--procedure PROCEDURE] [--out results.json]`: fits,
//! uncertainties and acceptance for one recording, or repeatability over several runs.
//! Exit codes: 0 the verdict is pass or not_judged (no acceptance check to judge), 3 it is
//! not (a failed check, a check that could not be evaluated, a failed sanity check, an
//! aborted run), 1 input error (a refused recording: time going backwards, clocks that do
//! not overlap...), 2 usage error (clap).

use crate::procedure::{self, FsSources};
use ratecal_analysis::fit::{self, Options};
use ratecal_analysis::measured::format_measured;
use ratecal_analysis::results::{Parameter, Results, RunVerdict};
use ratecal_check::{CheckOptions, check_text};
use ratecal_plan::Plan;
use std::path::PathBuf;

/// What `ratecal analyze` is asked.
pub struct Request {
    /// Recording folders; several runs of one procedure give the repeatability analysis.
    pub runs: Vec<PathBuf>,
    /// Procedure whose fits and thresholds apply (a checked plan as JSON too).
    pub procedure: Option<PathBuf>,
    /// Catalogue effects added to the model.
    pub with: Vec<String>,
    /// Where to write results.json (standard output without it).
    pub out: Option<PathBuf>,
    /// Accept a released version whose text no longer matches versions.lock.
    pub allow_changed: bool,
}

/// Analyses the runs; the exit code of spec/cli.md.
pub fn analyze(args: &Request) -> u8 {
    // An output never replaces an input (a recording, a seal, a recorded file).
    if let Some(out) = &args.out {
        let runs: Vec<&std::path::Path> = args.runs.iter().map(PathBuf::as_path).collect();
        if let Err(e) = ratecal_folder::outputs::refuse_inputs(out, "--out", &runs) {
            errln!("{e:?}");
            return 1;
        }
    }
    // Writing into a run folder: its lock first, so a second writer is refused at once.
    let _lock = match args
        .out
        .as_deref()
        .map(|p| ratecal_folder::lock::for_file(p, &ratecal_folder::sealing::command_line()))
    {
        Some(Err(e)) => {
            errln!("{e:?}");
            return 1;
        }
        Some(Ok(l)) => l,
        None => None,
    };
    // Results written into a sealed folder are computed from what its seal holds: the seal
    // is verified before anything is read (exit 4 when it fails, nothing written).
    let out_dir = args.out.as_deref().map(folder_of);
    if let Some(dir) = &out_dir
        && dir.join(ratecal_folder::names::SEAL_FILE).exists()
        && let Err(e) = ratecal_folder::verify::require_intact_replacing(
            dir,
            "results written into it",
            &[out_name(args.out.as_deref()).as_str()],
        )
    {
        errln!("{e:?}");
        return 4;
    }
    let load = |p: &std::path::Path| load_plan(p, args.allow_changed);
    let (plan, sha256) = match args.procedure.as_deref().map(load).transpose() {
        Ok(Some((p, h))) => (Some(p), h),
        Ok(None) => (None, None),
        Err(()) => return 1,
    };
    let mut runs = Vec::with_capacity(args.runs.len());
    for dir in &args.runs {
        match fit::Streamed::open(dir) {
            Ok(r) => runs.push((dir.display().to_string(), r)),
            Err(e) => {
                errln!("{:?}", miette::Report::new(e));
                return 1;
            }
        }
    }
    // The first run's station states the Type B figures of the budgets (a folder without a
    // station file is judged with the fit's Type A uncertainty, k = 2).
    let opts = Options {
        with: args.with.clone(),
        stated: args
            .runs
            .first()
            .and_then(|d| ratecal_certificate::stated_of_folder(d)),
        // The Allan series of a long block waits in an unlinked file of the temp dir, not
        // in memory.
        scratch: Some(fit::Scratch::new(tempfile::tempfile)),
        ..Options::default()
    };
    // The IMU stream is read a window at a time: a cell found bad there is refused as a
    // whole read would have refused it.
    let mut results = match fit::analyze_runs(&runs, plan.as_ref(), &opts) {
        Ok(r) => r,
        Err(e) => {
            errln!("{:?}", miette::Report::new(e));
            return 1;
        }
    };
    // The procedure given on the command line is identified by its own canonical hash.
    if let (Some(h), Some(p)) = (sha256, results.model.procedure.as_mut()) {
        p.sha256 = h;
    }
    let json = results.to_json();
    match &args.out {
        Some(path) => {
            // A file ratecal writes into a sealed run folder joins the seal, with the
            // command, in one committed change.
            let bytes = (json + "\n").into_bytes();
            // The folder's files the results were computed from, when it is the one read.
            use ratecal_folder::names::{IMU, MANIFEST, STATION, TABLE};
            let same = |a: &std::path::Path, b: &std::path::Path| {
                std::fs::canonicalize(a).ok() == std::fs::canonicalize(b).ok()
            };
            let read: &[&str] = match (&out_dir, args.runs.as_slice()) {
                (Some(d), [run]) if same(d, run) => &[MANIFEST, IMU, TABLE, STATION],
                _ => &[],
            };
            if let Err(e) = ratecal_folder::sealing::write_file(
                path,
                bytes,
                &ratecal_folder::sealing::command_line(),
                read,
            ) {
                errln!("error: cannot write {}: {e}", path.display());
                return if ratecal_folder::sealing::is_altered(&e) {
                    4
                } else {
                    1
                };
            }
        }
        None => outln!("{json}"),
    }
    summary(&results);
    exit_code(results.verdict)
}

/// The folder `path` lies in (`.` for a bare name).
fn folder_of(path: &std::path::Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// 0 for a pass and for nothing judged, 3 for every other verdict (spec/cli.md).
pub fn exit_code(v: RunVerdict) -> u8 {
    match v {
        RunVerdict::Pass | RunVerdict::NotJudged => 0,
        _ => 3,
    }
}

/// Loads and checks the procedure (a file, a folder's newest version, `folder@version`)
/// with the SHA-256 of its canonical text; a checked plan serialized as JSON is accepted
/// too (no hash then). Diagnostics go to standard error.
pub(crate) fn load_plan(
    arg: &std::path::Path,
    allow_changed: bool,
) -> Result<(Plan, Option<String>), ()> {
    if arg.extension().is_some_and(|e| e == "json") {
        let text = std::fs::read_to_string(arg)
            .map_err(|e| errln!("error: cannot read {}: {e}", arg.display()))?;
        return serde_json::from_str(&text)
            .map(|p| (p, None))
            .map_err(|e| errln!("error: {}: not a checked plan: {e}", arg.display()));
    }
    let file = procedure::read(&arg.display().to_string()).map_err(|d| procedure::report(&d))?;
    procedure::released_unchanged(&file, allow_changed).map_err(|_| ())?;
    match check_text(
        &file.display,
        &file.text,
        &FsSources,
        &CheckOptions::default(),
    ) {
        Ok(checked) => {
            checked.warnings.iter().for_each(procedure::report);
            let sha256 = ratecal_grammar::canonical(&file.text)
                .ok()
                .map(|c| c.sha256);
            Ok((checked.plan, sha256))
        }
        Err(diags) => {
            diags.iter().for_each(procedure::report);
            Err(())
        }
    }
}

/// A short human summary on standard error (standard output may hold the JSON).
fn summary(r: &Results) {
    errln!("ratecal analyze: {}", r.recording.paths.join(", "));
    match &r.model.procedure {
        Some(p) if r.model.selection == "procedure" => {
            errln!("model: the fits of procedure {} {}", p.name, p.version)
        }
        Some(p) => errln!(
            "model: segments chosen by kind (procedure {} {} has no fit statements)",
            p.name,
            p.version
        ),
        _ => errln!(
            "model: segments chosen by kind (no --procedure: no procedure's fits or thresholds apply)"
        ),
    }
    for f in &r.model.fits {
        errln!("  fit {f}");
    }
    for (name, p) in &r.parameters {
        match p {
            Parameter::Estimate { value, u, unit } => {
                errln!("  {name:<32} {}", format_measured(*value, *u, unit))
            }
            Parameter::Unobservable { .. } => errln!("  {name:<32} not observable"),
            Parameter::UpperBound {
                upper_bound, unit, ..
            } => errln!(
                "  {name:<32} <= {} (upper bound only)",
                ratecal_analysis::measured::format_value(*upper_bound, unit)
            ),
        }
    }
    for a in &r.acceptance {
        errln!("  [{}] {}", a.verdict.label(), a.name);
    }
    for line in verdict_lines(r) {
        errln!("{line}");
    }
}

/// The end of every terminal summary (`analyze`, `run`): the sanity checks that did not
/// pass, the warnings with their count (the count results.json and the report give), the
/// verdict and why it is what it is.
pub fn verdict_lines(r: &Results) -> Vec<String> {
    use ratecal_analysis::results::SanityStatus;
    let mut out = Vec::new();
    let passed = r
        .sanity
        .iter()
        .filter(|c| c.status == SanityStatus::Pass)
        .count();
    out.push(format!(
        "sanity: {passed} of {} checks pass",
        r.sanity.len()
    ));
    for c in r.sanity.iter().filter(|c| c.status != SanityStatus::Pass) {
        out.push(format!(
            "  [{}] {}: {}",
            c.status.label(),
            c.check,
            c.detail
        ));
    }
    out.push(format!("warnings: {}", r.warnings.len()));
    for w in &r.warnings {
        out.push(format!("  warning: {w}"));
    }
    let why = r
        .verdict_reason
        .as_ref()
        .map(|w| format!(" ({w})"))
        .unwrap_or_default();
    out.push(format!("verdict: {}{why}", r.verdict.label()));
    out
}

/// The file name of an output path (empty without one): an earlier copy of it in a sealed
/// folder is replaced, not read.
pub(crate) fn out_name(out: Option<&std::path::Path>) -> String {
    out.and_then(|p| p.file_name())
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default()
}
