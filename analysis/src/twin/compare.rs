//! Which of the twin's parameters the recording contradicts, and which effects it lacks.
//!
//! One fit over every segment: the twin's terms (nominal and declared effects) fitted,
//! explain's findings beside them, the Earth's rate held at the manifest's latitude. A
//! twin parameter changes only when the fit lies beyond the combined uncertainty of both
//! (the fit's honest covariance; for the gyro biases also the twin's stated bias
//! instability and random walk), Bonferroni-corrected over every parameter compared
//! (family-wise `alpha`, as explain's findings): a right twin keeps every value in all
//! but a fraction `alpha` of recordings. An effect found that the twin lacks is added with
//! every parameter the recording determines (`from` 0).

use super::output::{Change, Kept, TwinReport};
use super::predict::{THERMAL, predict, theta};
use super::{Twin, update};
use crate::explain::data::Data;
use crate::explain::model::{Terms, fit};
use crate::explain::{Explanation, NominalModel};
use crate::recording::Manifest;
use statrs::distribution::{ContinuousCDF, Normal};

/// The twin's report on a recording explain has read (`x`, with the twin's terms as its
/// nominal model).
pub(super) fn report(
    m: &Manifest,
    data: &Data,
    twin: &Twin,
    nominal: &NominalModel,
    x: &Explanation,
    t_ref_data: f64,
    alpha: f64,
) -> TwinReport {
    let lay = &data.layout;
    let own: Vec<usize> = nominal
        .effects
        .iter()
        .filter_map(|id| lay.index(id))
        .collect();
    let found: Vec<(usize, Option<String>)> = x
        .findings
        .iter()
        .filter(|f| f.effect != "earth_rate")
        .filter_map(|f| Some((lay.index(&f.effect)?, f.defined_in.clone())))
        .filter(|(e, _)| !own.contains(e))
        .collect();
    let earth = lay.index("earth_rate").expect("a registry id");
    let discovered = super::discovered::terms(data, x);
    let mut effects: Vec<usize> = own
        .iter()
        .chain(found.iter().map(|f| &f.0))
        .copied()
        .collect();
    for d in &discovered {
        if !effects.contains(&d.probe) {
            effects.push(d.probe);
        }
    }
    let terms = Terms {
        effects,
        fixed: vec![(
            earth,
            ratecal_physics::effects::EarthRate::values(m.station.site.latitude_deg).to_vec(),
        )],
        skip: Vec::new(),
    };
    let all: Vec<usize> = (0..data.accs.len()).collect();
    let (f, unobservable) = fit(data, &terms, &all, &all);
    let white: [f64; 6] = std::array::from_fn(|c| f.noise[c].sigma);
    let th_twin = theta(m, data, twin, t_ref_data);
    let before = predict(m, data, twin, &th_twin, &white);
    let dt = t_ref_data - twin.t_ref_c;
    let span = m.segments.iter().map(|s| s.t_end).fold(0.0, f64::max)
        - m.segments
            .iter()
            .map(|s| s.t_start)
            .fold(f64::INFINITY, f64::min);
    let wander = twin
        .gyro_bias_markov_sigma_dps
        .hypot(twin.gyro_bias_random_walk * span.max(0.0).sqrt());
    let ok = |g: usize| f.estimated.contains(&g) && !unobservable.contains(&g);
    // The fitted value of a column in the twin's reference temperature: the bias at the
    // recording's mean temperature minus the fitted drift times the difference.
    let to_twin_ref = |e: usize, k: usize, v: f64| {
        let id = lay.effects[e].id();
        match THERMAL.iter().find(|(_, n)| *n == id) {
            Some((thermal, _)) => {
                let drift = lay
                    .index(thermal)
                    .filter(|t| terms.effects.contains(t))
                    .map(|t| lay.columns_of(t).start + k)
                    .filter(|&g| ok(g))
                    .map_or(0.0, |g| f.theta[g]);
                v - drift * dt
            }
            None if id == "lever_arm" => {
                // The accelerometers sense the lever arm's acceleration through their
                // scale factor (`K (f + M r)`): the fit's coefficient is `r (1 + s_i)`.
                let s = lay
                    .index("accel_scale")
                    .map(|e| lay.columns_of(e).start + k / 3)
                    .filter(|&g| ok(g))
                    .map_or(0.0, |g| f.theta[g]);
                v / (1.0 + s * 1e-6)
            }
            // The timing the signals were evaluated at, plus what the fit leaves.
            None => match super::TIMING.iter().position(|t| *t == id) {
                Some(k) => v + data.retime.registry()[k],
                None => v,
            },
        }
    };
    let normal = Normal::standard();
    let mut tested = Vec::new();
    for &e in &own {
        for (k, g) in lay.columns_of(e).enumerate() {
            if !ok(g) {
                continue;
            }
            let twin_u = if lay.effects[e].id() == "gyro_bias" {
                wander
            } else {
                0.0
            };
            let uc = f.u(g).hypot(twin_u);
            let z = (f.theta[g] - th_twin[g]) / uc;
            tested.push((e, k, g, z));
        }
    }
    let per_test = alpha / tested.len().max(1) as f64;
    let mut changes = Vec::new();
    for (e, k, g, z) in tested {
        let p = 2.0 * normal.sf(z.abs());
        if p.is_nan() || p >= per_test {
            continue;
        }
        let fx = lay.effects[e];
        let from = twin.values(fx.id()).and_then(|v| v.get(k)).copied();
        changes.push(Change {
            effect: fx.id().into(),
            parameter: fx.params()[k].name.into(),
            from: from.unwrap_or(0.0),
            to: to_twin_ref(e, k, f.theta[g]),
            u: f.u(g),
            unit: fx.params()[k].unit.into(),
            standard_errors: z.abs(),
            // A timing the twin lacked is compared as held, at 0 (`compare_source`).
            added: from.is_none() && super::TIMING.contains(&fx.id()),
            defined_in: None,
        });
    }
    for (e, file) in &found {
        let fx = lay.effects[*e];
        for (k, g) in lay.columns_of(*e).enumerate() {
            if !ok(g) {
                continue;
            }
            changes.push(Change {
                effect: fx.id().into(),
                parameter: fx.params()[k].name.into(),
                from: 0.0,
                to: to_twin_ref(*e, k, f.theta[g]),
                u: f.u(g),
                unit: fx.params()[k].unit.into(),
                standard_errors: (f.theta[g] / f.u(g)).abs(),
                added: true,
                defined_in: file.clone(),
            });
        }
    }
    // A discovered form is the draft effect's parameter `k_<channel>`, added (`from` 0).
    let mut th_discovered = Vec::new();
    for d in &discovered {
        let g = d.column;
        if !ok(g) {
            continue;
        }
        th_discovered.push((g, f.theta[g]));
        changes.push(Change {
            effect: d.effect.clone(),
            parameter: format!("k_{}", d.channel),
            from: 0.0,
            to: f.theta[g],
            u: f.u(g),
            unit: d.unit.clone(),
            standard_errors: (f.theta[g] / f.u(g)).abs(),
            added: true,
            defined_in: None,
        });
    }
    let updated = update::updated(twin, &changes, lay);
    let mut th_updated = theta(m, data, &updated, t_ref_data);
    for (g, v) in th_discovered {
        th_updated[g] = v;
    }
    let after = predict(m, data, &updated, &th_updated, &white);
    let series = super::series::pick(m, data, &before, &th_twin, &th_updated);
    let needs_change = !changes.is_empty() || !x.findings.is_empty() || !x.unexplained.is_empty();
    let not_determined = not_determined(lay, twin, &changes, ok);
    TwinReport {
        station: String::new(),
        before,
        after,
        changes,
        not_determined,
        needs_change,
        written: None,
        diff: None,
        series,
    }
}

/// The parameters of every effect that changes or joins the twin which this recording
/// cannot determine: they keep the twin's value (0 for an effect it lacked), said so.
fn not_determined(
    lay: &crate::fit::joint::Layout,
    twin: &Twin,
    changes: &[Change],
    ok: impl Fn(usize) -> bool,
) -> Vec<Kept> {
    let mut ids: Vec<&str> = changes.iter().map(|c| c.effect.as_str()).collect();
    ids.dedup();
    let mut out = Vec::new();
    for id in ids {
        let Some(e) = lay.index(id) else { continue };
        let fx = lay.effects[e];
        for (k, g) in lay.columns_of(e).enumerate() {
            if ok(g) {
                continue;
            }
            let p = &fx.params()[k];
            out.push(Kept {
                effect: id.into(),
                parameter: p.name.into(),
                value: (twin.values(id).and_then(|v| v.get(k)).copied()).unwrap_or(0.0),
                unit: p.unit.into(),
            });
        }
    }
    out
}
