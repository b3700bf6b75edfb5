//! The one place `ratecal run` turns procedure text into a plan: parse, canonical hash,
//! check against the station's limits (the same check as `ratecal check --station`).

use crate::procedure;
use miette::Report;
use ratecal_check::{CheckOptions, Sources, check_text};
use ratecal_drivers::Station;
use ratecal_plan::Plan;
use std::path::Path;

/// Parses and checks a procedure (its imports read through `sources`); returns the plan and
/// the SHA-256 of its canonical text. Every diagnostic is printed; the error only summarises.
pub fn plan(
    path: &Path,
    text: &str,
    station: &Station,
    sources: &dyn Sources,
) -> Result<(Plan, String), Report> {
    let name = path.display().to_string();
    let opts = CheckOptions {
        station: Some(crate::station::station_limits(station)),
    };
    match check_text(&name, text, sources, &opts) {
        Ok(checked) => {
            checked.warnings.iter().for_each(procedure::report);
            let canon = ratecal_grammar::canonical(text).map_err(|d| {
                procedure::report(&d.with_source(&ratecal_grammar::source(&name, text)));
                miette::miette!("{name}: cannot format the procedure")
            })?;
            Ok((checked.plan, canon.sha256))
        }
        Err(diags) => {
            diags.iter().for_each(procedure::report);
            let n = diags.iter().filter(|d| d.is_error()).count();
            Err(miette::miette!(
                "{name}: {n} error{}; nothing was run",
                if n == 1 { "" } else { "s" }
            ))
        }
    }
}
