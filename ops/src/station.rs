//! A station file's user effects (`imu.user_effects`): their `.effect` files read
//! (relative to the station file's folder), checked, and their terms handed to the station
//! so that the simulator applies them as it applies the registry's effects.

use miette::{NamedSource, Report, SourceSpan, miette};
use ratecal_analysis::explain::{self, UserEffect};
use ratecal_check::StationLimits;
use ratecal_drivers::station::{self, Station};
use ratecal_physics::Effect;
use ratecal_physics::effects::Term;
use std::path::Path;

/// Reads the user effects `station` references (`text` its file's text, `path` the file)
/// into `station.user_terms`; returns the effects, for explain's layout.
pub fn load(
    station: &mut Station,
    text: &str,
    path: Option<&Path>,
) -> Result<Vec<&'static UserEffect>, Report> {
    let refs = &station.imu.user_effects;
    if refs.is_empty() {
        return Ok(Vec::new());
    }
    let name = path.map_or("<station>".to_string(), |p| p.display().to_string());
    let located = |message: String, help: &str| {
        let span =
            station::locate(text, "imu", "user_effects").map(|(a, n)| SourceSpan::new(a.into(), n));
        let mut r = miette!(
            labels = span
                .map(|s| vec![miette::LabeledSpan::at(s, "here")])
                .unwrap_or_default(),
            help = help.to_string(),
            "{name}: {message}"
        );
        r = r.with_source_code(NamedSource::new(name.clone(), text.to_string()));
        r
    };
    let base = path.and_then(Path::parent).unwrap_or(Path::new(""));
    let mut files: Vec<(String, String)> = Vec::new();
    for r in refs.values() {
        let p = base.join(&r.file);
        let shown = p.display().to_string();
        if files.iter().any(|f| f.0 == shown) {
            continue;
        }
        let body = std::fs::read_to_string(&p).map_err(|e| {
            located(
                format!("cannot read the user effect file {shown}: {e}"),
                "`file` is relative to the station file's folder",
            )
        })?;
        files.push((shown, body));
    }
    let effects = explain::user::load(&files).map_err(|diags| {
        diags.iter().for_each(super::procedure::report);
        located(
            "a user effect file has errors".into(),
            "docs/user-effects.md describes the language",
        )
    })?;
    let mut terms = Vec::new();
    for (id, r) in refs {
        let Some(e) = effects.iter().find(|e| e.id() == id) else {
            return Err(located(
                format!("`{id}` is not defined in {}", r.file),
                "the key under `user_effects` is the effect's id in its file",
            ));
        };
        let mut values = vec![0.0; e.params().len()];
        for (p, v) in &r.values {
            let Some(k) = e.params().iter().position(|q| q.name == p) else {
                let names: Vec<&str> = e.params().iter().map(|q| q.name).collect();
                return Err(located(
                    format!("`{id}` has no parameter `{p}`"),
                    &format!("its parameters: {}", names.join(", ")),
                ));
            };
            values[k] = *v;
        }
        terms.push(Term {
            effect: *e as &'static dyn Effect,
            values,
        });
    }
    station.user_terms.0 = terms;
    Ok(effects)
}

/// The station `ratecal check` compares a procedure with: the file given, or else the
/// embedded one `ratecal run` would use for it (`run::setup::builtin_for`); its limits and
/// how it is named in `check`'s output.
pub fn for_check(
    path: Option<&Path>,
    procedure_text: &str,
) -> Result<(StationLimits, String), Report> {
    let (yaml, name, described) = match path {
        Some(p) => {
            let yaml = std::fs::read_to_string(p)
                .map_err(|e| miette!("cannot read station `{}`: {e}", p.display()))?;
            (yaml, p.display().to_string(), p.display().to_string())
        }
        None => {
            let (y, n) = crate::run::setup::builtin_for(procedure_text);
            (
                y.to_string(),
                n.to_string(),
                format!("{n} (built in; --station FILE for yours)"),
            )
        }
    };
    let st = Station::from_yaml(&yaml, &name).map_err(|e| Report::new(*e))?;
    Ok((station_limits(&st), described))
}

/// The limits `check` compares a plan with, from a station description.
pub fn station_limits(st: &Station) -> StationLimits {
    StationLimits {
        max_rate_dps: st.table.max_rate.get(),
        max_accel_dps2: st.table.max_accel_dps2,
        gyro_range_dps: st.imu.gyro_range.get(),
        accel_range_mps2: st.imu.accel_range.get(),
        geometry: st.geometry(),
        manual: st.table.driver.kind.operator,
        travel_deg: [st.table.outer_travel, st.table.inner_travel]
            .map(|t| t.map(|[lo, hi]| (lo.get(), hi.get()))),
        imu_grade: st.imu.grade.clone(),
    }
}
