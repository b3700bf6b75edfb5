//! `ratecal explain --model M [RUN...] --twin STATION --write-twin OUT.yaml`: the model's
//! twin. The station file `STATION` with the fleet's pooled values written into its IMU
//! effects, through the single recording's twin editor (`crate::twin::corrected`): every
//! parameter whose verdict is `model` or `pooled_only` (pooled without the outliers), its
//! uncertainty `sqrt(u^2 + spread^2)`, what a new unit of the model is expected to show
//! (the pooled value is known to u, a unit lies about it by the spread). The rest of the
//! file (site, table, the unit's own bias and scale, what the fleet does not share) stays
//! as written. docs/explain.md, "Across recordings".

use crate::across::Explained;
use ratecal_analysis::explain::UserEffect;
use ratecal_analysis::explain::across::{Across, PooledOut};
use ratecal_analysis::fit::{Source, Streamed};
use ratecal_analysis::twin::Change;
use ratecal_physics::Effect;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// Where the model's twin is written, and from which station file.
pub struct Target {
    /// The station file (or run folder) whose text is edited.
    pub twin: PathBuf,
    /// Where the model's twin is written.
    pub out: PathBuf,
}

/// The model's twin: JSON key `twin` of explain across.
#[derive(Debug, Clone, Serialize)]
pub struct ModelTwin {
    /// The station file edited, as given.
    pub station: String,
    /// The model (`imu.model`) the fleet shares.
    pub model: String,
    /// The file written (absent when it was not).
    pub written: Option<String>,
    /// The pooled values written: `to` the pooled value, `u` with the spread.
    pub changes: Vec<Change>,
    /// Pooled `model`/`pooled_only` parameters not written, and why.
    pub not_written: Vec<NotWritten>,
    /// The unified diff from the station file to the model's twin.
    pub diff: Option<String>,
    /// Why it was not written.
    #[serde(skip)]
    pub failed: Option<String>,
}

/// A pooled parameter the station file cannot hold.
#[derive(Debug, Clone, Serialize)]
pub struct NotWritten {
    /// Effect id.
    pub effect: String,
    /// Parameter.
    pub parameter: String,
    /// Why.
    pub why: String,
}

/// A command that stops with this exit code, its diagnostics said.
type Exit = u8;

fn refuse(code: &str, help: &str, msg: String) -> Exit {
    let e = miette::miette!(code = code.to_string(), help = help.to_string(), "{msg}");
    errln!("{e:?}");
    2
}

/// `--write-twin` without `--twin` (one recording or several): refused, exit 2.
pub fn needs_twin(write_twin: Option<&Path>, twin: Option<&Path>) -> Result<(), Exit> {
    match (write_twin, twin) {
        (Some(out), None) => Err(refuse(
            "explain::write_twin_needs_twin",
            "add --twin STATION: the station file (or run folder) whose text the twin is written into",
            format!(
                "--write-twin {} needs --twin: there is no station file to write",
                out.display()
            ),
        )),
        _ => Ok(()),
    }
}

/// The model's twin, ready to be written once the fleet is pooled: where, and the station
/// file read.
pub struct Job {
    /// Where from and to.
    pub target: Target,
    file: crate::twin::TwinFile,
}

/// What the model's twin needs before anything is explained: not one unit's history
/// (`--serial`), recordings of one model, an output that is no run's input, a station file
/// that reads. Exit 2.
pub fn prepare(
    target: Target,
    runs: &[PathBuf],
    serial: Option<&str>,
    model: Option<&str>,
) -> Result<Job, Exit> {
    if let Some(sn) = serial {
        return Err(refuse(
            "explain::model_twin_of_a_serial",
            "write the model's twin from a fleet: --model M instead of --serial (one unit's twin: explain one recording with --twin --write-twin)",
            format!("--write-twin writes a model's twin; --serial {sn} selects one unit's history"),
        ));
    }
    let runs_ref: Vec<&Path> = runs.iter().map(PathBuf::as_path).collect();
    if let Err(e) = ratecal_folder::outputs::refuse_inputs(&target.out, "--write-twin", &runs_ref) {
        errln!("{e:?}");
        return Err(2);
    }
    let mut models: Vec<(String, String)> = model
        .map(|m| ("--model".to_string(), m.to_string()))
        .into_iter()
        .collect();
    for dir in runs {
        // A folder that cannot be read is said when it is explained.
        if let Ok(rec) = Streamed::open(dir) {
            let m = rec.manifest().imu.get("model").cloned();
            models.push((
                dir.display().to_string(),
                m.unwrap_or_else(|| "unknown".into()),
            ));
        }
    }
    one_model(&models)?;
    let file = crate::twin::read(&target.twin).map_err(|()| 2u8)?;
    Ok(Job { target, file })
}

/// The one model of `(source, model)` pairs; refused (exit 2) when they differ.
fn one_model(models: &[(String, String)]) -> Result<String, Exit> {
    let Some((_, first)) = models.first() else {
        return Ok("unknown".into());
    };
    match models.iter().find(|(_, m)| m != first) {
        None => Ok(first.clone()),
        Some((other, m)) => Err(refuse(
            "explain::model_twin_of_several_models",
            "a model's twin pools recordings of one imu.model: select them with --model M, or give only folders of that model",
            format!(
                "--write-twin writes one model's twin, but {} is {first:?} and {other} is {m:?}",
                models[0].0
            ),
        )),
    }
}

/// Writes the model's twin of the pooled fleet; the report (`written` absent and `failed`
/// saying why when it could not be written). Recordings of several models: refused, exit 2.
pub fn write(
    job: &Job,
    a: &Across,
    explained: &[Explained],
    user: &[&'static UserEffect],
) -> Result<ModelTwin, Exit> {
    let models: Vec<(String, String)> = explained
        .iter()
        .map(|e| (e.run.clone(), e.model.clone()))
        .collect();
    let model = one_model(&models)?;
    let (f, target) = (&job.file, &job.target);
    if !f.station.imu.model.is_empty() && f.station.imu.model != model {
        errln!(
            "warning: the station file's imu.model is {:?}, the fleet's {model:?}: its IMU effects are the fleet's, the rest as written",
            f.station.imu.model
        );
    }
    let (changes, not_written) = changes(a, &f.station, user);
    let header = header(a, &model, &changes);
    let mut report = ModelTwin {
        station: target.twin.display().to_string(),
        model,
        written: None,
        changes,
        not_written,
        diff: None,
        failed: None,
    };
    let written = crate::twin::corrected(f, &report.changes, &target.out, &header).and_then(
        |(text, diff)| {
            ratecal_recording::commit::write_nofollow(&target.out, text.as_bytes())
                .map(|()| diff)
                .map_err(|e| e.to_string())
        },
    );
    match written {
        Ok(diff) => {
            report.written = Some(target.out.display().to_string());
            report.diff = Some(diff);
        }
        Err(why) => report.failed = Some(why),
    }
    Ok(report)
}

/// Says why the model's twin was not written (after the pool's output): exit 2.
pub fn say_failed(t: &ModelTwin, out: &Path) -> Option<Exit> {
    let why = t.failed.as_deref()?;
    Some(refuse(
        "explain::twin_not_written",
        "the pool above stands; fix what is named and run the query again with --write-twin",
        format!(
            "the model's twin \"{}\" was not written: {why}",
            out.display()
        ),
    ))
}

/// Whether a pooled entry goes into the model's twin.
fn shared(e: &PooledOut) -> bool {
    e.verdict == "model" || e.verdict == "pooled_only"
}

/// The changes the fleet makes to the station file, and what it cannot hold.
fn changes(
    a: &Across,
    st: &ratecal_drivers::station::Station,
    user: &[&'static UserEffect],
) -> (Vec<Change>, Vec<NotWritten>) {
    let twin = crate::twin::twin_of(st);
    let (mut out, mut not) = (Vec::new(), Vec::new());
    for e in a.effects.iter().filter(|e| shared(e)) {
        let u_user = user.iter().find(|u| u.id() == e.effect);
        let fx: Option<&dyn Effect> =
            ratecal_physics::effect(&e.effect).or_else(|| u_user.map(|u| *u as &dyn Effect));
        let k = fx.and_then(|fx| fx.params().iter().position(|p| p.name == e.parameter));
        let (Some(_), Some(k)) = (fx, k) else {
            not.push(NotWritten {
                effect: e.effect.clone(),
                parameter: e.parameter.clone(),
                why: "a library form, not an effect a station file holds: explain one recording that finds it with --draft-effects, and pool again with --effects".into(),
            });
            continue;
        };
        let from = twin.values(&e.effect).and_then(|v| v.get(k)).copied();
        let u = e.fleet_u();
        out.push(Change {
            effect: e.effect.clone(),
            parameter: e.parameter.clone(),
            from: from.unwrap_or(0.0),
            to: e.pooled,
            u,
            unit: e.unit.clone(),
            standard_errors: (e.pooled - from.unwrap_or(0.0)).abs() / u,
            added: from.is_none(),
            defined_in: u_user.map(|u| u.file().to_string()),
        });
    }
    (out, not)
}

/// The comment the model's twin opens with: where its values come from, each with its
/// uncertainty (a station file states values only).
fn header(a: &Across, model: &str, changes: &[Change]) -> String {
    let units = a.units();
    let mut s = format!(
        "# The twin of model {model}: `ratecal explain` pooled {} recordings of {units} units.\n\
         # IMU effects shared by the fleet (verdict model or pooled_only), each as\n\
         # pooled ± sqrt(u^2 + spread^2) (the pooled value's u and the spread between units):\n",
        a.recordings.len()
    );
    for c in changes {
        let e = a
            .effects
            .iter()
            .find(|e| e.effect == c.effect && e.parameter == c.parameter && shared(e));
        let Some(e) = e else { continue };
        let left = match e.left_out.is_empty() {
            true => String::new(),
            false => format!("; left out: {}", e.left_out.join(", ")),
        };
        s.push_str(&format!(
            "#   {}.{} = {} ± {} {} ({}; pooled u {}, spread {}{left})\n",
            c.effect,
            c.parameter,
            ratecal_drivers::station::number(c.to, c.u),
            sig2(c.u),
            c.unit,
            e.verdict,
            sig2(e.u),
            sig2(e.spread),
        ));
    }
    s
}

/// Two significant digits.
fn sig2(v: f64) -> String {
    ratecal_drivers::station::number(v, v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use ratecal_analysis::explain::across::PerRecording;

    fn entry(effect: &str, parameter: &str, verdict: &str) -> PooledOut {
        PooledOut {
            effect: effect.into(),
            parameter: parameter.into(),
            pooled: 20.0,
            u: 3.0,
            spread: 4.0,
            i2: 0.5,
            verdict: verdict.into(),
            per_recording: vec![PerRecording {
                run: "r".into(),
                serial: "s".into(),
                value: 20.0,
                u: 3.0,
            }],
            left_out: vec![],
            unit: "ug/g^2".into(),
        }
    }

    #[test]
    fn only_what_the_fleet_shares_is_written_with_the_spread_in_its_u() {
        let st = ratecal_drivers::Station::from_yaml(ratecal_drivers::DEFAULT_STATION_YAML, "d")
            .unwrap();
        let a = Across {
            recordings: vec![],
            effects: vec![
                entry("accel_second_order", "x", "model"),
                entry("accel_second_order", "y", "pooled_only"),
                entry("lever_arm", "rxx_mm", "unit"),
                entry("gyro_scale_asymmetry", "x", "occasional"),
                entry("form_gyro_decay", "gx", "model"),
            ],
            outliers: vec![],
        };
        let (ch, not) = changes(&a, &st, &[]);
        let names: Vec<(&str, &str)> = ch
            .iter()
            .map(|c| (c.effect.as_str(), c.parameter.as_str()))
            .collect();
        assert_eq!(
            names,
            [("accel_second_order", "x"), ("accel_second_order", "y")]
        );
        assert!(ch.iter().all(|c| c.to == 20.0 && c.u == 5.0 && c.added));
        assert_eq!(not.len(), 1);
        assert_eq!(not[0].effect, "form_gyro_decay");
    }

    #[test]
    fn recordings_of_two_models_are_refused() {
        let m = |s: &str, m: &str| (s.to_string(), m.to_string());
        assert_eq!(one_model(&[m("a", "X"), m("b", "X")]), Ok("X".into()));
        assert_eq!(one_model(&[m("a", "X"), m("b", "Y")]), Err(2));
    }
}
