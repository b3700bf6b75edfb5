//! The analysis stage: a recording (and optionally the checked procedure) in, results out.
//!
//! Segments are chosen by the procedure's fit statements, or without one by kind
//! (spec/recording-format.md). Each segment is preprocessed on its own (sync, references
//! from the table feedback through `ratecal_physics`, outliers, low-pass), then the models
//! are fitted, residuals analysed and the procedure's thresholds evaluated.

// Numeric loops index several parallel channel arrays at once; iterators would hide that.
#![allow(clippy::needless_range_loop)]

mod accel;
mod accept;
mod allan;
mod effects;
mod gyro;
pub(crate) mod joint;
mod lsq;
pub(crate) mod prep;
mod repeat;
mod select;
pub mod size_effect;
mod stats;
mod temp;

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

pub(crate) fn residual_stats(
    s: &SegData,
    sensor: &str,
    ax: usize,
    r: &[f64],
    keep: &[bool],
    unit: &str,
) -> ResidualStats {
    let (mean, std, slope) = stats::mean_std_slope(s.t, r, keep);
    ResidualStats {
        segment: s.id.clone(),
        sensor: sensor.into(),
        channel: AXES[ax].into(),
        n: keep.iter().filter(|k| **k).count(),
        mean,
        std,
        slope_per_s: slope,
        unit: unit.into(),
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
    let get = |ix: &[usize]| ix.iter().filter_map(|i| data.get(i)).collect::<Vec<_>>();

    // The Allan curves (the costly part of the noise analysis) run beside the fits.
    let allan_block = sel.allan.and_then(|i| data.get(&i));
    let (curves, ()) = rayon::join(
        || allan_block.map(allan::curves),
        || {
            if let Some((ix, full)) = &sel.accel {
                let segs = get(ix);
                if *full {
                    accel::fit_full(&segs, &mut out)
                } else {
                    accel::fit_seed(&segs, &mut out)
                }
            }
            let block = sel.gyro_bias.and_then(|i| data.get(&i));
            if let Some((ix, axes)) = &sel.gyro_scale {
                let segs = get(ix);
                let mut scratch = Out::default();
                let first = match block {
                    // A first bias for the scale fit: the block mean of output minus reference.
                    Some(b) => fallback_bias(&[b]),
                    None => fallback_bias(&segs),
                };
                let s = gyro::fit_scale(&segs, axes, first, &mut scratch);
                let b = match block {
                    Some(b) => gyro::fit_bias(b, &s, &mut out),
                    None => {
                        out.warnings.push(
                            "no static block for the gyro bias: bias taken from the rate points"
                                .into(),
                        );
                        first
                    }
                };
                gyro::fit_scale(&segs, axes, b, &mut out);
            } else if let Some(b) = block {
                let (bias, _) = gyro::fit_bias(b, &Vec3::zeros(), &mut out);
                out.gyro_model = Some((Mat3::identity(), bias));
            }
            // The bias wanders: as a constant of the IMU over this run, its uncertainty holds the
            // random walk over half the run, at the rate the segment means show.
            if let (Some(_), Some(model)) = (block, &out.gyro_model) {
                let all: Vec<&SegData> = data.values().collect();
                let q2 = gyro::wander_q2(&all, model);
                let half_run = (rec.imu.t[rec.imu.t.len() - 1] - rec.imu.t[0]) / 2.0;
                for (ax, name) in AXES.iter().enumerate() {
                    if let Some(Parameter::Estimate { u, .. }) =
                        out.params.get_mut(&format!("gyro.bias.{name}"))
                    {
                        *u = (*u * *u + q2[ax] * half_run).sqrt();
                    }
                }
            }
            if let Some(ix) = &sel.gyro_full {
                gyro::fit_full(&get(ix), &mut out);
            }
        },
    );
    if let Some(ix) = &sel.size_effect {
        size_effect::fit(rec, ix, &mut out);
    }
    let allan = allan_block
        .zip(curves.as_ref())
        .and_then(|(b, c)| allan::analyse(b, c, &mut out));
    let static_segs: Vec<&SegData> = get(&sel.temp_segments);
    let temp_done = match (&out.accel_model, &out.gyro_model) {
        (Some(a), Some(g)) if !static_segs.is_empty() => {
            temp::fit(&static_segs, &a.clone(), &g.clone(), &mut out)
        }
        _ => false,
    };
    if sel.temp_requested && !temp_done {
        for s in ["accel", "gyro"] {
            for ax in AXES {
                out.unobservable(
                    &format!("{s}.thermal_drift.{ax}"),
                    "the IMU temperature did not vary by 1 degC across the static data",
                );
            }
        }
    }
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
    moving_accel_residuals(&data, &mut out);
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
    let declared = effects::declared(plan, &opts.with);
    if !declared.is_empty() {
        effects::apply(rec, &sel, &declared, &mut res);
    }
    res.acceptance = accept::evaluate(plan, &res, &out.quantities, &wh, &mut out.warnings);
    let mut w = std::mem::take(&mut out.warnings);
    w.append(&mut res.warnings);
    res.warnings = w;
    res.decide(results::ended_early(&rec.manifest));
    res
}

/// The accelerometer model checked on the segments that move (rate and oscillation),
/// which the seed model does not fit: their residuals join the results, and a mean
/// residual far beyond the static fit's noise is a warning (a lever arm, a time offset).
fn moving_accel_residuals(data: &BTreeMap<usize, SegData>, out: &mut Out) {
    let Some((k, b)) = out.accel_model else {
        return;
    };
    let noise = out
        .quantities
        .get("accel.residual.std")
        .map_or(0.0, |q| q.0);
    let moving: Vec<&SegData> = data
        .values()
        .filter(|s| s.kind != crate::recording::SegmentKind::Static)
        .collect();
    let first = out.residuals.len();
    accel::model_residuals(&moving, accel::Sensor::Accel, &k, &b, out);
    let worst = out.residuals[first..]
        .iter()
        .max_by(|a, b| a.mean.abs().total_cmp(&b.mean.abs()))
        .map(|r| (r.mean.abs(), r.segment.clone(), r.channel.clone()));
    if let Some((m, id, axis)) = worst
        && noise > 0.0
        && m > 5.0 * noise
    {
        out.warnings.push(format!(
                "accelerometer {axis} residual on moving segment {id}: mean {m:.4} m/s^2, {:.0} times the static noise: the model leaves out motion-dependent physics (a lever arm, a time offset); see `ratecal explain` or `--with lever_arm`",
                m / noise
            ));
    }
}

/// Bias per axis from the rate points when there is no static block: mean of output minus
/// reference, uncertainty from their scatter.
fn fallback_bias(segs: &[&SegData]) -> (Vec3, Vec3) {
    let mut b = Vec3::zeros();
    let mut u = Vec3::zeros();
    for ax in 0..3 {
        let d: Vec<f64> = segs
            .iter()
            .map(|s| stats::mean(&s.gyro[ax], &s.keep_g) - stats::mean(&s.w_ref[ax], &s.keep_g))
            .collect();
        let keep = vec![true; d.len()];
        b[ax] = stats::mean(&d, &keep);
        u[ax] = stats::std(&d, &keep) / (d.len().max(1) as f64).sqrt();
    }
    (b, u)
}
