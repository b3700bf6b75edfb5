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

pub use output::{Change, Prediction, SegmentResidual, Series, TwinReport};
pub use text::render_text;

use crate::explain::{self, Explanation, NominalModel, Options};
use crate::fit::Source;

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
    pub gyro_bias_instability_dps: f64,
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

/// Compares a recording with its twin: explain's findings with the twin's model as the
/// nominal one (its terms fitted, the Earth's rate held at the manifest's latitude), and
/// the twin's report. Fails only when a span of the recording cannot be read.
pub fn compare_source<S: Source>(
    src: &S,
    twin: &Twin,
    opts: &Options,
) -> Result<(Explanation, TwinReport), S::Error> {
    let (data, nonfinite) = explain::accumulate(src, opts)?;
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
