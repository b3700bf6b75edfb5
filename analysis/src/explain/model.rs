//! Models explain fits: a set of registry effects, some held at known values, over a set
//! of segments per sensor.

use super::data::Data;
pub(crate) use crate::fit::joint::Terms;
use crate::fit::joint::{Fit, WanderRule, fit_terms_merged, rss_on, seg_rss};
use crate::plan::Plan;
use crate::recording::{Manifest, SegmentKind};
use ratecal_physics::effects::EarthRate;

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

/// Fits terms over segments (indices into `data.accs`) for each sensor (see
/// [`crate::fit::joint::fit_terms`]).
pub(crate) fn fit(
    data: &Data,
    terms: &Terms,
    accel: &[usize],
    gyro: &[usize],
) -> (Fit, Vec<usize>) {
    fit_with(data, terms, accel, gyro, WanderRule::Estimated)
}

/// [`fit`] with the wandering bias taken as `wander` says (white noise only ranks many
/// models cheaply).
pub(crate) fn fit_with(
    data: &Data,
    terms: &Terms,
    accel: &[usize],
    gyro: &[usize],
    wander: WanderRule,
) -> (Fit, Vec<usize>) {
    let merged = data.merged(accel, gyro);
    let (mut f, unobs) = fit_terms_merged(
        &data.layout,
        &data.accs,
        &data.excitation,
        terms,
        accel,
        gyro,
        Some(merged.as_ref()),
        wander,
    );
    tilt_as_nuisance(data, &mut f);
    (f, unobs)
}

/// On faces placed by hand (`attitude: nominal`), a placement tilt is never physics: each
/// face's tilt is a nuisance within its tolerance, which a misalignment cannot be told
/// apart from. Its variance (two faces' tilts, each of standard deviation `tilt_rad`
/// across the face, halved) joins each accelerometer misalignment's, so that neither its
/// test nor its u credits the IMU with what the hand did.
fn tilt_as_nuisance(data: &Data, f: &mut Fit) {
    if data.tilt_rad <= 0.0 {
        return;
    }
    let var = (1e3 * data.tilt_rad).powi(2) / 2.0;
    for (e, fx) in data.layout.effects.iter().enumerate() {
        if fx.id() != "accel_misalignment" {
            continue;
        }
        for g in data.layout.columns_of(e) {
            if f.estimated.contains(&g) && data.layout.param(g).unit == "mrad" {
                f.cov[(g, g)] += var;
            }
        }
    }
}

/// Misfit of channel `c` over `segs` under `fit`: its residual sum of squares in units of
/// the white noise `sigma`.
pub(crate) fn misfit(data: &Data, fit: &Fit, c: usize, segs: &[usize], sigma: f64) -> f64 {
    let sigma = sigma.max(1e-300);
    segs.iter()
        .map(|&i| seg_rss(&data.accs[i], &data.layout, c, &fit.theta))
        .sum::<f64>()
        / (sigma * sigma)
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
pub(crate) fn seed_segments(m: &Manifest, data: &Data) -> (Vec<usize>, Vec<usize>) {
    let kind = |i: usize| m.segments[data.accs[i].seg].kind;
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
