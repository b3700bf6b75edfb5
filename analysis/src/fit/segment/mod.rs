//! One pass over a segment: its IMU rows are read a window at a time from the
//! [`Source`], and each window is synchronised with the table feedback (the kinematic
//! signals at every stamp, evaluated once), cleaned of outliers, low-passed, and folded into
//! the joint fit's factors ([`Accumulator`]) and into the few sums the rest of the analysis
//! reads (verification means, the Allan series, temperature span, synchronisation). What
//! is left of a segment is its [`Summary`]: a 1 kHz hour-long block never sits in memory.
//!
//! A window holds at most [`WINDOW_ROWS`] rows by default (a moving segment's, whose
//! signals are kept per row, an eighth of that); the outlier test runs within a window. A low-pass over
//! a segment of several windows reads each window with a margin on both sides, so that the
//! filter's start-up is spent outside the rows it keeps.

mod kin;
mod stats;

pub(crate) use stats::{ChannelStats, RawSums};

use super::joint::{Accumulator, Layout, SegAcc};
use super::prep::{self, PrepOptions};
use super::source::{ImuWork, Source};
use super::stats::median_step;
use crate::recording::{Segment, SegmentKind, TableStream};
use crate::results::SyncReport;
use kin::Kin;
pub use kin::Retime;
use ratecal_physics::Geometry;
use ratecal_physics::effects::Signals;
use std::borrow::Cow;

/// Rows per window of a static segment by default: 87 minutes at 100 Hz, 8.7 at 1 kHz.
pub const WINDOW_ROWS: usize = 524_288;
/// A moving segment's windows are this much shorter (its signals are kept per row).
const MOVING_DIVISOR: usize = 8;
/// Margin on each side of a window for a low-pass, in periods of the cutoff.
const MARGIN_PERIODS: f64 = 30.0;

/// What to do with one segment.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Job<'a> {
    /// Index in the manifest.
    pub seg: usize,
    /// Station geometry in force.
    pub geo: &'a Geometry,
    /// Columns of the joint fit.
    pub layout: &'a Layout,
    /// Temperature the thermal terms refer to, degC.
    pub t_ref_c: f64,
    /// Preprocessing; `None` accumulates the raw samples.
    pub prep: Option<PrepOptions>,
    /// Whether to keep the kept gyro series for the Allan analysis.
    pub allan: bool,
    /// Where that series goes as it comes (in memory without).
    pub spill: Option<&'a std::sync::Arc<super::allan::Spill>>,
    /// Whether to keep the outputs against their references (a verification segment).
    pub verify: bool,
    /// Mean IMU rate of the recording, Hz (sizes the windows).
    pub rate_hz: f64,
    /// Rows per window of a static segment.
    pub window_rows: usize,
    /// Only this part of the segment (s), when one segment is passed in pieces.
    pub span: Option<(f64, f64)>,
    /// The samples' known timing error against the feedback.
    pub retime: Retime,
    /// Only the windows `[a, b)` of the segment's [`windows`], when a long segment's
    /// windows are passed side by side (their summaries joined by [`Summary::merge`],
    /// their accumulations by `SegAcc::merge`): every window is read, cleaned and filtered
    /// exactly as in one pass over the whole segment.
    pub windows: Option<(usize, usize)>,
}

/// What is left of a segment once its rows have passed.
#[derive(Debug, Clone)]
pub(crate) struct Summary {
    /// Index in the manifest.
    pub seg: usize,
    /// IMU rows in the segment.
    pub rows: usize,
    /// Rows removed as outliers of either sensor.
    pub outliers: usize,
    /// Whether the segment was preprocessed.
    pub prepared: bool,
    /// Lowest and highest finite IMU temperature, degC.
    pub temp_range: Option<(f64, f64)>,
    /// Synchronisation seen.
    pub sync: SyncReport,
    /// What could not be done as asked.
    pub warnings: Vec<String>,
    /// The feedback angles (outer, inner) summed over the IMU stamps, deg.
    angle_sums: (f64, f64),
    /// Median IMU step of the first window, s.
    pub step_s: f64,
    /// Per output channel (`ax ay az gx gy gz`), outputs against references (prepared only).
    pub channels: [ChannelStats; 6],
    /// The kept gyro outputs per axis, in order (the Allan block only).
    pub allan: Option<super::allan::Series>,
    /// Raw outputs against references over every row, for the sanity checks.
    pub raw: RawSums,
}

/// How a segment's pass is cut: the span it covers, its windows (count) and the margin
/// each window reads on both sides for a low-pass, s.
#[derive(Debug, Clone, Copy)]
struct Cut {
    s0: f64,
    s1: f64,
    k: usize,
    margin: f64,
}

impl Cut {
    fn of<S: Source>(src: &S, job: &Job) -> Cut {
        let seg = &src.manifest().segments[job.seg];
        // A static segment's signals are one set (or its feedback's, without per-row
        // copies); a moving segment keeps them per row.
        let moving = seg.kind != SegmentKind::Static;
        let per = if moving {
            job.window_rows / MOVING_DIVISOR
        } else {
            job.window_rows
        }
        .max(1) as f64;
        let (s0, s1) = job.span.unwrap_or((seg.t_start, seg.t_end));
        let k = (((s1 - s0) * job.rate_hz / per).ceil() as usize).max(1);
        let margin = match job.prep.and_then(|p| p.lowpass) {
            Some((_, fc)) if k > 1 && fc > 0.0 => MARGIN_PERIODS / fc,
            _ => 0.0,
        };
        // Without two feedback samples there is no reference to fit against.
        let k = if src.table().t.len() < 2 { 0 } else { k };
        Cut { s0, s1, k, margin }
    }

    /// Window `i`'s own span.
    fn window(&self, i: usize) -> (f64, f64) {
        let at = |i: usize| self.s0 + (self.s1 - self.s0) * i as f64 / self.k as f64;
        (at(i), if i + 1 == self.k { self.s1 } else { at(i + 1) })
    }
}

/// How many windows the pass over `job`'s segment reads (0 without table feedback).
pub(crate) fn windows<S: Source>(src: &S, job: &Job) -> usize {
    Cut::of(src, job).k
}

/// Runs the pass over one segment.
pub(crate) fn pass<S: Source>(src: &S, job: &Job) -> Result<(Summary, SegAcc), S::Error> {
    let m = src.manifest();
    let seg = &m.segments[job.seg];
    let mut kin = Kin::new(src.table(), seg, job.geo, m.station.site, job.retime);
    let cut = Cut::of(src, job);
    let (a, b) = job.windows.map_or((0, cut.k), |(a, b)| (a, b.min(cut.k)));
    let mut acc = Accumulator::new(job.seg, cut.s0, job.layout);
    if a > 0 {
        // A later piece of the segment: its blocks keep the whole segment's grid.
        acc.continue_grid();
    }
    let mut w = Window {
        job,
        seg,
        acc,
        sum: Summary {
            seg: job.seg,
            rows: 0,
            outliers: 0,
            prepared: job.prep.is_some(),
            temp_range: None,
            sync: SyncReport::default(),
            warnings: Vec::new(),
            angle_sums: (0.0, 0.0),
            step_s: f64::NAN,
            channels: Default::default(),
            allan: (job.allan && job.prep.is_some())
                .then(|| super::allan::Series::new(job.spill.cloned())),
            raw: RawSums::default(),
        },
        step: None,
    };
    for i in a..b {
        let (c0, c1) = cut.window(i);
        let (r0, r1) = (
            (c0 - cut.margin).max(seg.t_start),
            (c1 + cut.margin).min(seg.t_end),
        );
        // Only the segment's own end is inclusive: a piece ends where the next begins.
        let last = i + 1 == cut.k && cut.s1 >= seg.t_end;
        src.rows_to_work(r0, r1, |v| w.window(&mut kin, v, c0, c1, last))?;
    }
    let Window { acc, sum, .. } = w;
    Ok((sum, acc.finish()))
}

impl Summary {
    /// Mean feedback angles (outer, inner) at the IMU stamps, deg.
    pub(crate) fn mean_angles_deg(&self) -> (f64, f64) {
        let n = self.rows.max(1) as f64;
        (self.angle_sums.0 / n, self.angle_sums.1 / n)
    }

    /// Adds the summary of the windows that follow this one's in the same segment.
    pub(crate) fn merge(&mut self, later: Summary) {
        debug_assert_eq!(self.seg, later.seg);
        // A piece's first window warns as the segment's first would: only the first's count.
        if self.rows == 0 {
            self.warnings.extend(later.warnings);
        }
        if self.step_s.is_nan() {
            self.step_s = later.step_s;
        }
        self.rows += later.rows;
        self.outliers += later.outliers;
        self.temp_range = match (self.temp_range, later.temp_range) {
            (Some(a), Some(b)) => Some((a.0.min(b.0), a.1.max(b.1))),
            (a, b) => a.or(b),
        };
        self.sync.widen(&later.sync);
        self.angle_sums.0 += later.angle_sums.0;
        self.angle_sums.1 += later.angle_sums.1;
        for (c, l) in self.channels.iter_mut().zip(&later.channels) {
            c.merge(l);
        }
        if let (Some(a), Some(b)) = (&mut self.allan, later.allan) {
            a.append(b);
        }
        self.raw.merge(&later.raw);
    }
}

/// A window's references per output channel: one set at rest, else per row.
enum Refs {
    Constant([f64; 6]),
    PerRow([Vec<f64>; 6]),
}

impl Refs {
    fn at(&self, c: usize, i: usize) -> f64 {
        match self {
            Refs::Constant(r) => r[c],
            Refs::PerRow(r) => r[c][i],
        }
    }
}

/// Adds `sign` times the references to the outputs.
fn shift(outputs: &mut [Cow<[f64]>; 6], refs: &Refs, sign: f64) {
    for (c, o) in outputs.iter_mut().enumerate() {
        for (i, v) in o.to_mut().iter_mut().enumerate() {
            *v += sign * refs.at(c, i);
        }
    }
}

/// What ideal sensors read: specific force, m/s^2, and inertial rate, deg/s.
fn reference(s: &Signals) -> [f64; 6] {
    let (f, w) = (s.f_b, s.w_ib_dps());
    [f.x, f.y, f.z, w.x, w.y, w.z]
}

/// The state of one segment's pass between windows.
struct Window<'a> {
    job: &'a Job<'a>,
    seg: &'a Segment,
    acc: Accumulator<'a>,
    sum: Summary,
    /// The feedback step the last stamp fell in.
    step: Option<Step>,
}

/// What the synchronisation reads of one feedback step: its angles' increments, deg.
#[derive(Debug, Clone, Copy)]
struct Step {
    j: usize,
    d_outer: f64,
    d_inner: f64,
}

impl Window<'_> {
    /// One window: rows `v`, of which those in `[c0, c1)` (`[c0, c1]` for the last) are
    /// its own; the others are the low-pass's margins.
    fn window(&mut self, kin: &mut Kin, v: ImuWork, c0: f64, c1: f64, last: bool) {
        let n = v.t.len();
        let ca = v.t.partition_point(|&t| t < c0);
        let cb = if last {
            n
        } else {
            v.t.partition_point(|&t| t < c1)
        };
        if self.sum.step_s.is_nan() && cb > ca + 1 {
            self.sum.step_s = median_step(&v.t[ca..cb]);
        }
        // Signals at every stamp (one set at rest), with the synchronisation seen.
        let mut sigs: Vec<Signals> = Vec::new();
        let constant = kin.rest;
        // Synchronisation and mean angles are reported for the prepared segments only.
        let prepared = self.job.prep.is_some();
        if let Some(&t0) = v.t.first() {
            kin.seek(t0);
        }
        for (i, &t) in v.t.iter().enumerate() {
            let (j, w) = kin.advance(t);
            if prepared && (ca..cb).contains(&i) {
                self.see_sync(kin.tab, j, w, t);
            }
            if constant.is_none() {
                sigs.push(kin.signals(j, w, t));
            }
        }
        let sig_at = |i: usize| match constant {
            Some(s) => s.at(v.t[i]),
            None => sigs[i],
        };
        // References: specific force and inertial rate (with the Earth's), per channel.
        let refs = match constant {
            Some(s) => Refs::Constant(reference(&s)),
            None if prepared => {
                let mut r: [Vec<f64>; 6] = std::array::from_fn(|_| Vec::with_capacity(n));
                for s in &sigs {
                    for (c, v) in reference(s).into_iter().enumerate() {
                        r[c].push(v);
                    }
                }
                Refs::PerRow(r)
            }
            None => Refs::Constant([0.0; 6]),
        };
        // The raw rows against their references, for the sanity checks (before the
        // outputs are filtered, in place when the window's rows are its own).
        // At rest the references are the window's one set (they do not read the time).
        let raw_ref = |i: usize| match (&refs, constant) {
            (Refs::PerRow(_), _) | (_, Some(_)) => [0, 1, 2, 3, 4, 5].map(|c| refs.at(c, i)),
            _ => reference(&sig_at(i)),
        };
        let mut outputs = v.outputs;
        for i in ca..cb {
            self.sum
                .raw
                .add(outputs.each_ref().map(|o| o[i]), raw_ref(i));
        }
        let mut keep_a = vec![true; n];
        let mut keep_g = vec![true; n];
        if let Some(po) = self.job.prep {
            if let Some(rule) = po.outliers {
                let core = ca..cb;
                let resid = |c: usize| -> Vec<f64> {
                    outputs[c]
                        .iter()
                        .enumerate()
                        .map(|(i, o)| o - refs.at(c, i))
                        .collect()
                };
                rayon::join(
                    || prep::flag_window(resid, rule, &core, &mut keep_a),
                    || prep::flag_window(|k| resid(3 + k), rule, &core, &mut keep_g),
                );
            }
            if let Some((order, cutoff)) = po.lowpass {
                let first = self.sum.rows == 0;
                let id = &self.seg.id;
                // The filter runs on what the outputs hold beyond their references: the
                // motion itself (gravity turning through an axis at g w) is not noise, and
                // a filter started at a segment's first sample would leave its start-up
                // transient on it (0.03 m/s^2 at 100 deg/s on the default station).
                shift(&mut outputs, &refs, -1.0);
                match prep::lowpass(&mut outputs, &keep_a, &keep_g, v.t, order, cutoff) {
                    Ok(()) => {}
                    Err(why) if first => self.sum.warnings.push(format!("segment {id}: {why}")),
                    Err(_) => {}
                }
                shift(&mut outputs, &refs, 1.0);
            }
        }
        // The window's own rows, into the fit and the sums.
        let temp_at = |i: usize| v.temp.map_or(f64::NAN, |x| x[i]);
        for i in ca..cb {
            let tc = temp_at(i);
            if tc.is_finite() {
                let r = self.sum.temp_range.get_or_insert((tc, tc));
                *r = (r.0.min(tc), r.1.max(tc));
            }
            if !keep_a[i] || !keep_g[i] {
                self.sum.outliers += 1;
                continue;
            }
            let mut s = sig_at(i);
            let dt = tc - self.job.t_ref_c;
            s.dtemp_c = if dt.is_finite() { dt } else { 0.0 };
            let o = |c: usize| outputs[c][i];
            self.acc
                .push(&s, v.t[i], [o(0), o(1), o(2)], [o(3), o(4), o(5)]);
        }
        self.sum.rows += cb - ca;
        if prepared && self.job.verify {
            for c in 0..6 {
                let keep = if c < 3 { &keep_a } else { &keep_g };
                let r: Vec<f64> = (ca..cb).map(|i| refs.at(c, i)).collect();
                self.sum.channels[c].add_window(&outputs[c][ca..cb], &r, &keep[ca..cb]);
            }
        }
        if let Some(series) = &mut self.sum.allan {
            // The window's own gyro columns become the series' chunk, cut to its rows and
            // its kept samples in place (a span read for the window is not copied).
            series.push(std::array::from_fn(|ax| {
                let mut col = std::mem::take(outputs[3 + ax].to_mut());
                col.truncate(cb);
                col.drain(..ca);
                let mut kept = keep_g[ca..cb].iter();
                col.retain(|_| *kept.next().expect("a flag a row"));
                col
            }));
        }
    }

    /// The synchronisation of the stamp `t` in feedback step `j` at fraction `w`.
    fn see_sync(&mut self, tab: &TableStream, j: usize, w: f64, t: f64) {
        let (t0, t1) = (tab.t[j], tab.t[j + 1]);
        // What depends on the feedback step alone, once a step (a 1 kHz IMU sees each
        // 100 Hz step ten times).
        if self.step.is_none_or(|s| s.j != j) {
            let gap = t1 - t0;
            let acc_o = prep::rate_derivative(&tab.t, &tab.outer_rate, j);
            let acc_i = prep::rate_derivative(&tab.t, &tab.inner_rate, j);
            let max_acc = acc_o.abs().max(acc_i.abs());
            let sync = &mut self.sum.sync;
            sync.max_gap_s = sync.max_gap_s.max(gap);
            sync.max_angle_error_deg = sync.max_angle_error_deg.max(gap * gap / 8.0 * max_acc);
            self.step = Some(Step {
                j,
                d_outer: prep::unwrap(tab.outer[j + 1] - tab.outer[j]),
                d_inner: prep::unwrap(tab.inner[j + 1] - tab.inner[j]),
            });
        }
        let step = self.step.expect("set above");
        let sync = &mut self.sum.sync;
        sync.max_sync_error_s = sync
            .max_sync_error_s
            .max((t - t0).abs().min((t1 - t).abs()));
        self.sum.angle_sums.0 += tab.outer[j] + w * step.d_outer;
        self.sum.angle_sums.1 += tab.inner[j] + w * step.d_inner;
    }
}
