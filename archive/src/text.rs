//! The archive's listings as text, for a person: `archive list` and `archive show`.

use crate::{RunDetail, RunSummary};
use ratecal_analysis::measured::format_measured;

/// `archive list` as a table, one run a line, with the count and how many dry runs the
/// filter left out (`hidden_dry`), so that an empty list is never a mystery.
pub fn list_table(runs: &[RunSummary], hidden_dry: usize) -> String {
    let mut s = format!(
        "{:<16}  {:<12}  {:<12}  {:<20}  {:<8}  {:<20}  {:<10}  {}\n",
        "ID", "SERIAL", "MODEL", "PROCEDURE", "VERSION", "STARTED", "VERDICT", "DRY RUN"
    );
    for r in runs {
        s.push_str(&format!(
            "{:<16}  {:<12}  {:<12}  {:<20}  {:<8}  {:<20}  {:<10}  {}\n",
            r.id,
            r.serial,
            r.model,
            r.procedure,
            r.version,
            r.started,
            r.verdict,
            if r.dry_run { "yes" } else { "no" }
        ));
    }
    s.push_str(&format!("{} run(s)", runs.len()));
    if hidden_dry > 0 {
        s.push_str(&format!(
            "; {hidden_dry} dry run(s) not listed (--include-dry-runs lists them)"
        ));
    }
    s.push('\n');
    s
}

/// `archive show` in words: the run, its parameters and its stored files.
pub fn show_text(d: &RunDetail) -> String {
    let r = &d.summary;
    let mut s = format!(
        "run {} ({})\n  imu: {} serial {}\n  procedure: {} {} (sha256 {})\n  station: {}\n  \
         operator: {}\n  started: {}\n  ended: {}\n  status: {}, verdict: {}{}\n  environment: {}\n",
        r.id,
        r.name,
        r.model,
        r.serial,
        r.procedure,
        r.version,
        d.procedure_sha256,
        r.station,
        r.operator.as_deref().unwrap_or("-"),
        r.started,
        d.ended.as_deref().unwrap_or("-"),
        d.status,
        r.verdict,
        if r.dry_run { " (dry run)" } else { "" },
        d.environment
    );
    s.push_str(&format!("parameters ({}):\n", d.parameters.len()));
    for p in &d.parameters {
        s.push_str(&format!(
            "  {:<28} {}\n",
            p.name,
            format_measured(p.value, p.u, &p.unit)
        ));
    }
    s.push_str(&format!("files ({}):\n", d.files.len()));
    for f in &d.files {
        s.push_str(&format!(
            "  {:<28} {:>10} B  {}\n",
            f.path, f.size, f.sha256
        ));
    }
    s
}

#[cfg(test)]
mod tests {
    #[test]
    fn hidden_dry_runs_are_counted() {
        assert!(super::list_table(&[], 0).ends_with("\n0 run(s)\n"));
        assert!(
            super::list_table(&[], 4)
                .ends_with("0 run(s); 4 dry run(s) not listed (--include-dry-runs lists them)\n")
        );
    }
}
