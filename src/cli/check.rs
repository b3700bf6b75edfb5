//! `ratecal check`: syntax, units, names, station limits, observability and duration of
//! each procedure given; every diagnostic at once. Exit 0 (warnings allowed), 1 errors.

use ratecal_check::{CheckOptions, check_text};
use ratecal_ops::procedure::{self, FsSources};
use std::process::ExitCode;

/// Arguments of `ratecal check`.
#[derive(clap::Args)]
pub struct Args {
    /// Procedures: files, folders (newest version) or folder@version.
    #[arg(required = true)]
    inputs: Vec<String>,
    /// Station file: compare rates, accelerations, travel and the IMU with it (default: the
    /// built-in station `run` would use).
    #[arg(long)]
    station: Option<std::path::PathBuf>,
    /// Output format: text, or json (the checked plans on standard output).
    #[arg(long, value_parser = ["text", "json"], default_value = "text")]
    format: String,
    /// Accept a released version whose text no longer matches versions.lock (a warning).
    #[arg(long)]
    allow_changed: bool,
}

/// Formats a duration in seconds as `1 h 22 min`, `12 min`, `45 s`.
pub fn human_duration(s: f64) -> String {
    if !s.is_finite() {
        return "unbounded".to_string();
    }
    let total_min = (s / 60.0).round() as u64;
    match (total_min / 60, total_min % 60) {
        (0, 0) => format!("{} s", s.round() as u64),
        (0, m) => format!("{m} min"),
        (h, 0) => format!("{h} h"),
        (h, m) => format!("{h} h {m} min"),
    }
}

/// What explain could determine on a recording of this procedure: the registry effects
/// its motion determines in full, in part, and not at all (docs/explain.md).
fn observability_lines(obs: &[ratecal_check::EffectObservability]) -> Vec<String> {
    let list = |v: Vec<String>| {
        if v.is_empty() {
            "none".to_string()
        } else {
            v.join(", ")
        }
    };
    let full: Vec<String> = obs
        .iter()
        .filter(|o| o.not.is_empty())
        .map(|o| o.effect.to_string())
        .collect();
    let part: Vec<String> = obs
        .iter()
        .filter(|o| !o.not.is_empty() && !o.determined.is_empty())
        .map(|o| {
            let missing: Vec<&str> = o.not.iter().map(|n| n.0).collect();
            format!("{} (not {})", o.effect, missing.join(" "))
        })
        .collect();
    let none: Vec<String> = obs
        .iter()
        .filter(|o| o.determined.is_empty())
        .map(|o| o.effect.to_string())
        .collect();
    vec![
        format!("  explain can determine: {}", list(full)),
        format!("  in part: {}", list(part)),
        format!("  not at all: {}", list(none)),
    ]
}

/// Runs the subcommand.
pub fn main(args: Args) -> ExitCode {
    let mut failed = false;
    let mut plans = Vec::new();
    for input in &args.inputs {
        // A procedure folder also obeys the version rules of versions.lock (audit).
        if std::path::Path::new(input).is_dir() {
            for d in ratecal_ops::versions::check_folder(std::path::Path::new(input)) {
                procedure::report(&d);
                failed |= d.is_error();
            }
        }
        let file = match procedure::read(input) {
            Ok(f) => f,
            Err(d) => {
                procedure::report(&d);
                failed = true;
                continue;
            }
        };
        // A folder's versions were checked against the lock just above.
        if !std::path::Path::new(input).is_dir() {
            if procedure::released_unchanged(&file, args.allow_changed).is_err() {
                failed = true;
            }
            // A draft or a broken release however it is named (a path, folder@version).
            for d in ratecal_ops::release::file_diagnostics(&file) {
                procedure::report(&d);
                failed |= d.is_error();
            }
        }
        let (limits, station) =
            match ratecal_ops::station::for_check(args.station.as_deref(), &file.text) {
                Ok(s) => s,
                Err(e) => {
                    errln!("{e:?}");
                    return ExitCode::from(1);
                }
            };
        let opts = CheckOptions {
            station: Some(limits),
        };
        match check_text(&file.display, &file.text, &FsSources, &opts) {
            Ok(checked) => {
                checked.warnings.iter().for_each(procedure::report);
                let p = &checked.plan;
                let line = format!(
                    "{} {}: ok, estimated duration {}\n  station: {station}",
                    p.name,
                    p.version,
                    human_duration(p.estimated_duration_s)
                );
                let observes = observability_lines(checked.observability());
                if args.format == "json" {
                    errln!("{line}");
                    observes.iter().for_each(|l| errln!("{l}"));
                } else {
                    outln!("{line}");
                    observes.iter().for_each(|l| outln!("{l}"));
                }
                plans.push(checked.plan);
            }
            Err(diags) => {
                diags.iter().for_each(procedure::report);
                let n = diags.iter().filter(|d| d.is_error()).count();
                errln!(
                    "{}: {n} error{} (checked on {station})",
                    file.display,
                    if n == 1 { "" } else { "s" }
                );
                failed = true;
            }
        }
    }
    if args.format == "json" {
        match serde_json::to_string_pretty(&plans) {
            Ok(s) => outln!("{s}"),
            Err(e) => {
                errln!("ratecal check: cannot write JSON: {e}");
                return ExitCode::from(1);
            }
        }
    }
    if failed {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    }
}
