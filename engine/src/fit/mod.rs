//! The analysis stage: a recording (and optionally the checked procedure) in, results out.
//!
//! Segments are chosen by the procedure's fit statements, or without one by kind
//! (spec/recording-format.md). Each segment is preprocessed on its own (sync, references
//! from the table feedback through `ratecal_physics`, outliers, low-pass), then the models
//! are fitted, residuals analysed and the procedure's thresholds evaluated.

// Numeric loops index several parallel channel arrays at once; iterators would hide that.
#![allow(clippy::needless_range_loop)]

mod accept;
mod allan;
mod gyro;
pub(crate) mod joint;
mod models;
pub(crate) mod prep;
mod repeat;
mod residuals;
mod select;
pub mod size_effect;
mod stats;

pub use allan::overlapping_adev;
pub use repeat::analyze_runs;

use crate::plan::{Outliers, Plan};
use crate::recording::Recording;
use crate::results::{self, Parameter, ResidualStats, Results, SyncReport};
use prep::SegData;
use ratecal_physics::{Mat3, Vec3};
use std::collections::BTreeMap;

pub(crate) const AXES: [&str; 3] = ["x", "y", "z"];

/// Analysis options that the procedure does not fix.
#[derive(Debug, Clone)]
pub struct Options {
    /// Outlier rule when a fit statement names none (the seed's 3-sigma).
    pub outliers: Option<Outliers>,
    /// Low-pass when a fit statement names none: (order, cutoff Hz).
    pub lowpass: Option<(u32, f64)>,
    /// How the recording is named in the results (its folder).
    pub path: String,
    /// Catalogue effects added to whatever model applies (`--with`).
    pub with: Vec<String>,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            outliers: Some(Outliers::Sigma(3.0)),
            lowpass: None,
            path: String::new(),
            with: Vec::new(),
        }
    }
}

/// What the fits produce before it is assembled into `Results`.
#[derive(Debug, Default)]
pub(crate) struct Out {
    pub params: BTreeMap<String, Parameter>,
    pub observability: BTreeMap<String, String>,
    pub residuals: Vec<ResidualStats>,
    pub warnings: Vec<String>,
    /// Derived quantities for acceptance: (value, standard uncertainty), internal units.
    pub quantities: BTreeMap<String, (f64, f64)>,
    pub accel_model: Option<(Mat3, Vec3)>,
    pub gyro_model: Option<(Mat3, Vec3)>,
    pub size_effect: Option<results::SizeEffectDrifts>,
}

impl Out {
    pub(crate) fn unobservable(&mut self, name: &str, why: &str) {
        self.params
            .insert(name.to_string(), Parameter::unobservable());
        self.observability.insert(name.to_string(), why.to_string());
    }
}

/// Analyses one recording with default options.
pub fn analyze(rec: &Recording, plan: Option<&Plan>) -> Results {
    analyze_with(rec, plan, &Options::default())
}

/// Analyses one recording.
pub fn analyze_with(rec: &Recording, plan: Option<&Plan>, opts: &Options) -> Results {
    let sel = select::select(rec, plan, opts);
    let geos = prep::geometries(rec);
    let mut out = Out {
        warnings: sel.warnings.clone(),
        ..Default::default()
    };
    let mut sync = SyncReport {
        method: "linear_interpolation".into(),
        table_step_s: stats::median_step(&rec.table.t),
        ..Default::default()
    };
    // Segments are independent: prepared in parallel, longest first so that the work
    // stealing balances; a long segment splits its own work too.
    let dur = |i: usize| rec.manifest.segments[i].t_end - rec.manifest.segments[i].t_start;
    let mut order = sel.prep.clone();
    order.sort_by(|a, b| dur(b.0).total_cmp(&dur(a.0)));
    let done: Vec<(usize, SegData, SyncReport, Vec<String>)> = {
        use rayon::prelude::*;
        order
            .par_iter()
            .map(|&(i, po)| {
                let mut sync = SyncReport::default();
                let mut warnings = Vec::new();
                let seg = &rec.manifest.segments[i];
                let d = prep::prepare(rec, seg, &geos[i], po, &mut sync, &mut warnings);
                (i, d, sync, warnings)
            })
            .collect()
    };
    let mut data: BTreeMap<usize, SegData> = BTreeMap::new();
    for (i, d, sy, w) in done {
        data.insert(i, d);
        sync.max_gap_s = sync.max_gap_s.max(sy.max_gap_s);
        sync.max_sync_error_s = sync.max_sync_error_s.max(sy.max_sync_error_s);
        sync.max_angle_error_deg = sync.max_angle_error_deg.max(sy.max_angle_error_deg);
        out.warnings.extend(w);
    }

    // The Allan curves (the costly part of the noise analysis) run beside the fits.
    let allan_block = sel.allan.and_then(|i| data.get(&i));
    let declared = models::declared(plan, &opts.with);
    let temperature = sel.temp_requested && temperature_varies(rec, &sel.temp_segments);
    let (curves, fitted) = rayon::join(
        || allan_block.map(allan::curves),
        || models::fit(rec, &sel, &data, &declared, temperature, &mut out),
    );
    if sel.temp_requested && !temperature {
        for s in ["accel", "gyro"] {
            for ax in AXES {
                out.unobservable(
                    &format!("{s}.thermal_drift.{ax}"),
                    "the IMU temperature did not vary by 1 degC across the static data",
                );
            }
        }
    }
    out.accel_model = fitted.accel;
    out.gyro_model = fitted.gyro;
    for sensor in ["accel", "gyro"] {
        let fitted_of = fitted
            .residuals
            .iter()
            .filter(|(r, f)| *f && r.sensor == sensor);
        if fitted_of.clone().next().is_some() {
            let worst = residuals::pooled_worst(fitted_of.map(|(r, _)| r));
            out.quantities
                .insert(format!("{sensor}.residual.std"), worst);
        }
    }
    residual_means(&fitted.residuals, &mut out);
    if let (Some((k, b)), Some(block)) = (out.gyro_model, sel.gyro_bias.and_then(|i| data.get(&i)))
    {
        gyro::block_noise(block, &k, &b, &mut out);
    }
    if let Some(ix) = &sel.size_effect {
        size_effect::fit(rec, ix, &mut out);
    }
    let allan = allan_block
        .zip(curves.as_ref())
        .and_then(|(b, c)| allan::analyse(b, c, &mut out));
    // results.json always lists bias and scale of both sensors on every axis.
    for s in ["accel", "gyro"] {
        for what in ["bias", "scale"] {
            for ax in AXES {
                let name = format!("{s}.{what}.{ax}");
                if !out.params.contains_key(&name) {
                    out.unobservable(&name, "no fit of this recording's plan determines it");
                }
            }
        }
    }
    out.residuals = fitted.residuals.iter().map(|(r, _)| r.clone()).collect();
    unfitted_residual_warnings(&fitted.residuals, &mut out);
    let (verification, wh) = accept::verify(&sel, &data, &out, rec);
    let segments = sel.uses(rec, &data);
    let mut res = Results {
        format: results::FORMAT.into(),
        verdict: results::RunVerdict::default(),
        parameters: std::mem::take(&mut out.params),
        acceptance: Vec::new(),
        observability: std::mem::take(&mut out.observability),
        recording: select::recording_info(rec, &opts.path),
        model: sel.model.clone(),
        segments,
        sync,
        residuals: std::mem::take(&mut out.residuals),
        allan,
        verification,
        repeatability: None,
        environment: select::environment(rec),
        warnings: Vec::new(),
        fits: Default::default(),
        size_effect: out.size_effect.take(),
    };
    res.fits = fitted.fits;
    res.model
        .fits
        .extend(fitted.description.iter().map(|d| format!("joint {d}")));
    res.acceptance = accept::evaluate(plan, &res, &out.quantities, &wh, &mut out.warnings);
    let mut w = std::mem::take(&mut out.warnings);
    w.append(&mut res.warnings);
    res.warnings = w;
    res.decide(results::ended_early(&rec.manifest));
    res
}

/// Residuals on the segments a sensor's fit did not use (the accelerometers on the rate
/// and oscillation segments of the seed model): a mean residual far beyond the fit's noise
/// is a warning that the model leaves physics out.
fn unfitted_residual_warnings(rs: &[(ResidualStats, bool)], out: &mut Out) {
    for (sensor, physics) in [
        (
            "accel",
            "motion-dependent physics (a lever arm, a time offset)",
        ),
        (
            "gyro",
            "attitude-dependent physics (g-sensitivity, a misalignment)",
        ),
    ] {
        let noise = out
            .quantities
            .get(&format!("{sensor}.residual.std"))
            .map_or(0.0, |q| q.0);
        let worst = rs
            .iter()
            .filter(|(r, fitted)| !*fitted && r.sensor == sensor && r.n > 1)
            .map(|(r, _)| r)
            .max_by(|a, b| a.mean.abs().total_cmp(&b.mean.abs()));
        if let Some(r) = worst
            && noise > 0.0
            && r.mean.abs() > 5.0 * noise
        {
            out.warnings.push(format!(
                "{sensor} {} residual on segment {}, which the {sensor} fit does not use: mean {:.4} {}, {:.0} times the fit's noise: the model leaves out {physics}; see `ratecal explain`",
                r.channel,
                r.segment,
                r.mean,
                r.unit,
                r.mean.abs() / noise
            ));
        }
    }
}

/// Whether the IMU temperature varied by at least 1 degC across these segments: a thermal
/// coefficient needs a temperature span to be determined.
fn temperature_varies(rec: &Recording, segs: &[usize]) -> bool {
    let Some(temp) = &rec.imu.temp else {
        return false;
    };
    let (mut lo, mut hi) = (f64::MAX, f64::MIN);
    for &i in segs {
        let s = &rec.manifest.segments[i];
        let a = rec.imu.t.partition_point(|&t| t < s.t_start);
        let b = rec.imu.t.partition_point(|&t| t <= s.t_end);
        for &v in temp[a..b].iter().filter(|v| v.is_finite()) {
            lo = lo.min(v);
            hi = hi.max(v);
        }
    }
    hi - lo >= 1.0
}

/// The largest mean residual of each sensor's fitted segments (`accel.residual.mean`,
/// `gyro.residual.mean`), with the standard uncertainty of that mean from its samples.
fn residual_means(rs: &[(ResidualStats, bool)], out: &mut Out) {
    for sensor in ["accel", "gyro"] {
        let worst = rs
            .iter()
            .filter(|(r, fitted)| *fitted && r.sensor == sensor && r.n > 1)
            .map(|(r, _)| r)
            .max_by(|a, b| a.mean.abs().total_cmp(&b.mean.abs()));
        if let Some(r) = worst {
            let u = r.std / (r.n as f64).sqrt();
            out.quantities
                .insert(format!("{sensor}.residual.mean"), (r.mean.abs(), u));
        }
    }
}
