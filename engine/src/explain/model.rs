//! Models explain fits: a set of registry effects, some held at known values, over a set
//! of segments per sensor.

use super::data::Data;
use crate::fit::joint::{Fit, FitRequest, rss_on, solve};
use crate::plan::Plan;
use crate::recording::{Recording, SegmentKind};
use ratecal_physics::effects::{EarthRate, Sensor};

/// The model a recording is compared with before anything is added.
#[derive(Debug, Clone)]
pub struct NominalModel {
    /// `seed`, or the procedure's `name version`.
    pub name: String,
    /// Registry ids of the fitted terms.
    pub effects: Vec<&'static str>,
    /// Registry ids held at known values (the Earth's rate at the station's latitude).
    pub fixed: Vec<(&'static str, Vec<f64>)>,
}

impl NominalModel {
    /// The standard's own seed model: per-axis bias and scale, no Earth rate.
    pub fn seed() -> Self {
        NominalModel {
            name: "seed".into(),
            effects: vec!["accel_bias", "accel_scale", "gyro_bias", "gyro_scale"],
            fixed: Vec::new(),
        }
    }

    /// A procedure's fits, with the effects they declare; the Earth's rate is in their
    /// references (held at the recording's latitude).
    pub fn from_plan(plan: &Plan, latitude_deg: f64) -> Self {
        use crate::plan::FitModel as M;
        let mut effects: Vec<&'static str> = Vec::new();
        let mut add = |ids: &[&'static str]| {
            for id in ids {
                if !effects.contains(id) {
                    effects.push(id);
                }
            }
        };
        for f in &plan.fits {
            match f.model {
                M::AccelBiasScale => add(&["accel_bias", "accel_scale"]),
                M::AccelFull => add(&["accel_bias", "accel_scale", "accel_misalignment"]),
                M::GyroBias => add(&["gyro_bias"]),
                M::GyroScale => add(&["gyro_bias", "gyro_scale"]),
                M::GyroFull => add(&["gyro_bias", "gyro_scale", "gyro_misalignment"]),
                M::TempCompensation => add(&["gyro_thermal_drift", "accel_thermal_drift"]),
                M::Allan | M::SizeEffect => {}
            }
            for id in &f.effects {
                if let Some(e) = ratecal_physics::effect(id) {
                    add(&[e.id()]);
                }
            }
        }
        if effects.is_empty() {
            return Self::seed();
        }
        let fixed = if effects.contains(&"earth_rate") {
            Vec::new()
        } else {
            vec![("earth_rate", EarthRate::values(latitude_deg).to_vec())]
        };
        NominalModel {
            name: format!("{} {}", plan.name, plan.version),
            effects,
            fixed,
        }
    }
}

/// Effects (layout indices) and fixed values of a model under test.
#[derive(Debug, Clone, Default)]
pub(crate) struct Terms {
    /// Fitted effects.
    pub effects: Vec<usize>,
    /// Effects held at values.
    pub fixed: Vec<(usize, Vec<f64>)>,
}

impl Terms {
    /// The ids, fitted then fixed (`earth_rate (fixed)`).
    pub(crate) fn names(&self, data: &Data) -> Vec<String> {
        let l = &data.layout;
        self.effects
            .iter()
            .map(|&e| l.effects[e].id().to_string())
            .chain(
                self.fixed
                    .iter()
                    .map(|(e, _)| format!("{} (fixed)", l.effects[*e].id())),
            )
            .collect()
    }
}

/// Fits terms over segments (indices into `data.accs`) for each sensor. Columns of an
/// effect that these segments barely excite (below a thousandth of the effect's most
/// excited column) are left out as unobservable.
pub(crate) fn fit(
    data: &Data,
    terms: &Terms,
    accel: &[usize],
    gyro: &[usize],
) -> (Fit, Vec<usize>) {
    let lay = &data.layout;
    let mut cols = Vec::new();
    let mut weak = Vec::new();
    for &e in &terms.effects {
        let range = lay.columns_of(e);
        let ex: Vec<f64> = range
            .clone()
            .map(|g| {
                let sensors = lay.effects[e].sensors();
                let mut m = 0.0f64;
                for (s, segs) in [(Sensor::Accel, accel), (Sensor::Gyro, gyro)] {
                    if sensors.contains(&s) {
                        for &i in segs {
                            m = m.max(data.excitation[i][g]);
                        }
                    }
                }
                m
            })
            .collect();
        let top = ex.iter().copied().fold(0.0, f64::max);
        for (k, g) in range.enumerate() {
            if ex[k] > 1e-3 * top && top > 0.0 {
                cols.push(g);
            } else {
                weak.push(g);
            }
        }
    }
    let mut fixed = Vec::new();
    for (e, v) in &terms.fixed {
        for (k, g) in lay.columns_of(*e).enumerate() {
            fixed.push((g, v[k]));
        }
    }
    let req = FitRequest {
        layout: lay,
        cols,
        fixed,
        accel: accel.iter().map(|&i| &data.accs[i]).collect(),
        gyro: gyro.iter().map(|&i| &data.accs[i]).collect(),
    };
    let f = solve(&req);
    let mut unobs = f.unobservable.clone();
    unobs.extend(weak);
    unobs.sort_unstable();
    (f, unobs)
}

/// Residual RMS per sensor of a fit over segments.
pub(crate) fn rms(data: &Data, fit: &Fit, segs: &[usize]) -> super::Rms {
    let accs: Vec<_> = segs.iter().map(|&i| &data.accs[i]).collect();
    let sensor = |cs: std::ops::Range<usize>| {
        let (mut s, mut n) = (0.0, 0usize);
        for c in cs {
            let (a, b) = rss_on(fit, &data.layout, &accs, c);
            s += a;
            n += b;
        }
        if n == 0 { 0.0 } else { (s / n as f64).sqrt() }
    };
    super::Rms {
        accel_mps2: sensor(0..3),
        gyro_dps: sensor(3..6),
    }
}

/// The seed model's segments: static ones for the accelerometers; the longest static one
/// and the rate segments for the gyros.
pub(crate) fn seed_segments(rec: &Recording, data: &Data) -> (Vec<usize>, Vec<usize>) {
    let kind = |i: usize| rec.manifest.segments[data.accs[i].seg].kind;
    let all = 0..data.accs.len();
    let accel: Vec<usize> = all
        .clone()
        .filter(|&i| kind(i) == SegmentKind::Static)
        .collect();
    let longest = accel.iter().copied().max_by_key(|&i| data.accs[i].n);
    let gyro: Vec<usize> = all
        .filter(|&i| kind(i) == SegmentKind::Rate || Some(i) == longest)
        .collect();
    (accel, gyro)
}

/// The latitude (deg, with its u) that a fit's Earth-rate components give, when the layout
/// effect `e` is `earth_rate` and both components were estimated.
pub(crate) fn latitude(data: &Data, fit: &Fit, e: usize) -> Option<(f64, f64)> {
    if data.layout.effects[e].id() != "earth_rate" {
        return None;
    }
    let r = data.layout.columns_of(e);
    let (n, u) = (r.start, r.start + 1);
    if !(fit.estimated.contains(&n) && fit.estimated.contains(&u)) {
        return None;
    }
    let c = &fit.cov;
    Some(EarthRate::latitude_deg(
        fit.theta[n],
        fit.theta[u],
        [[c[(n, n)], c[(n, u)]], [c[(u, n)], c[(u, u)]]],
    ))
}
