//! Effects declared for an analysis (`ratecal analyze --with lever_arm`, or a procedure's
//! `fit ... with lever_arm`): the nominal model the selection chose plus those effects,
//! fitted as one least-squares from the effect registry. Each fit an effect touches widens
//! to every segment that excites it (a lever arm brings the rate segments into the
//! accelerometer fit); the nominal estimates of the sensors it touches are replaced by the
//! joint ones, and results.json gains the effects' parameters and the fit's correlations.

use super::select::Selection;
use crate::explain::data::Data;
use crate::explain::model::{Terms, fit, latitude};
use crate::plan::Plan;
use crate::recording::Recording;
use crate::results::{JointFit, Parameter, Results};
use ratecal_physics::effects::{EarthRate, Sensor};

/// The effects a plan's fits and the command line declare (registry ids, deduplicated).
pub(crate) fn declared(plan: Option<&Plan>, with: &[String]) -> Vec<String> {
    let mut v: Vec<String> = Vec::new();
    let from_plan = plan
        .into_iter()
        .flat_map(|p| p.fits.iter().flat_map(|f| f.effects.iter()));
    for id in from_plan.chain(with) {
        if !v.contains(id) {
            v.push(id.clone());
        }
    }
    v
}

/// The results.json key of a column: the nominal terms under their existing names.
fn key(id: &str, param: &str) -> String {
    match id {
        "accel_bias" => format!("accel.bias.{param}"),
        "accel_scale" => format!("accel.scale.{param}"),
        "gyro_bias" => format!("gyro.bias.{param}"),
        "gyro_scale" => format!("gyro.scale.{param}"),
        _ => format!("{id}.{param}"),
    }
}

/// Runs the joint fit and writes it into `res`.
pub(crate) fn apply(rec: &Recording, sel: &Selection, effects: &[String], res: &mut Results) {
    let data = Data::new(rec);
    let lay = &data.layout;
    let index = |id: &str| lay.index(id);
    let mut unknown = Vec::new();
    let mut added = Vec::new();
    for id in effects {
        match index(id) {
            Some(e) if !lay.effects[e].nominal() => added.push(e),
            _ => unknown.push(id.clone()),
        }
    }
    if !unknown.is_empty() {
        res.warnings.push(format!(
            "unknown effects ignored: {} (the catalogue: {})",
            unknown.join(", "),
            ratecal_physics::effects::catalogue()
                .map(|e| e.id())
                .collect::<Vec<_>>()
                .join(", ")
        ));
    }
    if added.is_empty() {
        return;
    }
    // The nominal terms the selection chose.
    let mut nominal: Vec<&str> = Vec::new();
    if let Some((_, full)) = &sel.accel {
        nominal.extend(["accel_bias", "accel_scale"]);
        if *full {
            nominal.push("accel_misalignment");
        }
    }
    if sel.gyro_scale.is_some() || sel.gyro_full.is_some() || sel.gyro_bias.is_some() {
        nominal.push("gyro_bias");
    }
    if sel.gyro_scale.is_some() || sel.gyro_full.is_some() {
        nominal.push("gyro_scale");
    }
    if sel.gyro_full.is_some() {
        nominal.push("gyro_misalignment");
    }
    let mut terms = Terms::default();
    for id in &nominal {
        if let Some(e) = index(id) {
            terms.effects.push(e);
        }
    }
    for &e in &added {
        if !terms.effects.contains(&e) {
            terms.effects.push(e);
        }
    }
    let earth = index("earth_rate").expect("registry");
    if !terms.effects.contains(&earth) {
        let lat = rec.manifest.station.site.latitude_deg;
        terms.fixed.push((earth, EarthRate::values(lat).to_vec()));
    }
    // Segments: the selection's, widened to those exciting each added effect.
    let acc_of = |seg: usize| data.accs.iter().position(|a| a.seg == seg);
    let mut accel: Vec<usize> = sel
        .accel
        .iter()
        .flat_map(|(ix, _)| ix.iter())
        .filter_map(|&s| acc_of(s))
        .collect();
    let mut gyro: Vec<usize> = sel
        .gyro_bias
        .iter()
        .copied()
        .chain(sel.gyro_scale.iter().flat_map(|(ix, _)| ix.iter().copied()))
        .chain(sel.gyro_full.iter().flat_map(|ix| ix.iter().copied()))
        .filter_map(acc_of)
        .collect();
    for &e in &added {
        let cols: Vec<usize> = lay.columns_of(e).collect();
        let top = (0..data.accs.len())
            .flat_map(|i| cols.iter().map(move |&g| (i, g)))
            .map(|(i, g)| data.excitation[i][g])
            .fold(0.0, f64::max);
        for i in 0..data.accs.len() {
            let ex = cols
                .iter()
                .map(|&g| data.excitation[i][g])
                .fold(0.0, f64::max);
            if top > 0.0 && ex > 1e-3 * top {
                for (s, set) in [(Sensor::Accel, &mut accel), (Sensor::Gyro, &mut gyro)] {
                    if lay.effects[e].sensors().contains(&s) && !set.contains(&i) {
                        set.push(i);
                    }
                }
            }
        }
    }
    accel.sort_unstable();
    gyro.sort_unstable();
    let (f, unobservable) = fit(&data, &terms, &accel, &gyro);
    let mut keys = Vec::new();
    let mut order = Vec::new();
    for &e in &terms.effects {
        let fx = lay.effects[e];
        // Only the sensors an added effect touches take the joint estimates.
        let touched = fx
            .sensors()
            .iter()
            .any(|s| added.iter().any(|&a| lay.effects[a].sensors().contains(s)));
        if fx.nominal() && !touched {
            continue;
        }
        for g in lay.columns_of(e) {
            let prm = lay.param(g);
            let mut k = key(fx.id(), prm.name);
            if fx.id().ends_with("_misalignment") && nominal.contains(&fx.id()) {
                // A full model's misalignment keeps its name: gyro.misalignment.xy.
                let s = if fx.id().starts_with("accel") {
                    "accel"
                } else {
                    "gyro"
                };
                k = format!("{s}.misalignment.{}", prm.name.trim_end_matches("_mrad"));
            }
            let value = if unobservable.contains(&g) || !f.estimated.contains(&g) {
                Parameter::needs(prm.needs)
            } else {
                let (v, u) = (f.theta[g], f.u(g));
                keys.push(k.clone());
                order.push(g);
                Parameter::estimate(v, u, prm.unit)
            };
            res.parameters.insert(k, value);
        }
        if let Some((lat, ul)) = latitude(&data, &f, e) {
            res.parameters.insert(
                "earth_rate.latitude_deg".into(),
                Parameter::estimate(lat, ul, "deg"),
            );
        }
    }
    let correlation = order
        .iter()
        .map(|&a| order.iter().map(|&b| f.corr(a, b)).collect())
        .collect();
    let ids: Vec<String> = terms.names(&data);
    res.model.fits.push(format!(
        "joint: {} over {} accelerometer and {} gyro segments",
        ids.join(", "),
        accel.len(),
        gyro.len()
    ));
    res.fits.insert(
        "joint".into(),
        JointFit {
            effects: ids,
            parameters: keys,
            correlation,
        },
    );
}
