//! The twin's prediction of the recording: its terms at its values through the registry's
//! columns of explain's single pass (the regressors every effect gives, evaluated on the
//! recording's own table feedback, site and mount), and the residual of every segment and
//! channel against the noise. No refit: what a dry run would have shown for this motion.

use super::output::{Prediction, SegmentResidual};
use super::{NOMINAL, Twin};
use crate::explain::Rms;
use crate::explain::data::Data;
use crate::fit::joint::{CHANNELS, seg_rss};
use crate::recording::Manifest;
use nalgebra::DVector;

/// Most entries of `disagree`.
const MOST: usize = 10;

/// Thermal terms and the nominal term whose value they shift when the reference
/// temperature moves: `(thermal id, nominal id)`.
pub(super) const THERMAL: [(&str, &str); 4] = [
    ("accel_thermal_drift", "accel_bias"),
    ("gyro_thermal_drift", "gyro_bias"),
    ("accel_scale_thermal", "accel_scale"),
    ("gyro_scale_thermal", "gyro_scale"),
];

/// The twin's terms as the layout's coefficients: its values, the Earth's rate at the
/// manifest's latitude, the nominal terms moved from the twin's reference temperature to
/// the recording's (`t_ref_data`: a drift `k` adds `k (T_data - T_twin)` to its bias).
pub(super) fn theta(m: &Manifest, data: &Data, twin: &Twin, t_ref_data: f64) -> DVector<f64> {
    let lay = &data.layout;
    let mut th = DVector::zeros(lay.cols.len());
    let dt = t_ref_data - twin.t_ref_c;
    let mut set = |id: &str, v: &[f64]| {
        if let Some(e) = lay.index(id) {
            for (g, x) in lay.columns_of(e).zip(v) {
                th[g] += x;
            }
        }
    };
    for (id, v) in &twin.terms {
        set(id, v);
    }
    for (thermal, nominal) in THERMAL {
        if let Some(k) = twin.values(thermal) {
            let shift: Vec<f64> = k.iter().map(|k| k * dt).collect();
            set(nominal, &shift);
        }
    }
    // The signals hold the timing they were evaluated at: its columns measure what is left.
    for (id, b) in super::TIMING.iter().zip(data.retime.registry()) {
        set(id, &[-b]);
    }
    let lat = m.station.site.latitude_deg;
    set(
        "earth_rate",
        &ratecal_physics::effects::EarthRate::values(lat),
    );
    // The accelerometers sense the lever arm's acceleration through their scale factor
    // (`K (f + M r)`, spec/physics.md): in the registry's linear columns accelerometer i's
    // coordinates weigh `1 + s_i`.
    if let (Some(e), Some(scale)) = (lay.index("lever_arm"), twin.values("accel_scale")) {
        for (k, g) in lay.columns_of(e).enumerate() {
            th[g] *= 1.0 + scale[k / 3] * 1e-6;
        }
    }
    debug_assert!(NOMINAL.iter().all(|id| lay.index(id).is_some()));
    th
}

/// Residuals of the prediction `theta` on every segment and channel; `white` is the
/// recording's own white noise per channel (explain's final model).
pub(super) fn predict(
    m: &Manifest,
    data: &Data,
    twin: &Twin,
    theta: &DVector<f64>,
    white: &[f64; 6],
) -> Prediction {
    let lay = &data.layout;
    let t0 = m
        .segments
        .iter()
        .map(|s| s.t_start)
        .fold(f64::INFINITY, f64::min);
    let mut segments = Vec::new();
    let mut chi: Vec<f64> = Vec::new();
    let (mut ss, mut nn) = ([0.0f64; 2], [0usize; 2]);
    for acc in &data.accs {
        if acc.n == 0 {
            continue;
        }
        let seg = &m.segments[acc.seg];
        let t_mid = 0.5 * (seg.t_start + seg.t_end) - t0;
        for c in 0..6 {
            let rss = seg_rss(acc, lay, c, theta);
            let n = acc.n as f64;
            let cols = &lay.by_channel[c];
            let sum: f64 = acc
                .blocks
                .iter()
                .map(|b| {
                    b.sy[c]
                        - b.sx[c]
                            .iter()
                            .zip(cols)
                            .map(|(x, &g)| x * theta[g])
                            .sum::<f64>()
                })
                .sum();
            let wander2 = if c < 3 {
                0.0
            } else {
                twin.gyro_bias_markov_sigma_dps.powi(2)
                    + twin.gyro_bias_random_walk.powi(2) * t_mid.max(0.0)
            };
            let white_twin = if c < 3 {
                twin.noise.accel_mps2
            } else {
                twin.noise.gyro_dps
            };
            let noise_twin = (white_twin.powi(2) + wander2).sqrt();
            let allowed = (white_twin.max(white[c]).powi(2) + wander2).sqrt();
            let ratio = if allowed > 0.0 {
                (rss / n).sqrt() / allowed
            } else {
                f64::INFINITY
            };
            // The residual's sum of squares against the noise's: n +- sqrt(2 n).
            chi.push(if allowed > 0.0 {
                (rss / allowed.powi(2) - n) / (2.0 * n).sqrt()
            } else {
                f64::INFINITY
            });
            ss[c / 3] += rss;
            nn[c / 3] += acc.n;
            segments.push(SegmentResidual {
                segment: seg.id.clone(),
                kind: kind_name(seg.kind).into(),
                channel: CHANNELS[c].into(),
                rms: (rss / n).sqrt(),
                mean: sum / n,
                sd: (rss / n - (sum / n).powi(2)).max(0.0).sqrt(),
                noise_twin,
                noise_recording: white[c],
                ratio,
            });
        }
    }
    let mut disagree: Vec<(f64, SegmentResidual)> = segments
        .iter()
        .zip(&chi)
        .filter(|(s, z)| s.ratio > 1.1 && **z > 5.0)
        .map(|(s, _)| (s.ratio, s.clone()))
        .collect();
    disagree.sort_by(|a, b| b.0.total_cmp(&a.0));
    let rms = |k: usize| {
        if nn[k] == 0 {
            0.0
        } else {
            (ss[k] / nn[k] as f64).sqrt()
        }
    };
    Prediction {
        rms: Rms {
            accel_mps2: rms(0),
            gyro_dps: rms(1),
        },
        noise: Rms {
            accel_mps2: twin.noise.accel_mps2,
            gyro_dps: twin.noise.gyro_dps.hypot(twin.gyro_bias_markov_sigma_dps),
        },
        segments,
        disagree: disagree.into_iter().take(MOST).map(|d| d.1).collect(),
    }
}

pub(super) fn kind_name(k: crate::recording::SegmentKind) -> &'static str {
    use crate::recording::SegmentKind as K;
    match k {
        K::Static => "static",
        K::Rate => "rate",
        K::Oscillation => "oscillation",
        K::Turn => "turn",
    }
}
