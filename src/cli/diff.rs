//! `ratecal diff OLD NEW [--format text|json]`: the semantic diff of two procedure
//! versions (files or `folder@version`), compared after parameters and imports are
//! resolved. Exit codes like diff(1): 0 no semantic change, 1 changes, 2 error.

use ratecal_audit::{self as audit, render};
use ratecal_ops::procedure::load;
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
