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
mod manual;
mod models;
pub(crate) mod prep;
mod repeat;
mod residuals;
mod sanity;
mod segment;
mod select;
pub mod size_effect;
mod source;
mod stats;

pub use allan::overlapping_adev;
pub use repeat::analyze_runs;
pub use segment::{Retime, WINDOW_ROWS};
pub use source::{ImuView, ImuWork, Source, Streamed};

use crate::plan::{Outliers, Plan};
use crate::recording::Recording;
use crate::results::{self, Parameter, ResidualStats, Results, SyncReport};
use joint::{Layout, SegAcc};
use ratecal_physics::{Mat3, Vec3};
use segment::Summary;
use std::collections::BTreeMap;
use std::sync::Arc;

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
    /// Most IMU rows of a static segment held at once (its outlier test runs within each
    /// window of that many rows); a moving segment's windows are an eighth of it.
    pub window_rows: usize,
    /// Whether the windows of a segment longer than one window are passed side by side
    /// (the default), their sums joined in order; `false` passes them one after another.
    /// The results agree to rounding (the joined factors and block sums are summed in
    /// another order).
    pub parallel_windows: bool,
    /// The Type B figures the station states: with them every reported parameter gets its
    /// GUM budget (results.json `budgets`) and the checks on parameters are judged with
    /// its `U` and `k`; without, with the fit's Type A uncertainty at k = 2.
    pub stated: Option<crate::budget::terms::Stated>,
    /// Where the Allan block's gyro series may be kept instead of memory (87 MB at 1 kHz
    /// for an hour at rest): with it the series is written to a scratch file as it comes
    /// and read back a block at a time, and the analysis holds a few MB of it whatever
    /// the recording's length; without, it stays in memory. The curves are the same to
    /// the bit either way. A scratch file that cannot be opened or written leaves the
    /// series in memory; one that cannot be read back leaves the Allan parameters
    /// unobservable, with a warning.
    pub scratch: Option<Scratch>,
}

/// Opens a fresh scratch file, read and written, empty, removed when closed (as
/// `tempfile::tempfile`): the analysis opens no file of its own.
#[derive(Clone)]
pub struct Scratch(pub Arc<dyn Fn() -> std::io::Result<std::fs::File> + Send + Sync>);

impl Scratch {
    /// Scratch files opened by `open`.
    pub fn new(open: impl Fn() -> std::io::Result<std::fs::File> + Send + Sync + 'static) -> Self {
        Scratch(Arc::new(open))
    }
}

impl std::fmt::Debug for Scratch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Scratch")
    }
}

impl Default for Options {
    fn default() -> Self {
        Options {
            outliers: Some(Outliers::Sigma(3.0)),
            lowpass: None,
            path: String::new(),
            with: Vec::new(),
            window_rows: segment::WINDOW_ROWS,
            parallel_windows: true,
            stated: None,
            scratch: None,
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

/// Analyses one recording held in memory.
pub fn analyze_with(rec: &Recording, plan: Option<&Plan>, opts: &Options) -> Results {
    let Ok(res) = analyze_source(rec, plan, opts);
    res
}

/// Analyses one recording read from `src` segment by segment, a window of samples at a
/// time; fails only when a span of the recording cannot be read.
pub fn analyze_source<S: Source>(
    src: &S,
    plan: Option<&Plan>,
    opts: &Options,
) -> Result<Results, S::Error> {
    let m = src.manifest();
    if manual::is_manual(m) {
        return manual::analyze(src, plan, opts);
    }
    let sel = select::select(m, plan, opts);
    let mut out = Out {
        warnings: sel.warnings.clone(),
        ..Default::default()
    };
    let declared = models::declared(plan, &opts.with);
    let thermal = sel.temp_requested && src.has_temp();
    let design = models::Design::new(&sel, &declared, thermal, &mut out);
    let (mut sums, accs) = pass_segments(src, &design.layout, opts, |i| {
        let prep = sel.prep.iter().find(|p| p.0 == i).map(|p| p.1);
        (prep, sel.allan == Some(i), sel.unused.contains(&i))
    })?;
    let mut sync = SyncReport {
        method: "linear_interpolation".into(),
        table_step_s: stats::median_step(&src.table().t),
        ..Default::default()
    };
    for s in sums.iter_mut().filter(|s| s.prepared) {
        sync.widen(&s.sync);
        out.warnings.append(&mut s.warnings);
    }

    // The Allan curves (the costly part of the noise analysis) run beside the fits.
    let allan_block = sel
        .allan
        .and_then(|i| sums.iter_mut().find(|s| s.seg == i))
        .and_then(|s| Some((s.allan.take()?, s.step_s)));
    let temperature = sel.temp_requested && temperature_varies(&sums, &sel.temp_segments);
    let (curves, fitted) = rayon::join(
        || allan_block.map(|(series, dt)| allan::curves(series, dt)),
        || models::fit(m, &sel, &design, &accs, temperature, &mut out),
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
    if let (Some(_), Some(b)) = (out.gyro_model, sel.gyro_bias) {
        let id = &m.segments[b].id;
        gyro::block_noise(id, fitted.residuals.iter().map(|r| &r.0), &mut out);
    }
    if let Some(ix) = &sel.size_effect {
        size_effect::fit(&*src.recording()?, ix, &mut out);
    }
    let allan = match (sel.allan, curves) {
        (Some(i), Some(Ok(c))) => allan::analyse(&m.segments[i].id, &c, &mut out),
        (Some(i), Some(Err(e))) => {
            allan::unreadable(&m.segments[i].id, &e, &mut out);
            None
        }
        _ => None,
    };
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
    let mut checks = sanity::recording_checks(
        m,
        &sums,
        &src.imu_cadence(),
        src.imu_extent(),
        src.table(),
        &mut out.warnings,
    );
    checks.push(sanity::plausible(&out.params));
    out.residuals = fitted.residuals.iter().map(|(r, _)| r.clone()).collect();
    unfitted_residual_warnings(&fitted.residuals, &mut out);
    let (verification, wh) = accept::verify(&sel, &sums, &out, m);
    let segments = sel.uses(m, &sums);
    let steps: Vec<f64> = sums
        .iter()
        .map(|s| s.step_s)
        .filter(|s| s.is_finite())
        .collect();
    let imu = (src.imu_rows(), src.imu_extent(), median(steps));
    let temp_range = temp_span(sums.iter());
    let mut res = Results {
        format: results::FORMAT.into(),
        verdict: results::RunVerdict::default(),
        verdict_reason: None,
        sanity: checks,
        parameters: std::mem::take(&mut out.params),
        acceptance: Vec::new(),
        observability: std::mem::take(&mut out.observability),
        recording: select::recording_info(m, src.table(), imu, &opts.path),
        model: sel.model.clone(),
        segments,
        sync,
        residuals: std::mem::take(&mut out.residuals),
        allan,
        verification,
        repeatability: None,
        environment: select::environment(m, src.table(), temp_range),
        warnings: Vec::new(),
        fits: Default::default(),
        size_effect: out.size_effect.take(),
        manual: None,
        budgets: Vec::new(),
        draft_procedure: m.run.as_ref().and_then(|r| r.draft_procedure.clone()),
    };
    res.fits = fitted.fits;
    res.model
        .fits
        .extend(fitted.description.iter().map(|d| format!("joint {d}")));
    if let Some(stated) = &opts.stated {
        res.budgets = crate::budget::budgets(&res, stated);
    }
    res.acceptance = accept::evaluate(plan, &res, &out.quantities, &wh, &mut out.warnings);
    let mut w = std::mem::take(&mut out.warnings);
    w.append(&mut res.warnings);
    res.warnings = w;
    res.decide(results::ended_early(m));
    Ok(res)
}

/// Every segment's raw samples (no preprocessing) accumulated over `layout`, in manifest
/// order, those without samples left out: what explain fits its models from.
///
/// A long segment (the standard's hour at rest is four fifths of its samples) is passed in
/// pieces of about [`PIECE_ROWS`] rows side by side, their factors merged: the factor of
/// stacked rows is the factor of the stacked factors.
pub(crate) fn accumulate_all<S: Source>(
    src: &S,
    layout: &Layout,
    retime: Retime,
) -> Result<Vec<SegAcc>, S::Error> {
    use rayon::prelude::*;
    let m = src.manifest();
    let Context {
        geos,
        rate_hz,
        t_ref_c,
    } = Context::of(src, layout)?;
    let mut jobs = Vec::new();
    for (i, seg) in m.segments.iter().enumerate() {
        let rows = (seg.t_end - seg.t_start) * rate_hz;
        let pieces = ((rows / PIECE_ROWS as f64).floor() as usize).max(1);
        for p in 0..pieces {
            let at = |p: usize| seg.t_start + (seg.t_end - seg.t_start) * p as f64 / pieces as f64;
            let span = (pieces > 1).then(|| {
                (
                    at(p),
                    if p + 1 == pieces {
                        seg.t_end
                    } else {
                        at(p + 1)
                    },
                )
            });
            jobs.push(segment::Job {
                seg: i,
                geo: &geos[i],
                layout,
                t_ref_c,
                prep: None,
                allan: false,
                spill: None,
                verify: false,
                rate_hz,
                window_rows: segment::WINDOW_ROWS,
                span,
                retime,
                windows: None,
            });
        }
    }
    let dur = |j: &segment::Job| match j.span {
        Some((a, b)) => b - a,
        None => m.segments[j.seg].t_end - m.segments[j.seg].t_start,
    };
    jobs.sort_by(|a, b| dur(b).total_cmp(&dur(a)));
    let mut passed: Vec<(f64, SegAcc)> = jobs
        .par_iter()
        .map(|job| {
            let t0 = job.span.map_or(m.segments[job.seg].t_start, |s| s.0);
            segment::pass(src, job).map(|(_, acc)| (t0, acc))
        })
        .collect::<Result<_, _>>()?;
    passed.sort_by(|a, b| a.1.seg.cmp(&b.1.seg).then(a.0.total_cmp(&b.0)));
    let mut accs: Vec<SegAcc> = Vec::new();
    for (_, acc) in passed {
        match accs.last_mut() {
            Some(last) if last.seg == acc.seg => last.merge(acc),
            _ => accs.push(acc),
        }
    }
    accs.retain(|a| a.n > 0);
    Ok(accs)
}

/// What every segment's pass shares: the station geometry per segment, the recording's mean
/// IMU rate, and the temperature the thermal terms refer to (the recording's mean, read only
/// when a term of `layout` uses it).
struct Context {
    geos: Vec<ratecal_physics::Geometry>,
    rate_hz: f64,
    t_ref_c: f64,
}

impl Context {
    fn of<S: Source>(src: &S, layout: &Layout) -> Result<Context, S::Error> {
        let t_ref_c = if layout.effects.iter().any(|e| e.uses_temperature()) {
            src.mean_temp()?
        } else {
            0.0
        };
        Ok(Context {
            geos: prep::geometries(src.manifest()),
            rate_hz: mean_rate(src),
            t_ref_c,
        })
    }
}

/// Rows of one piece of a long segment in [`accumulate_all`].
const PIECE_ROWS: usize = 65_536;

/// Passes every segment once over `layout` (in parallel, longest first so that the work
/// stealing balances; a long segment's windows side by side, joined in order, unless
/// `opts` says otherwise), the thermal terms referred to the recording's mean temperature;
/// `what(i)` says how segment `i` is prepared, whether it is the Allan block and whether a
/// verification segment. Summaries in manifest order; accumulations of the segments with
/// samples.
fn pass_segments<S: Source>(
    src: &S,
    layout: &Layout,
    opts: &Options,
    what: impl Fn(usize) -> (Option<prep::PrepOptions>, bool, bool) + Sync,
) -> Result<(Vec<Summary>, Vec<SegAcc>), S::Error> {
    use rayon::prelude::*;
    let m = src.manifest();
    let Context {
        geos,
        rate_hz,
        t_ref_c,
    } = Context::of(src, layout)?;
    // The Allan series goes to a scratch file when one is handed in and opens; else it
    // stays in memory.
    let spill = (opts.scratch.as_ref())
        .filter(|_| (0..m.segments.len()).any(|i| what(i).1))
        .and_then(|open| open.0().ok())
        .map(|file| Arc::new(allan::Spill::new(file)));
    let mut jobs = Vec::new();
    for i in 0..m.segments.len() {
        let (prep, allan, verify) = what(i);
        let job = segment::Job {
            seg: i,
            geo: &geos[i],
            layout,
            t_ref_c,
            prep,
            allan,
            spill: spill.as_ref(),
            verify,
            rate_hz,
            window_rows: opts.window_rows,
            span: None,
            retime: Retime::default(),
            windows: None,
        };
        // A long segment's windows side by side (a verification segment's statistics
        // are kept whole), each weighed by the time it covers.
        let dur = m.segments[i].t_end - m.segments[i].t_start;
        let k = segment::windows(src, &job);
        match opts.parallel_windows && k > 1 && !verify {
            true => jobs.extend((0..k).map(|w| {
                let piece = segment::Job {
                    windows: Some((w, w + 1)),
                    ..job
                };
                (piece, dur / k as f64)
            })),
            false => jobs.push((job, dur)),
        }
    }
    // Longest first, so that the work stealing balances.
    let mut order: Vec<usize> = (0..jobs.len()).collect();
    order.sort_by(|&a, &b| jobs[b].1.total_cmp(&jobs[a].1));
    let mut passed: Vec<(usize, (Summary, SegAcc))> = order
        .par_iter()
        .map(|&j| segment::pass(src, &jobs[j].0).map(|p| (j, p)))
        .collect::<Result<_, _>>()?;
    // The pieces of a segment in order, joined.
    passed.sort_by_key(|p| p.0);
    let (mut sums, mut accs): (Vec<Summary>, Vec<SegAcc>) = (Vec::new(), Vec::new());
    for (_, (sum, acc)) in passed {
        match (sums.last_mut(), accs.last_mut()) {
            (Some(s), Some(a)) if s.seg == sum.seg => {
                s.merge(sum);
                a.merge(acc);
            }
            _ => {
                sums.push(sum);
                accs.push(acc);
            }
        }
    }
    accs.retain(|a| a.n > 0);
    Ok((sums, accs))
}

/// The lowest and highest IMU temperature over these segments' samples.
fn temp_span<'a>(sums: impl Iterator<Item = &'a Summary>) -> Option<(f64, f64)> {
    sums.filter_map(|s| s.temp_range)
        .reduce(|a, b| (a.0.min(b.0), a.1.max(b.1)))
}

/// The median of some values (NaN of none).
fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// The recording's mean IMU rate, Hz: rows over its extent.
fn mean_rate<S: Source>(src: &S) -> f64 {
    let (rows, (t0, t1)) = (src.imu_rows(), src.imu_extent());
    if rows > 1 && t1 > t0 {
        (rows - 1) as f64 / (t1 - t0)
    } else {
        1.0
    }
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
                "{sensor} {} residual on segment {}, which the {sensor} fit does not use: mean {:.4} {}, {:.0} times the fit's noise: the nominal model does not describe that segment ({physics}, or a disturbance during it); `ratecal explain` tests the catalogue's effects against it and says whether one accounts for it",
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
fn temperature_varies(sums: &[Summary], segs: &[usize]) -> bool {
    temp_span(sums.iter().filter(|s| segs.contains(&s.seg))).is_some_and(|(lo, hi)| hi - lo >= 1.0)
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
