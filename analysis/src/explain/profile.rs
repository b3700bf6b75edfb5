//! A recording's profile: every candidate (registry effect, user effect, library form)
//! fitted beside the recording's final model, found there or not, each parameter with its
//! value and honest u. What `explain` over several recordings pools (`super::across`):
//! an effect too weak to pass in any one recording is still measured in each.
//!
//! Forms are named by form and channel, not by instant (`form_accel_f2` / `ax`); a decay
//! is fitted at the time constant of the library's grid that the recording likes best
//! (`form_gyro_decay` / `gx`; the time constant is not pooled: where no decay is, the
//! best one is noise, and always positive). A bias step's instant differs between
//! recordings and is not profiled. The Earth's rate (held at its physical value) and the
//! nominal model's terms are not profiled; neither is a column the recording cannot
//! determine.

use super::data::Data;
use super::model::{Terms, fit};
use super::probe::Form;
use super::stats::wald;
use crate::fit::joint::{CHANNELS, Fit};
use ratecal_physics::effects::Sensor;
use serde::{Deserialize, Serialize};

/// One parameter of a candidate fitted beside a recording's final model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Fitted {
    /// The registry or user effect's id, or `form_<sensor>_<form>` for a library form.
    pub effect: String,
    /// The parameter's name (`rxx_mm`), or a form's channel (`ax`).
    pub parameter: String,
    /// Value, in `unit`.
    pub value: f64,
    /// Standard uncertainty (white noise and the wandering bias), in `unit`.
    pub u: f64,
    /// Unit.
    pub unit: String,
    /// The output channel it acts on (`ax` ... `gz`), when one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub channel: Option<String>,
    /// Whether explain reported the effect in this recording.
    #[serde(default)]
    pub found: bool,
}

/// Every candidate of `data` fitted beside the final model `terms` over every segment
/// (`start_skip`: the columns the recording cannot determine; `found`: layout effects
/// reported as findings).
pub(crate) fn profile(
    data: &Data,
    terms: &Terms,
    start_skip: &[usize],
    found: &[usize],
    latitude_deg: f64,
) -> Vec<Fitted> {
    use rayon::prelude::*;
    let all: Vec<usize> = (0..data.accs.len()).collect();
    let terms = &with_earth(data, terms, latitude_deg);
    let mut plain: Vec<usize> = data
        .candidates
        .iter()
        .copied()
        .filter(|&e| e != data.earth)
        .collect();
    plain.extend(
        data.probes
            .iter()
            .filter(|(_, p)| !matches!(p.form, Form::Step { .. } | Form::ScaleStep { .. }))
            .filter(|(_, p)| !matches!(p.form, Form::Decay { .. }))
            .map(|&(e, _)| e),
    );
    let mut out: Vec<Fitted> = plain
        .par_iter()
        .flat_map_iter(|&e| {
            let f = beside(data, terms, start_skip, e, &all);
            entries(data, e, &f, start_skip, found.contains(&e), false)
        })
        .collect();
    for sensor in [Sensor::Accel, Sensor::Gyro] {
        out.extend(decay(data, terms, start_skip, found, sensor, &all));
    }
    out
}

/// The final model with the Earth's rate held at its physical value when it lacks it: a
/// recording too short to find it still turns with the Earth, and a candidate that mimics
/// it (a g-sensitivity) would take it up alike in every recording, which the pool would
/// then find.
fn with_earth(data: &Data, terms: &Terms, latitude_deg: f64) -> Terms {
    let reg = data.layout.index("earth_rate");
    let has = terms.effects.contains(&data.earth)
        || reg.is_some_and(|r| terms.effects.contains(&r) || terms.fixed.iter().any(|f| f.0 == r));
    let mut t = terms.clone();
    if !has {
        t.effects.push(data.earth);
        if super::earth::hold(data, &mut t, latitude_deg).is_none() {
            return terms.clone();
        }
    }
    t
}

/// The final model with candidate `e` added (every column of it the recording determines).
fn beside(data: &Data, terms: &Terms, start_skip: &[usize], e: usize, all: &[usize]) -> Fit {
    let mut t = terms.clone();
    let cols: Vec<usize> = data.layout.columns_of(e).collect();
    if !t.effects.contains(&e) {
        t.effects.push(e);
    }
    // A discovered form keeps only its significant channels: here every channel is fitted.
    t.skip
        .retain(|g| !cols.contains(g) || start_skip.contains(g));
    fit(data, &t, all, all).0
}

/// The decay of the library on `sensor` at the grid's time constant that removes most
/// (the largest Wald statistic over its channels), as entries.
fn decay(
    data: &Data,
    terms: &Terms,
    start_skip: &[usize],
    found: &[usize],
    sensor: Sensor,
    all: &[usize],
) -> Vec<Fitted> {
    use rayon::prelude::*;
    let grid: Vec<(usize, f64)> = data
        .probes
        .iter()
        .filter(|(_, p)| p.sensor == sensor)
        .filter_map(|&(e, p)| match p.form {
            Form::Decay { tau, .. } => Some((e, tau)),
            _ => None,
        })
        .collect();
    let best = grid
        .par_iter()
        .map(|&(e, tau)| {
            let f = beside(data, terms, start_skip, e, all);
            let cols: Vec<usize> = data
                .layout
                .columns_of(e)
                .filter(|g| f.estimated.contains(g))
                .collect();
            let chi2 = if cols.is_empty() {
                0.0
            } else {
                wald(&f, &cols).0
            };
            (e, tau, f, chi2)
        })
        .max_by(|a, b| a.3.total_cmp(&b.3));
    let Some((e, _, f, _)) = best else {
        return Vec::new();
    };
    let any_found = grid.iter().any(|(g, _)| found.contains(g));
    entries(data, e, &f, start_skip, any_found, true)
}

/// The determined columns of candidate `e` in fit `f` as entries (`decay`: a decay at
/// some time constant of the grid, named for every time constant alike).
fn entries(
    data: &Data,
    e: usize,
    f: &Fit,
    start_skip: &[usize],
    found: bool,
    decay: bool,
) -> Vec<Fitted> {
    let lay = &data.layout;
    let probe = data.probe(e);
    let effect = match (probe, decay) {
        (Some(p), true) => format!("form_{}_decay", p.sensor.name()),
        _ => super::observe::candidate_name(data, e),
    };
    lay.columns_of(e)
        .filter(|g| !start_skip.contains(g) && f.estimated.contains(g))
        .filter(|&g| f.u(g).is_finite() && f.u(g) > 0.0 && f.theta[g].is_finite())
        .map(|g| {
            let p = lay.param(g);
            let channel = p
                .channel
                .map(|(s, ax)| CHANNELS[if s == Sensor::Accel { ax } else { 3 + ax }].to_string());
            let parameter = match (probe, &channel) {
                (Some(_), Some(c)) => c.clone(),
                _ => p.name.to_string(),
            };
            Fitted {
                effect: effect.clone(),
                parameter,
                value: f.theta[g],
                u: f.u(g),
                unit: p.unit.to_string(),
                channel,
                found,
            }
        })
        .collect()
}
