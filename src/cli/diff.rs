//! `ratecal diff OLD NEW [--format text|json]`: the semantic diff of two procedure
//! versions (files or `folder@version`), compared after parameters and imports are
//! resolved. Exit codes like diff(1): 0 no semantic change, 1 changes, 2 error.

use super::procedure::{self, FsSources};
use ratecal_audit::{self as audit, render};
use ratecal_check::{CheckOptions, check_text};
use ratecal_plan::Plan;
use std::io::IsTerminal;
use std::process::ExitCode;

/// Output format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    /// A change list an auditor reads and signs.
    Text,
    /// `{"old": {...}, "new": {...}, "changes": [...]}`.
    Json,
}

/// Arguments of `ratecal diff`.
#[derive(clap::Args)]
pub struct Args {
    /// Old version: a procedure file, a folder (its newest version) or `folder@version`.
    old: String,
    /// New version, in the same forms.
    new: String,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Text)]
    format: Format,
}

/// A procedure loaded for auditing.
pub(crate) struct Loaded {
    /// Its checked plan.
    pub plan: Plan,
    /// SHA-256 of its canonical text.
    pub sha256: String,
}

/// Resolves `file | folder | folder@version`, reads, checks and hashes a procedure. Its
/// diagnostics go to standard error; `None` when it cannot be used.
pub(crate) fn load(spec: &str) -> Option<Loaded> {
    match procedure::read(spec) {
        Ok(f) => load_text(&f.display, &f.text),
        Err(d) => {
            procedure::report(&d);
            None
        }
    }
}

/// Checks and hashes one procedure text (diagnostics to standard error).
pub(crate) fn load_text(display: &str, text: &str) -> Option<Loaded> {
    let checked = match check_text(display, text, &FsSources, &CheckOptions::default()) {
        Ok(c) => c,
        Err(diags) => {
            diags.iter().for_each(procedure::report);
            return None;
        }
    };
    let sha256 = match ratecal_grammar::canonical(text) {
        Ok(c) => c.sha256,
        Err(d) => {
            procedure::report(&d);
            return None;
        }
    };
    Some(Loaded {
        plan: checked.plan,
        sha256,
    })
}

/// Runs the subcommand.
pub fn main(args: Args) -> ExitCode {
    let (Some(old), Some(new)) = (load(&args.old), load(&args.new)) else {
        return ExitCode::from(2);
    };
    let report = audit::diff_report(&old.plan, &old.sha256, &new.plan, &new.sha256);
    match args.format {
        Format::Json => outln!("{}", render::json(&report)),
        Format::Text => {
            let color = std::io::stdout().is_terminal() && std::env::var_os("NO_COLOR").is_none();
            out!("{}", render::text(&report, color));
        }
    }
    if report.changes.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    }
}
