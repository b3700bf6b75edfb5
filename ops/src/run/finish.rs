//! The end of `ratecal run`: the summary on the terminal (every warning with its text), the
//! analysis (of an aborted run too, from the data kept), the reports, then the seal, written
//! last; and the record of a run that failed after its folder existed.

use ed25519_dalek::SigningKey;
use miette::Report;
use ratecal_analysis::measured::{format_k, format_measured, format_reading, format_value};
use ratecal_analysis::results::RunVerdict;
use ratecal_folder::RunFolder;
use ratecal_folder::names::{JOURNAL, MANIFEST, PLAN, RESULTS, SEAL_FILE};
use ratecal_plan::Plan;
use ratecal_recording::{manifest_yaml, parse_manifest, rfc3339};
use ratecal_run::{JournalEntry, JournalEvent, RunOutcome, RunStatus};
use std::path::Path;

/// A run that ended (completed or aborted), to analyse, report and seal.
pub struct End<'a> {
    /// The run folder.
    pub dir: &'a Path,
    /// The checked plan that ran.
    pub plan: &'a Plan,
    /// How the interpreter ended.
    pub outcome: &'a RunOutcome,
    /// Wall-clock seconds the run took.
    pub wall_s: f64,
    /// Whether the station was simulated (virtual clock).
    pub simulated: bool,
    /// The lab's key, to sign the seal.
    pub key: Option<&'a SigningKey>,
    /// The lab's archive (`--archive`), whose history of the unit the report uses.
    pub archive: Option<&'a str>,
    /// The streams hashed as they were written (`RecordingWriter::written`): the seal reads
    /// them again only if their length changed.
    pub written: &'a [ratecal_recording::WrittenFile],
}

impl End<'_> {
    /// Summary, analysis, reports, seal; the exit code of spec/cli.md.
    pub fn finish(&self) -> u8 {
        let (dir, out) = (self.dir, self.outcome);
        let run_s = out.t_end - out.t_start;
        outln!("run folder: {}", dir.display());
        let clock = if self.simulated { "simulated" } else { "run" };
        outln!(
            "duration: {} {clock}, {:.1} s real ({:.0}x)",
            super::hms(run_s),
            self.wall_s,
            run_s / self.wall_s.max(1e-9)
        );
        outln!(
            "steps: {}/{}, segments: {}",
            out.steps_completed,
            self.plan.steps.len(),
            out.segments,
        );
        if let Some(sync) = &out.sync {
            for (name, l) in [("imu", &sync.imu), ("table", &sync.table)] {
                if let Some(l) = l {
                    outln!(
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
                outln!(
                    "table-to-IMU sync: table stamps {:+.3} ms relative to the IMU's (estimate)",
                    skew * 1e3
                );
            }
        }
        let aborted = matches!(out.status, RunStatus::Aborted(_));
        if let RunStatus::Aborted(a) = &out.status {
            let step = a.step.as_ref().map(|s| format!(" in step {s}"));
            outln!(
                "ABORTED at t = {:.3} s{}: {}",
                a.t,
                step.unwrap_or_default(),
                a.rule
            );
            outln!("  {}", a.values);
            let upto = if self.at_rest() {
                "the safe stop"
            } else {
                "the end of the safe stop's wait"
            };
            if let Some(f) = write_failure(dir) {
                if let Some(end) = f.data_end_s {
                    outln!(
                        "  the write failed with the data at t = {end:.3} s: {} ends there (the run noticed it at t = {:.3} s)",
                        f.file,
                        a.t
                    );
                }
                outln!(
                    "a write failed ({}: {}): the recording holds every sample written before it; {}",
                    f.file,
                    f.error,
                    if f.cut_bytes > 0 {
                        format!("a partial last line ({} bytes) was cut", f.cut_bytes)
                    } else {
                        "no partial line was left".to_string()
                    }
                );
                outln!(
                    "free space (or raise the file-size limit), then continue with `ratecal run --resume {}`",
                    ratecal_folder::shell::quoted(dir)
                );
            } else {
                outln!(
                    "the recording holds every sample up to {upto}; continue with `ratecal run --resume {}`",
                    ratecal_folder::shell::quoted(dir)
                );
            }
        }
        let verdict = analyze(dir, self.plan, self.archive);
        if verdict.is_none() {
            // Without results, the run's own warnings are all there is to tell.
            outln!("warnings: {}", out.warnings.len());
            for w in &out.warnings {
                outln!("  warning: {w}");
            }
        }
        if let Err(e) = ratecal_folder::sealing::write_known(dir, self.key, self.written) {
            errln!("cannot seal {}: {e}", dir.display());
            self.warn_not_at_rest();
            return 1;
        }
        outln!("sealed: {}", dir.join(SEAL_FILE).display());
        self.warn_not_at_rest();
        match verdict {
            _ if aborted => 4,
            Some(v) => crate::analyze::exit_code(v),
            None => 1,
        }
    }
}

impl End<'_> {
    /// Whether the safe stop (if there was one) was seen to end at rest.
    fn at_rest(&self) -> bool {
        !self
            .outcome
            .warnings
            .iter()
            .any(|w| w.ends_with(ratecal_run::NOT_AT_REST))
    }

    /// The last lines on the console when the table may still be moving: plain, on both
    /// streams (a script may keep only one).
    fn warn_not_at_rest(&self) {
        if !self.at_rest() {
            let line = format!("WARNING: {}", ratecal_run::NOT_AT_REST);
            outln!("{line}");
            errln!("{line}");
        }
    }
}

/// The failed write the manifest records, if any.
fn write_failure(dir: &Path) -> Option<ratecal_recording::WriteFailure> {
    RunFolder::new(dir).manifest_quiet()?.run?.write_failure
}

/// A run that ended but was never sealed (a crash after its manifest said so), finished by
/// `run --resume`: analysed, reported and sealed. Exit codes as `run`'s.
pub fn seal_recorded(
    dir: &Path,
    plan: &Plan,
    status: &str,
    key: Option<&SigningKey>,
    archive: Option<&str>,
) -> u8 {
    let verdict = analyze(dir, plan, archive);
    let warnings = journal_warnings(dir);
    if verdict.is_none() {
        outln!("warnings: {}", warnings.len());
        for w in &warnings {
            outln!("  warning: {w}");
        }
    }
    if let Err(e) = ratecal_folder::sealing::write(dir, key) {
        errln!("cannot seal {}: {e}", dir.display());
        return 1;
    }
    outln!("sealed: {}", dir.join(SEAL_FILE).display());
    if status != "completed" {
        outln!(
            "the run {status} before its end; continue it with `ratecal run --resume {}`",
            ratecal_folder::shell::quoted(dir)
        );
    }
    if warnings
        .iter()
        .any(|w| w.ends_with(ratecal_run::NOT_AT_REST))
    {
        let line = format!("WARNING: {}", ratecal_run::NOT_AT_REST);
        outln!("{line}");
        errln!("{line}");
    }
    match verdict {
        _ if status != "completed" => 4,
        Some(v) => crate::analyze::exit_code(v),
        None => 1,
    }
}

/// Every warning of the run (all its parts, resumed or not) with its text, from the journal.
pub fn journal_warnings(dir: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(dir.join(JOURNAL)).unwrap_or_default();
    text.lines()
        .filter_map(|l| serde_json::from_str::<JournalEntry>(l).ok())
        .filter_map(|e| {
            let what = match e.event {
                JournalEvent::Warning { rule, values } => format!("{rule}: {values}"),
                JournalEvent::SettleTimeout {
                    after_s,
                    action,
                    unmet,
                } if action == "warn" => format!("settle timeout after {after_s:.1} s: {unmet}"),
                _ => return None,
            };
            let step = e.step.map(|s| format!(", step {s}")).unwrap_or_default();
            Some(format!("during the run (t = {:.3} s{step}): {what}", e.t))
        })
        .collect()
}

/// Analyses the recording kept (complete or not), writes results.json, plan.json and the
/// reports; the verdict, or `None` when the recording could not be analysed.
fn analyze(dir: &Path, plan: &Plan, archive: Option<&str>) -> Option<RunVerdict> {
    use ratecal_analysis::fit::{Options, Scratch, Source, Streamed, analyze_source};
    // The recording is read back a window at a time, as `ratecal analyze` reads it.
    let unreadable = |e| {
        errln!("{:?}", Report::new(e));
        errln!("no analysis: the recording cannot be read back");
    };
    let rec = Streamed::open(dir).map_err(unreadable).ok()?;
    // The station's Type B figures: every parameter's full budget, and the checks on
    // parameters judged with its U and k (the certificate states the same).
    let opts = Options {
        stated: ratecal_certificate::stated_of_folder(dir),
        // The Allan series of a long block waits in an unlinked file of the temp dir, not
        // in memory.
        scratch: Some(Scratch::new(tempfile::tempfile)),
        ..Options::default()
    };
    // The report's temperature plot is read beside the analysis: its one pass over two
    // cells of each line fills the analysis's single-threaded stretches.
    let (results, temperature) = std::thread::scope(|s| {
        let temperature =
            s.spawn(|| ratecal_render::TemperatureSeries::from_source(&rec).map_err(Box::new));
        let results = analyze_source(&rec, Some(plan), &opts);
        (results, temperature.join())
    });
    let mut results = results.map_err(unreadable).ok()?;
    let temperature = temperature
        .map_err(|_| errln!("no analysis: the temperature plot's reader stopped"))
        .ok()?
        .map_err(|e| unreadable(*e))
        .ok()?;
    let run_warnings = journal_warnings(dir);
    results.warnings.splice(0..0, run_warnings);
    if let Err(e) =
        ratecal_recording::commit::write_nofollow(&dir.join(RESULTS), results.to_json().as_bytes())
    {
        errln!("cannot write results.json: {e}");
        return None;
    }
    ratecal_recording::commit::crash_point("after-results");
    if !results.acceptance.is_empty() {
        outln!("acceptance (value ± expanded uncertainty U, k as stated):");
    }
    for a in &results.acceptance {
        // GUM 7.2.6: U to two digits and the value to match, with its k; a reading whose U
        // is not stated says so (no k for a U that is not there) at four digits.
        let (value, k) = match (a.value, a.expanded_u) {
            (Some(x), Some(u)) if u > 0.0 => (
                format_measured(x, u, &a.unit),
                a.k.map(|k| format!(", k = {}", format_k(k)))
                    .unwrap_or_default(),
            ),
            (Some(x), _) => (format_reading(x, &a.unit), ", U not stated".into()),
            (None, _) => (format!("- {}", a.unit), String::new()),
        };
        // A check made at several points says which (its name's last parenthesis).
        let at = (a.name.strip_suffix(')'))
            .and_then(|n| n.rfind(" (").map(|i| format!(": {}", &n[i + 2..])))
            .unwrap_or_default();
        outln!(
            "  {:>13}  {} = {value} (limit {} {}{k}){at}",
            a.verdict.label(),
            a.quantity,
            a.op,
            format_value(a.limit, &a.unit)
        );
    }
    // Sanity, warnings (the run's and the analysis's: the count results.json and the
    // report give) and the verdict, as `ratecal analyze` tells them.
    for line in crate::analyze::verdict_lines(&results) {
        outln!("{line}");
    }
    outln!("results: {}", dir.join(RESULTS).display());
    // The checked plan beside the results lets `ratecal report` describe the process later.
    if let Ok(json) = serde_json::to_string_pretty(plan) {
        let _ = ratecal_recording::commit::write_nofollow(&dir.join(PLAN), json.as_bytes());
    }
    let mut input = ratecal_render::ReportInput::from_run(
        &results,
        rec.manifest(),
        Some(plan),
        temperature,
        env!("CARGO_PKG_VERSION"),
    );
    let serial = crate::report::serial_of(&input);
    input.archive_trend = crate::archive::trend_json(archive, serial.as_deref());
    match crate::report::write_reports(dir, &input, None) {
        Ok(paths) => {
            for p in paths {
                outln!("report: {}", p.display());
            }
        }
        Err(e) => {
            errln!("{e:?}");
            return None;
        }
    }
    ratecal_recording::commit::crash_point("after-reports");
    Some(results.verdict)
}

/// Records that the run failed after its folder existed (`status: failed` and why), then
/// seals what the folder holds.
pub fn mark_failed(dir: &Path, why: &str, key: Option<&SigningKey>) -> std::io::Result<()> {
    let path = dir.join(MANIFEST);
    let text = std::fs::read_to_string(&path)?;
    let mut m =
        parse_manifest(MANIFEST, &text).map_err(|e| std::io::Error::other(e.to_string()))?;
    if let Some(run) = m.run.as_mut() {
        run.status = "failed".into();
        run.failure = Some(why.to_string());
        run.ended = Some(rfc3339(std::time::SystemTime::now()));
    }
    ratecal_recording::commit::write_atomic(dir, MANIFEST, manifest_yaml(&m)?.as_bytes())?;
    outln!("FAILED: {why}");
    outln!("the run folder {} records the failure", dir.display());
    ratecal_folder::sealing::write(dir, key)
}
