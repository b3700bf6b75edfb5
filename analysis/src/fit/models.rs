//! The calibration models of one analysis, fitted as one least-squares from the effect
//! registry: the nominal terms the selection chose (bias and scale, misalignment of a full
//! model, thermal drift of a temperature compensation), the effects a procedure's fits or
//! `--with` declare, and the Earth's rate in the gyro references (held at the station's
//! latitude unless `earth_rate` itself is declared). Each fit an added effect touches widens
//! to every segment that excites it (a lever arm brings the rate segments into the
//! accelerometer fit). The covariance accounts for the wandering gyro bias (`joint::solve`).

use super::joint::{Layout, SegAcc, Terms, excitation, excites, fit_terms, latitude_of};
use super::select::Selection;
use super::{AXES, Out};
use crate::recording::Manifest;
use crate::results::{JointFit, Parameter, ResidualStats};
use ratecal_physics::effects::{EarthRate, Sensor};
use ratecal_physics::{Mat3, Vec3};
use std::collections::BTreeMap;

/// The sensor models the fit gives, for residuals and verification: `out = K ref + b`.
#[derive(Debug, Default)]
pub(crate) struct Models {
    pub accel: Option<(Mat3, Vec3)>,
    pub gyro: Option<(Mat3, Vec3)>,
    /// Per fit (`accel`, `gyro`): the effects, parameter keys and correlations.
    pub fits: BTreeMap<String, JointFit>,
    /// One line per sensor: which terms over how many segments.
    pub description: Vec<String>,
    /// Residuals of every segment with samples, per channel of each fitted sensor, and
    /// whether the sensor's fit used the segment.
    pub residuals: Vec<(ResidualStats, bool)>,
}

/// The effects a plan's fits and the command line declare (registry ids, deduplicated).
pub(crate) fn declared(plan: Option<&crate::plan::Plan>, with: &[String]) -> Vec<String> {
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

/// The registry terms the selection chose.
fn nominal_ids(sel: &Selection) -> Vec<&'static str> {
    let mut ids = Vec::new();
    if let Some((_, full)) = &sel.accel {
        ids.extend(["accel_bias", "accel_scale"]);
        if *full {
            ids.push("accel_misalignment");
        }
    }
    if sel.gyro_bias.is_some() || sel.gyro_scale.is_some() || sel.gyro_full.is_some() {
        ids.push("gyro_bias");
    }
    if sel.gyro_scale.is_some() || sel.gyro_full.is_some() {
        ids.push("gyro_scale");
    }
    if sel.gyro_full.is_some() {
        ids.push("gyro_misalignment");
    }
    ids
}

/// The results.json key and unit of a parameter: the nominal terms keep their names.
fn key(id: &str, param: &str, unit: &'static str, nominal: &[&str]) -> (String, &'static str) {
    let axis = param.trim_end_matches("_mrad");
    match id {
        "accel_bias" => (format!("accel.bias.{param}"), unit),
        "accel_scale" => (format!("accel.scale.{param}"), unit),
        "gyro_bias" => (format!("gyro.bias.{param}"), unit),
        "gyro_scale" => (format!("gyro.scale.{param}"), unit),
        "accel_misalignment" if nominal.contains(&id) => {
            (format!("accel.misalignment.{axis}"), unit)
        }
        "gyro_misalignment" if nominal.contains(&id) => (format!("gyro.misalignment.{axis}"), unit),
        "gyro_thermal_drift" if nominal.contains(&id) => {
            (format!("gyro.thermal_drift.{param}"), "deg/s/degC")
        }
        "accel_thermal_drift" if nominal.contains(&id) => {
            (format!("accel.thermal_drift.{param}"), "m/s^2/degC")
        }
        _ => (format!("{id}.{param}"), unit),
    }
}

/// The columns any fit of one analysis may use, fixed before the samples pass: the
/// selection's nominal terms, thermal drift when a temperature compensation is asked (left
/// out of the fit again if the temperature did not vary), the declared effects, and the
/// Earth's rate.
#[derive(Debug)]
pub(crate) struct Design {
    /// Every column.
    pub layout: Layout,
    nominal: Vec<&'static str>,
    added: Vec<&'static str>,
    earth_fitted: bool,
}

impl Design {
    /// The design of a selection with these declared effects; `thermal`: whether the
    /// thermal terms may enter (asked for, and the IMU reports its temperature).
    pub(crate) fn new(sel: &Selection, declared: &[String], thermal: bool, out: &mut Out) -> Self {
        let mut nominal = nominal_ids(sel);
        if thermal {
            nominal.extend(["accel_thermal_drift", "gyro_thermal_drift"]);
        }
        let mut added: Vec<&'static str> = Vec::new();
        let mut unknown = Vec::new();
        for id in declared {
            match ratecal_physics::effect(id) {
                Some(e) if !e.nominal() => {
                    if !nominal.contains(&e.id()) && !added.contains(&e.id()) {
                        added.push(e.id());
                    }
                }
                _ => unknown.push(id.clone()),
            }
        }
        if !unknown.is_empty() {
            out.warnings.push(format!(
                "unknown effects ignored: {} (the catalogue: {})",
                unknown.join(", "),
                ratecal_physics::effects::catalogue()
                    .map(|e| e.id())
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
        }
        let mut ids: Vec<&'static str> = nominal.iter().chain(&added).copied().collect();
        let earth_fitted = ids.contains(&"earth_rate");
        if !earth_fitted {
            ids.push("earth_rate");
        }
        let layout = Layout::new(
            ids.iter()
                .map(|id| ratecal_physics::effect(id).expect("a registry id"))
                .collect(),
        );
        Design {
            layout,
            nominal,
            added,
            earth_fitted,
        }
    }
}

/// Fits the models from the segments' accumulations (`accs`, those with samples) and
/// writes their parameters into `out`; `temperature`: whether the thermal terms the design
/// holds are fitted.
pub(crate) fn fit(
    m: &Manifest,
    sel: &Selection,
    design: &Design,
    accs: &[SegAcc],
    temperature: bool,
    out: &mut Out,
) -> Models {
    let layout = &design.layout;
    let thermal = ["accel_thermal_drift", "gyro_thermal_drift"];
    let nominal: Vec<&'static str> = design
        .nominal
        .iter()
        .copied()
        .filter(|id| temperature || !thermal.contains(id))
        .collect();
    let added = &design.added;
    let earth_fitted = design.earth_fitted;
    let e_of = |id: &str| layout.index(id).expect("in the layout");
    let mut terms = Terms::default();
    for id in nominal.iter().chain(added) {
        terms.effects.push(e_of(id));
    }
    if !earth_fitted {
        let lat = m.station.site.latitude_deg;
        terms
            .fixed
            .push((e_of("earth_rate"), EarthRate::values(lat).to_vec()));
    }
    // A gyro scale fit that names some axes leaves the others' columns out.
    if let (Some((_, axes)), None) = (&sel.gyro_scale, &sel.gyro_full) {
        let first = layout.columns_of(e_of("gyro_scale")).start;
        terms
            .skip
            .extend((0..3).filter(|a| !axes.contains(a)).map(|a| first + a));
    }

    // The segments the fits use; every segment is accumulated (an added effect widens a
    // fit to those exciting it, and residuals are reported on all of them).
    let accel_segs: Vec<usize> = sel.accel.iter().flat_map(|(ix, _)| ix.clone()).collect();
    let gyro_segs: Vec<usize> = sel
        .gyro_bias
        .iter()
        .copied()
        .chain(sel.gyro_scale.iter().flat_map(|(ix, _)| ix.iter().copied()))
        .chain(sel.gyro_full.iter().flat_map(|ix| ix.iter().copied()))
        .collect();
    let ex: Vec<Vec<f64>> = accs.iter().map(|a| excitation(layout, a)).collect();
    let acc_of = |seg: usize| accs.iter().position(|a| a.seg == seg);
    let mut accel: Vec<usize> = accel_segs.iter().filter_map(|&s| acc_of(s)).collect();
    let mut gyro: Vec<usize> = gyro_segs.iter().filter_map(|&s| acc_of(s)).collect();
    for id in added {
        let e = e_of(id);
        for i in 0..accs.len() {
            if !excites(layout, &ex, e, i) {
                continue;
            }
            for (s, set) in [(Sensor::Accel, &mut accel), (Sensor::Gyro, &mut gyro)] {
                if layout.effects[e].sensors().contains(&s) && !set.contains(&i) {
                    set.push(i);
                }
            }
        }
    }
    accel.sort_unstable();
    accel.dedup();
    gyro.sort_unstable();
    gyro.dedup();
    if accel.is_empty() && gyro.is_empty() {
        return Models::default();
    }
    let (f, unobservable) = fit_terms(layout, accs, &ex, &terms, &accel, &gyro);

    // Parameters, under their keys, and the sensor models.
    let mut models = Models::default();
    let mut k = [Mat3::identity(), Mat3::identity()];
    let mut b = [Vec3::zeros(), Vec3::zeros()];
    let mut order: [Vec<(String, usize)>; 2] = Default::default();
    for &e in &terms.effects {
        let fx = layout.effects[e];
        for g in layout.columns_of(e) {
            let prm = layout.param(g);
            let (name, unit) = key(fx.id(), prm.name, prm.unit, &nominal);
            if terms.skip.contains(&g) {
                out.unobservable(&name, "the procedure's gyro scale fit leaves this axis out");
                continue;
            }
            if unobservable.contains(&g) || !f.estimated.contains(&g) {
                out.params.insert(name.clone(), Parameter::needs(prm.needs));
                out.observability
                    .insert(name, format!("needs: {}", prm.needs));
                continue;
            }
            let (v, u) = (f.theta[g], f.u(g));
            out.params
                .insert(name.clone(), Parameter::estimate(v, u, unit));
            for (si, s) in [Sensor::Accel, Sensor::Gyro].into_iter().enumerate() {
                if fx.sensors().contains(&s) {
                    order[si].push((name.clone(), g));
                }
            }
            let col = layout.cols[g].param;
            let si = usize::from(fx.sensors() == [Sensor::Gyro]);
            match fx.id() {
                "accel_bias" | "gyro_bias" => b[si][col] = v,
                "accel_scale" | "gyro_scale" => k[si][(col, col)] += v * 1e-6,
                "accel_misalignment" | "gyro_misalignment" => {
                    let (i, j) = misalignment_index(prm.name);
                    k[si][(i, j)] = v * 1e-3;
                }
                _ => {}
            }
        }
        if let Some((lat, ul)) = latitude_of(layout, &f, e) {
            out.params.insert(
                "earth_rate.latitude_deg".into(),
                Parameter::estimate(lat, ul, "deg"),
            );
        }
    }
    let names = terms.names(layout);
    for (si, (sensor, segs)) in [("accel", &accel), ("gyro", &gyro)].into_iter().enumerate() {
        if segs.is_empty() || order[si].is_empty() {
            continue;
        }
        let s = [Sensor::Accel, Sensor::Gyro][si];
        let effects: Vec<String> = names
            .iter()
            .filter(|n| {
                let id = n.trim_end_matches(" (fixed)");
                ratecal_physics::effect(id).is_some_and(|e| e.sensors().contains(&s))
            })
            .cloned()
            .collect();
        models.description.push(format!(
            "{sensor}: {} over {} segments",
            effects.join(", "),
            segs.len()
        ));
        let ord = &order[si];
        models.fits.insert(
            sensor.into(),
            JointFit {
                effects,
                parameters: ord.iter().map(|(n, _)| n.clone()).collect(),
                correlation: ord
                    .iter()
                    .map(|&(_, a)| ord.iter().map(|&(_, c)| f.corr(a, c)).collect())
                    .collect(),
            },
        );
    }
    for (si, set) in [&accel, &gyro].into_iter().enumerate() {
        if set.is_empty() {
            continue;
        }
        for (i, a) in accs.iter().enumerate() {
            let id = &m.segments[a.seg].id;
            for c in 3 * si..3 * si + 3 {
                let r = super::residuals::of_segment(a, layout, c, &f.theta, id);
                models.residuals.push((r, set.contains(&i)));
            }
        }
    }
    if sel.accel.is_some() {
        models.accel = Some((k[0], b[0]));
    }
    if !gyro_segs.is_empty() {
        models.gyro = Some((k[1], b[1]));
    }
    models
}

/// Row and column of a misalignment parameter `<i><j>_mrad`.
fn misalignment_index(name: &str) -> (usize, usize) {
    let ix = |c: u8| AXES.iter().position(|a| a.as_bytes()[0] == c).unwrap_or(0);
    let b = name.as_bytes();
    (ix(b[0]), ix(b[1]))
}
