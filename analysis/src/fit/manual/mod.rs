//! Calibration without a rate table: static poses whose attitude is `nominal` (a fixture's
//! faces: the six-face solution, Ferraris) or `unknown` (hand-held poses: gravity's
//! magnitude, Tedaldi/imu_tk), and the turns between them for the gyros. The results go
//! through the same sanity checks, acceptance and verdict as a rate-table run; the gravity
//! check is made on the calibrated poses.

mod accel;
mod checks;
mod data;
mod gyro;
mod lsq;

pub(crate) use data::is_manual;

use super::{Options, Source, accept, sanity, select};
use crate::plan::Plan;
use crate::recording::{Attitude, SegmentKind};
use crate::results::{self, ManualFit, Parameter, Results, SegmentUse, SyncReport};
use data::{Data, Pose};
use nalgebra::{Matrix3, Vector3};
use std::collections::BTreeMap;

const AXES: [&str; 3] = ["x", "y", "z"];

/// One sensor's fitted model and its results.json entries.
#[derive(Debug, Clone)]
pub(crate) struct Triad {
    sensor: &'static str,
    bias_unit: &'static str,
    pub k: Matrix3<f64>,
    pub b: Vector3<f64>,
    pub params: BTreeMap<String, Parameter>,
    pub why: BTreeMap<String, String>,
    pub rms: f64,
}

impl Triad {
    fn new(
        sensor: &'static str,
        k: Matrix3<f64>,
        b: Vector3<f64>,
        bias_unit: &'static str,
    ) -> Self {
        Triad {
            sensor,
            bias_unit,
            k,
            b,
            params: BTreeMap::new(),
            why: BTreeMap::new(),
            rms: f64::NAN,
        }
    }

    fn bias(&mut self, i: usize, v: f64, u: f64) {
        let key = format!("{}.bias.{}", self.sensor, AXES[i]);
        self.params
            .insert(key, Parameter::estimate(v, u, self.bias_unit));
    }

    /// `k_ii` is the diagonal term (reported as `K_ii - 1` in ppm).
    fn scale(&mut self, i: usize, k_ii: f64, u: f64) {
        let key = format!("{}.scale.{}", self.sensor, AXES[i]);
        self.params
            .insert(key, Parameter::estimate((k_ii - 1.0) * 1e6, u * 1e6, "ppm"));
    }

    fn misalignment(&mut self, i: usize, j: usize, v: f64, u: f64) {
        let key = format!("{}.misalignment.{}{}", self.sensor, AXES[i], AXES[j]);
        self.params
            .insert(key, Parameter::estimate(v * 1e3, u * 1e3, "mrad"));
    }

    fn unobservable(&mut self, i: usize, j: usize, why: &str) {
        let key = format!("{}.misalignment.{}{}", self.sensor, AXES[i], AXES[j]);
        self.params.insert(key.clone(), Parameter::needs(why));
        self.why.insert(key, why.to_string());
    }
}

/// The fitted sensors and the figures the results state.
struct Fitted {
    method: &'static str,
    accel: Option<accel_fit::Out>,
    gyro: Option<Triad>,
    turns: Vec<results::TurnMiss>,
    warnings: Vec<String>,
}

mod accel_fit {
    /// The accelerometer fit and the poses it used.
    pub(super) struct Out {
        pub triad: super::Triad,
        pub convention: Option<&'static str>,
    }
}

/// Analyses a manual recording.
pub(crate) fn analyze<S: Source>(
    src: &S,
    plan: Option<&Plan>,
    opts: &Options,
) -> Result<Results, S::Error> {
    let m = src.manifest();
    let g = m.station.site.gravity_mps2;
    let data = data::read(src)?;
    let fitted = fit(&data, g);
    let mut params = BTreeMap::new();
    let mut observability = BTreeMap::new();
    let mut warnings = fitted.warnings.clone();
    for (sensor, t) in [
        ("accel", fitted.accel.as_ref().map(|a| &a.triad)),
        ("gyro", fitted.gyro.as_ref()),
    ] {
        match t {
            Some(t) => {
                params.extend(t.params.clone());
                observability.extend(t.why.clone());
            }
            None => {
                let why = format!(
                    "the poses and turns of this recording do not determine the {sensor} model"
                );
                warnings.push(format!("{why}: see `manual` and `observability`"));
                for what in ["bias", "scale"] {
                    for ax in AXES {
                        let key = format!("{sensor}.{what}.{ax}");
                        params.insert(key.clone(), Parameter::needs(&why));
                        observability.insert(key, why.clone());
                    }
                }
            }
        }
    }
    let manual = summary(&data, &fitted, g, &params);
    let mut sanity = checks::checks(
        m,
        src,
        &data,
        fitted.accel.as_ref().map(|a| &a.triad),
        g,
        &mut warnings,
    );
    sanity.push(sanity::plausible_with(
        &params,
        sanity::ACCEL_OFFSET_MAX_MANUAL,
    ));
    let (rows, extent) = (src.imu_rows(), src.imu_extent());
    let step = if rows > 1 {
        (extent.1 - extent.0) / (rows - 1) as f64
    } else {
        f64::NAN
    };
    let mut res = Results {
        format: results::FORMAT.into(),
        verdict: results::RunVerdict::default(),
        verdict_reason: None,
        sanity,
        parameters: params,
        acceptance: Vec::new(),
        observability,
        recording: select::recording_info(m, src.table(), (rows, extent, step), &opts.path),
        model: results::ModelInfo {
            procedure: select::select(m, plan, opts).model.procedure,
            selection: "manual".into(),
            fits: model_fits(&fitted, &data),
        },
        segments: uses(m, &data, &fitted),
        sync: SyncReport {
            method: "none (no table: attitudes from the poses)".into(),
            ..Default::default()
        },
        residuals: checks::residuals(&data, fitted.accel.as_ref().map(|a| &a.triad), g),
        allan: None,
        verification: Vec::new(),
        repeatability: None,
        environment: select::environment(m, src.table(), None),
        warnings: Vec::new(),
        fits: Default::default(),
        size_effect: None,
        manual: Some(manual),
        budgets: Vec::new(),
        draft_procedure: m.run.as_ref().and_then(|r| r.draft_procedure.clone()),
    };
    let mut q = BTreeMap::new();
    if let Some(man) = &res.manual {
        q.insert(
            "accel.residual.std".to_string(),
            (man.gravity_rms_calibrated_mps2, 0.0),
        );
    }
    res.acceptance = accept::evaluate(plan, &res, &q, &Default::default(), &mut warnings);
    res.warnings = warnings;
    res.decide(results::ended_early(m));
    Ok(res)
}

/// The fits: six faces when every pose is a nominal face and they determine the model,
/// else gravity's magnitude over every pose.
fn fit(d: &Data, g: f64) -> Fitted {
    let poses: Vec<&Pose> = d.poses.iter().collect();
    let all_faces = !poses.is_empty()
        && poses
            .iter()
            .all(|p| p.attitude == Attitude::Nominal && p.face.is_some());
    let mut warnings = Vec::new();
    if all_faces && let Some(t) = accel::from_faces(&poses, g) {
        let tol = poses.iter().map(|p| p.tol_rad).fold(0.0, f64::max);
        let gyro = gyro::from_axis_turns(&d.turns, gyro::faces_bias(&poses), tol);
        if gyro.is_none() {
            warnings.push(
                "the gyro scale needs a turn about each body axis with its nominal `angle_deg`"
                    .into(),
            );
        }
        return Fitted {
            method: "six_face",
            accel: Some(accel_fit::Out {
                triad: t,
                convention: None,
            }),
            gyro,
            turns: Vec::new(),
            warnings,
        };
    }
    let accel = accel::from_magnitude(&poses, g);
    if accel.is_none() {
        warnings.push(format!(
            "{} poses: gravity's magnitude needs at least {} poses of varied attitude",
            poses.len(),
            accel::REDUCED_MIN_POSES
        ));
    }
    let (gyro, turns) = match (&accel, d.poses.first()) {
        (Some(a), Some(rest)) => turn_fit(d, a, rest),
        _ => (None, Vec::new()),
    };
    Fitted {
        method: "multi_pose",
        accel: accel.map(|t| accel_fit::Out {
            triad: t,
            convention: Some(accel::CONVENTION),
        }),
        gyro,
        turns,
        warnings,
    }
}

/// The gyro fit over the turns between poses, bias from the initial rest, and each turn's
/// miss with the nominal and the calibrated gyros.
fn turn_fit(d: &Data, a: &Triad, rest: &Pose) -> (Option<Triad>, Vec<results::TurnMiss>) {
    let bias = gyro::rest_bias(rest);
    let joined: Vec<_> = d
        .turns
        .iter()
        .filter_map(|t| Some((t, t.from?, t.to?)))
        .collect();
    let prepare = |b: &Vector3<f64>| -> Vec<gyro::Prepared> {
        joined
            .iter()
            .map(|(t, f, to)| {
                let (pf, pt) = (&d.poses[*f], &d.poses[*to]);
                gyro::Prepared::of(t, b, accel::calibrated(a, pf), accel::calibrated(a, pt))
            })
            .collect()
    };
    let prepared = prepare(&bias.0);
    let ids: Vec<String> = joined.iter().map(|(t, ..)| t.id.clone()).collect();
    let shifted: Vec<_> = (0..3)
        .map(|k| prepare(&(bias.0 + Vector3::ith(k, bias.1[k]))))
        .collect();
    let fit = gyro::from_turns(&prepared, bias, &shifted);
    let k_inv = fit.as_ref().and_then(|f| f.k.try_inverse());
    let misses = match k_inv {
        Some(k_inv) => prepared
            .iter()
            .zip(ids)
            .map(|(p, id)| results::TurnMiss {
                segment: id,
                nominal_deg: p.miss_deg(&Matrix3::identity()),
                calibrated_deg: p.miss_deg(&k_inv),
            })
            .collect(),
        None => Vec::new(),
    };
    (fit, misses)
}

fn rms(v: impl Iterator<Item = f64>) -> f64 {
    let (s, n) = v.fold((0.0, 0usize), |(s, n), x| (s + x * x, n + 1));
    if n == 0 {
        f64::NAN
    } else {
        (s / n as f64).sqrt()
    }
}

/// The `manual` block of results.json.
fn summary(d: &Data, f: &Fitted, g: f64, params: &BTreeMap<String, Parameter>) -> ManualFit {
    let poses: Vec<results::PoseGravity> = d
        .poses
        .iter()
        .map(|p| results::PoseGravity {
            segment: p.id.clone(),
            raw_mps2: Vector3::from(p.f).norm(),
            calibrated_mps2: f
                .accel
                .as_ref()
                .map_or(f64::NAN, |a| accel::calibrated(&a.triad, p).norm()),
        })
        .collect();
    let turns_some = !f.turns.is_empty();
    ManualFit {
        method: f.method.into(),
        determined: params
            .iter()
            .filter(|(_, p)| p.value_u().is_some())
            .map(|(k, _)| k.clone())
            .collect(),
        convention: f
            .accel
            .as_ref()
            .and_then(|a| a.convention)
            .map(str::to_string),
        gravity_mps2: g,
        gravity_rms_raw_mps2: rms(poses.iter().map(|p| p.raw_mps2 - g)),
        gravity_rms_calibrated_mps2: rms(poses.iter().map(|p| p.calibrated_mps2 - g)),
        poses,
        turn_rms_nominal_deg: turns_some.then(|| rms(f.turns.iter().map(|t| t.nominal_deg))),
        turn_rms_calibrated_deg: turns_some.then(|| rms(f.turns.iter().map(|t| t.calibrated_deg))),
        turns: f.turns.clone(),
    }
}

/// What each fit used, in words (`model.fits`).
fn model_fits(f: &Fitted, d: &Data) -> Vec<String> {
    let n_turns = if f.method == "six_face" {
        d.turns
            .iter()
            .filter(|t| t.axis.is_some() && t.angle_deg.is_some())
            .count()
    } else {
        f.turns.len()
    };
    let what = match f.method {
        "six_face" => "accel six_face (nominal faces; tilts as nuisances within their tolerance)",
        _ => "accel multi_pose (gravity's magnitude; attitudes unknown)",
    };
    let gyro = match f.method {
        "six_face" => {
            "gyro bias from the faces, K_g from the turns about body axes (integrated angle / nominal angle)"
        }
        _ => {
            "gyro bias from the initial rest, K_g from the turns between poses (gravity's direction carried)"
        }
    };
    vec![
        format!("{what} from {} poses", d.poses.len()),
        format!("{gyro} from {n_turns} turns"),
    ]
}

/// Each segment and what the fits used it for.
fn uses(m: &crate::recording::Manifest, d: &Data, f: &Fitted) -> Vec<SegmentUse> {
    m.segments
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let pose = d.poses.iter().position(|p| p.seg == i);
            let mut used = Vec::new();
            if pose.is_some() && f.accel.is_some() {
                used.push("accel".to_string());
            }
            if f.gyro.is_some() {
                if pose == Some(0) && f.method == "multi_pose"
                    || pose.is_some() && f.method == "six_face"
                {
                    used.push("gyro_bias".into());
                }
                let turn_used = s.kind == SegmentKind::Turn
                    && (f.turns.iter().any(|t| t.segment == s.id)
                        || f.method == "six_face" && s.axis.is_some() && s.angle_deg.is_some());
                if turn_used {
                    used.push("gyro_full".into());
                }
            }
            SegmentUse {
                id: s.id.clone(),
                kind: format!("{:?}", s.kind).to_lowercase(),
                t_start: s.t_start,
                t_end: s.t_end,
                imu_samples: pose.map_or(0, |p| d.poses[p].n),
                outliers_removed: 0,
                used_for: used,
            }
        })
        .collect()
}
