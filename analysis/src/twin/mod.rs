//! The station's twin against a recording (docs/explain.md, "The twin"): what the twin's
//! IMU model predicts for the recording's own motion ([`predict`]), which of its
//! parameters the recording contradicts and which physics it lacks ([`compare`]), and the
//! twin those changes make, which predicts again ([`update`]).
//!
//! The twin is plain data here ([`Twin`]): the CLI reads the station file (drivers) and
//! hands its terms in. Everything is solved from explain's single pass over the samples.

mod compare;
mod discovered;
mod output;
mod predict;
mod series;
mod text;
mod update;

pub use output::{Change, Kept, Prediction, SegmentResidual, Series, TwinReport};
pub use text::render_text;

use crate::explain::{self, Explanation, NominalModel, Options};
use crate::fit::{Retime, Source};

/// The twin's IMU model and noise as a station file states them.
#[derive(Debug, Clone, PartialEq)]
pub struct Twin {
    /// Every term the twin declares (nominal terms and catalogue effects, the table's
    /// station-side ones too), registry id and values in the catalogue's units; the
    /// Earth's rate is not one (site physics, always on).
    pub terms: Vec<(String, Vec<f64>)>,
    /// Reference temperature of its thermal terms, degC.
    pub t_ref_c: f64,
    /// White noise per sample: accelerometers m/s^2, gyros deg/s.
    pub noise: explain::Rms,
    /// Sigma of the gyro bias wander (Gauss-Markov), deg/s.
    pub gyro_bias_markov_sigma_dps: f64,
    /// Gyro bias random walk, deg/s per root second.
    pub gyro_bias_random_walk: f64,
}

impl Twin {
    /// The values of a term, if the twin declares it.
    pub fn values(&self, id: &str) -> Option<&[f64]> {
        self.terms
            .iter()
            .find(|(i, _)| i == id)
            .map(|(_, v)| v.as_slice())
    }
}

/// The nominal terms: the twin always has them (zero when the file leaves them out).
const NOMINAL: [&str; 4] = ["accel_bias", "accel_scale", "gyro_bias", "gyro_scale"];

/// The registry's timing terms: the simulator re-times the motion by them (exactly), so
/// the comparison evaluates the signals at the twin's timing and fits what is left.
pub(crate) use crate::explain::TIMING;

/// The timing a twin declares.
fn retime_of(twin: &Twin) -> Retime {
    Retime::from_registry(TIMING.map(|id| {
        twin.values(id)
            .and_then(|v| v.first())
            .copied()
            .unwrap_or(0.0)
    }))
}

/// Compares a recording with its twin: explain's findings with the twin's model as the
/// nominal one (its terms fitted, the Earth's rate held at the manifest's latitude), and
/// the twin's report. Fails only when a span of the recording cannot be read.
///
/// The signals are evaluated at the twin's own timing (`time_offset`, `clock_rate`), as
/// the simulator re-times the motion, so the twin's prediction holds its timing exactly.
/// When the recording's timing differs (50 ppm is 0.2 s late after an hour: far beyond
/// what a first-order column carries), the comparison is made again about the corrected
/// timing; the report keeps the first pass's prediction of the twin as it was.
pub fn compare_source<S: Source>(
    src: &S,
    twin: &Twin,
    opts: &Options,
) -> Result<(Explanation, TwinReport), S::Error> {
    let (x, report) = compare_at(src, twin, opts, retime_of(twin))?;
    let timing = |r: &TwinReport| -> Vec<Change> {
        r.changes
            .iter()
            .filter(|c| TIMING.contains(&c.effect.as_str()))
            .cloned()
            .collect()
    };
    let mut found = timing(&report);
    if found.is_empty() {
        return Ok((x, report));
    }
    let before = report.before.clone();
    // About the corrected timing, until what the timing columns leave is within their
    // uncertainty (a time offset hidden behind a large clock rate shows on the second
    // pass).
    let mut at = twin.clone();
    let (mut x, mut report) = (x, report);
    for _ in 0..TIMING_PASSES {
        for c in &found {
            match at.terms.iter_mut().find(|(id, _)| *id == c.effect) {
                Some((_, v)) => v[0] = c.to,
                None => at.terms.push((c.effect.clone(), vec![c.to])),
            }
        }
        let held = retime_of(&at);
        (x, report) = compare_at(src, twin, opts, held)?;
        let next = timing(&report);
        let settled = next.iter().all(|c| {
            let was = at.values(&c.effect).and_then(|v| v.first()).copied();
            was.is_some_and(|w| (c.to - w).abs() <= c.u)
        });
        found = next;
        if settled {
            break;
        }
    }
    report.before = before;
    x.warnings.push(format!(
        "the recording's timing differs from the twin's ({}): compared again about the corrected timing, so that the growing lag is taken exactly",
        found
            .iter()
            .map(|c| format!("{}.{} {} -> {:.4} {}", c.effect, c.parameter, c.from, c.to, c.unit))
            .collect::<Vec<_>>()
            .join(", ")
    ));
    Ok((x, report))
}

/// Passes about a corrected timing at most.
const TIMING_PASSES: usize = 3;

/// One comparison, the signals evaluated at timing `retime`.
fn compare_at<S: Source>(
    src: &S,
    twin: &Twin,
    opts: &Options,
    retime: Retime,
) -> Result<(Explanation, TwinReport), S::Error> {
    let (data, nonfinite) = explain::accumulate(src, opts, retime)?;
    let m = src.manifest();
    let t_ref_data = if data.layout.effects.iter().any(|e| e.uses_temperature()) {
        src.mean_temp()?
    } else {
        twin.t_ref_c
    };
    let mut effects: Vec<&'static str> = NOMINAL.to_vec();
    for (id, _) in &twin.terms {
        if let Some(e) = ratecal_physics::effect(id)
            && !effects.contains(&e.id())
            && e.id() != "earth_rate"
        {
            effects.push(e.id());
        }
    }
    // A timing the signals hold is part of the model the recording is compared with.
    for (id, v) in TIMING.iter().zip(retime.registry()) {
        if v != 0.0 && !effects.contains(id) {
            effects.push(id);
        }
    }
    for u in &opts.user {
        if twin.values(ratecal_physics::Effect::id(*u)).is_some() {
            effects.push(ratecal_physics::Effect::id(*u));
        }
    }
    let nominal = NominalModel {
        name: "twin".into(),
        effects,
        fixed: vec![(
            "earth_rate",
            ratecal_physics::effects::EarthRate::values(m.station.site.latitude_deg).to_vec(),
        )],
    };
    let x = explain::explain_data(m, &data, &nonfinite, &nominal, opts);
    let report = compare::report(m, &data, twin, &nominal, &x, t_ref_data, opts.alpha);
    Ok((x, report))
}
