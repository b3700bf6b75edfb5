//! Which segments feed which fit: the procedure's fit statements, or segment kinds.

use super::Options;
use super::prep::PrepOptions;
use super::segment::Summary;
use crate::plan::{FitModel, Plan, segment_matches};
use crate::recording::{Manifest, SegmentKind, TableStream};
use crate::results::{AmbientStats, EnvironmentInfo, ModelInfo, RecordingInfo, SegmentUse};
use std::collections::HashMap;

/// The analysis plan for one recording.
#[derive(Debug, Default, Clone)]
pub(crate) struct Selection {
    /// Every segment to prepare, with its preprocessing.
    pub prep: Vec<(usize, PrepOptions)>,
    /// Accelerometer segments and whether the full model is asked.
    pub accel: Option<(Vec<usize>, bool)>,
    /// The gyro bias block.
    pub gyro_bias: Option<usize>,
    /// Gyro scale segments and axes.
    pub gyro_scale: Option<(Vec<usize>, Vec<usize>)>,
    /// Full gyro model segments.
    pub gyro_full: Option<Vec<usize>>,
    /// Allan block.
    pub allan: Option<usize>,
    /// Static segments for the temperature model.
    pub temp_segments: Vec<usize>,
    /// Whether the procedure asks for temperature compensation.
    pub temp_requested: bool,
    /// Segments used by no fit (candidates for verification).
    pub unused: Vec<usize>,
    /// Description for the results.
    pub model: ModelInfo,
    /// What could not be selected.
    pub warnings: Vec<String>,
    /// Uses per segment.
    pub used_for: HashMap<usize, Vec<String>>,
    /// Oscillation segments of the size-effect fit (navigated on the raw stream, not prepared).
    pub size_effect: Option<Vec<usize>>,
}

impl Selection {
    fn add(&mut self, ix: &[usize], po: PrepOptions, why: &str) {
        for &i in ix {
            if !self.prep.iter().any(|p| p.0 == i) {
                self.prep.push((i, po));
            }
            let u = self.used_for.entry(i).or_default();
            if !u.iter().any(|w| w == why) {
                u.push(why.to_string());
            }
        }
    }

    /// The segment table of the results.
    pub(crate) fn uses(&self, m: &Manifest, sums: &[Summary]) -> Vec<SegmentUse> {
        m.segments
            .iter()
            .enumerate()
            .map(|(i, s)| {
                let sum = sums.iter().find(|x| x.seg == i);
                let mut used_for = self.used_for.get(&i).cloned().unwrap_or_default();
                if self.unused.contains(&i) && sum.is_some_and(|x| x.prepared) {
                    used_for.push("verification".into());
                }
                SegmentUse {
                    id: s.id.clone(),
                    kind: kind_name(s.kind).into(),
                    t_start: s.t_start,
                    t_end: s.t_end,
                    imu_samples: sum.map_or(0, |x| x.rows),
                    outliers_removed: sum.filter(|x| x.prepared).map_or(0, |x| x.outliers),
                    used_for,
                }
            })
            .collect()
    }
}

fn kind_name(k: SegmentKind) -> &'static str {
    match k {
        SegmentKind::Static => "static",
        SegmentKind::Rate => "rate",
        SegmentKind::Oscillation => "oscillation",
        SegmentKind::Turn => "turn",
    }
}

/// Chooses segments for each fit.
pub(crate) fn select(m: &Manifest, plan: Option<&Plan>, opts: &Options) -> Selection {
    let segs = &m.segments;
    let dur = |i: &usize| segs[*i].t_end - segs[*i].t_start;
    let longest = |ix: &[usize]| {
        ix.iter()
            .copied()
            .filter(|&i| segs[i].kind == SegmentKind::Static)
            .max_by(|a, b| dur(a).total_cmp(&dur(b)))
    };
    let default_po = PrepOptions {
        outliers: opts.outliers,
        lowpass: opts.lowpass,
    };
    let mut sel = Selection::default();
    // The procedure applied (its thresholds, and its fits when it has any). The recording
    // names the procedure it ran, with its hash: the same one here.
    sel.model.procedure = plan.map(|plan| crate::recording::ProcedureRef {
        name: plan.name.clone(),
        version: plan.version.clone(),
        sha256: m
            .procedure
            .as_ref()
            .filter(|p| p.name == plan.name && p.version == plan.version)
            .map(|p| p.sha256.clone())
            .unwrap_or_default(),
    });
    match plan.filter(|p| !p.fits.is_empty()) {
        Some(plan) => {
            sel.model.selection = "procedure".into();
            for f in &plan.fits {
                let ix: Vec<usize> = (0..segs.len())
                    .filter(|&i| f.segments.iter().any(|p| segment_matches(p, &segs[i].id)))
                    .collect();
                let po = PrepOptions {
                    outliers: f.outliers.or(opts.outliers),
                    lowpass: f.lowpass.or(opts.lowpass),
                };
                let desc = format!(
                    "{} from {}",
                    serde_json::to_value(&f.model)
                        .ok()
                        .and_then(|v| v.as_str().map(String::from))
                        .unwrap_or_default(),
                    f.segments.join(", ")
                );
                sel.model.fits.push(desc.clone());
                if ix.is_empty() {
                    sel.warnings
                        .push(format!("fit `{desc}` matches no segment of the recording"));
                    if f.model == FitModel::TempCompensation {
                        sel.temp_requested = true;
                    }
                    continue;
                }
                match f.model {
                    FitModel::AccelBiasScale | FitModel::AccelFull => {
                        sel.add(&ix, po, "accel");
                        sel.accel = Some((ix.clone(), f.model == FitModel::AccelFull));
                        sel.temp_segments
                            .extend(ix.iter().filter(|&&i| segs[i].kind == SegmentKind::Static));
                    }
                    FitModel::GyroBias => {
                        if let Some(b) = longest(&ix) {
                            sel.add(&[b], po, "gyro_bias");
                            sel.gyro_bias = Some(b);
                            sel.allan.get_or_insert(b);
                            sel.temp_segments.push(b);
                        }
                    }
                    FitModel::GyroScale => {
                        sel.add(&ix, po, "gyro_scale");
                        sel.gyro_scale = Some((ix, f.axes.clone()));
                    }
                    FitModel::GyroFull => {
                        sel.add(&ix, po, "gyro_full");
                        sel.gyro_full = Some(ix);
                    }
                    FitModel::TempCompensation => {
                        sel.temp_requested = true;
                        let st: Vec<usize> = ix
                            .iter()
                            .copied()
                            .filter(|&i| segs[i].kind == SegmentKind::Static)
                            .collect();
                        sel.add(&st, po, "temperature");
                        sel.temp_segments.extend(st);
                    }
                    FitModel::Allan => {
                        if let Some(b) = longest(&ix) {
                            sel.add(&[b], po, "allan");
                            sel.allan = Some(b);
                        }
                    }
                    FitModel::SizeEffect => {
                        for &i in &ix {
                            sel.used_for
                                .entry(i)
                                .or_default()
                                .push("size_effect".into());
                        }
                        sel.size_effect = Some(ix);
                    }
                }
            }
            sel.unused = (0..segs.len())
                .filter(|i| {
                    !sel.used_for.contains_key(i) && segs[*i].kind != SegmentKind::Oscillation
                })
                .collect();
        }
        None => {
            sel.model.selection = "by_kind".into();
            // The six-position fits take the faces; an oblique pose (`up: oblique`, written
            // by `ratecal import`) is left to a multi-position calibration.
            let oblique: Vec<&str> = segs
                .iter()
                .filter(|s| s.kind == SegmentKind::Static && s.is_oblique())
                .map(|s| s.id.as_str())
                .collect();
            if !oblique.is_empty() {
                sel.warnings.push(format!(
                    "{} oblique static segment(s) skipped (up: oblique): the six-position fits \
                     use the faces only ({})",
                    oblique.len(),
                    oblique.join(", ")
                ));
            }
            let st: Vec<usize> = (0..segs.len())
                .filter(|&i| segs[i].kind == SegmentKind::Static && !segs[i].is_oblique())
                .collect();
            let rt: Vec<usize> = (0..segs.len())
                .filter(|&i| segs[i].kind == SegmentKind::Rate)
                .collect();
            if !st.is_empty() {
                sel.add(&st, default_po, "accel");
                sel.accel = Some((st.clone(), false));
                sel.model
                    .fits
                    .push("accel_bias_scale from every static segment".into());
                let b = longest(&st).expect("static segments exist");
                sel.add(&[b], default_po, "gyro_bias");
                sel.gyro_bias = Some(b);
                sel.allan = Some(b);
                sel.model
                    .fits
                    .push(format!("gyro_bias from {} (longest static)", segs[b].id));
                sel.temp_segments = st;
            } else {
                sel.warnings.push(
                    "no static segment: accelerometer model and gyro bias not determined".into(),
                );
            }
            if !rt.is_empty() {
                sel.add(&rt, default_po, "gyro_scale");
                sel.gyro_scale = Some((rt, vec![0, 1, 2]));
                sel.model
                    .fits
                    .push("gyro_scale from every rate segment".into());
            } else {
                sel.warnings
                    .push("no rate segment: gyro scale factors not determined".into());
            }
        }
    }
    sel.temp_segments.sort_unstable();
    sel.temp_segments.dedup();
    let unused = sel.unused.clone();
    sel.add(&unused, default_po, "verification");
    for i in &unused {
        sel.used_for.remove(i);
    }
    sel
}

/// Identity of the recording: `imu` is its IMU rows, first and last stamp and the median
/// step, s.
pub(crate) fn recording_info(
    m: &Manifest,
    table: &TableStream,
    imu: (usize, (f64, f64), f64),
    path: &str,
) -> RecordingInfo {
    let (rows, (first, last), step) = imu;
    RecordingInfo {
        paths: if path.is_empty() {
            Vec::new()
        } else {
            vec![path.to_string()]
        },
        imu: m.imu.clone(),
        procedure: m.procedure.clone(),
        run_id: m.run.as_ref().map(|r| r.id.clone()),
        latitude_deg: m.station.site.latitude_deg,
        gravity_mps2: m.station.site.gravity_mps2,
        imu_rows: rows,
        table_rows: table.t.len(),
        imu_rate_hz: 1.0 / step,
        table_rate_hz: 1.0 / super::stats::median_step(&table.t),
        duration_s: last - first,
    }
}

/// Lab conditions: the manifest's block, the `ambient` column, and the IMU temperature
/// range over the segments' samples (`imu_temp`).
pub(crate) fn environment(
    m: &Manifest,
    table: &TableStream,
    imu_temp: Option<(f64, f64)>,
) -> EnvironmentInfo {
    let ambient = table.ambient.as_ref().filter(|a| !a.is_empty()).map(|a| {
        let keep = vec![true; a.len()];
        let (mean, _, slope) = super::stats::mean_std_slope(&table.t, a, &keep);
        AmbientStats {
            mean_c: mean,
            min_c: a.iter().copied().fold(f64::MAX, f64::min),
            max_c: a.iter().copied().fold(f64::MIN, f64::max),
            drift_c_per_h: slope * 3600.0,
        }
    });
    EnvironmentInfo {
        recorded: m.environment.clone(),
        ambient,
        imu_temp_range_c: imu_temp.map(|(lo, hi)| [lo, hi]),
    }
}
