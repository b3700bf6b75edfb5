//! Hidden effects: physics added to the IMU's outputs, each a closed form of the instant
//! ([`Instant`]: specific force, inertial rate, time, temperature), each with its truth.

use std::fmt;

use serde::Serialize;
use serde_json::{Value, json};

use crate::motion::AxesState;
use crate::rot::{M3, V3};
use crate::station::{Instant, Station};
use crate::table;

/// A closed form of the instant: what it adds to the accelerometer (m/s^2) and gyro (deg/s)
/// outputs.
pub type CustomFn = Box<dyn Fn(&Instant) -> (V3, V3) + Send + Sync>;

/// One effect added to the outputs. Forms use `f` = `Instant::f_b` (m/s^2, at the body
/// origin), `w` = `Instant::w_ib_dps`, `t` = `Instant::t` (table time, s), `g` the site's.
pub enum Hidden {
    /// `a_i += K2_i 1e-6 f_i^2 / g` (IEEE 1293's K2, ug/g^2). Registry `accel_second_order`.
    AccelSecondOrder {
        /// K2 per axis, ug/g^2.
        k2_ug_per_g2: V3,
    },
    /// `a_x += k_x 1e-6 f_y f_z / g`, `a_y += k_y 1e-6 f_x f_z / g`,
    /// `a_z += k_z 1e-6 f_x f_y / g` (ug/g^2). Not in the registry.
    AccelCrossCoupling {
        /// Coefficient per output axis, ug/g^2.
        ug_per_g2: V3,
    },
    /// `g_i += k_i f_i^2 / g^2` (deg/s per g^2). Not in the registry.
    GyroG2 {
        /// Coefficient per axis, deg/s per g^2.
        dps_per_g2: V3,
    },
    /// `g_i += A_i 1e-6 |w_i|`: the scale is `K_ii + A_i 1e-6` for positive rates and
    /// `K_ii - A_i 1e-6` for negative ones. Registry `gyro_scale_asymmetry`.
    GyroScaleAsymmetry {
        /// A per axis, ppm.
        ppm: V3,
    },
    /// `a_i += A_i 1e-6 |f_i|`: the scale is `K_ii + A_i 1e-6` for +g and `K_ii - A_i 1e-6`
    /// for -g. Registry `accel_scale_asymmetry`.
    AccelScaleAsymmetry {
        /// A per axis, ppm.
        ppm: V3,
    },
    /// The IMU clock runs fast by `ppm` against the table's (both read zero at t = 0): the
    /// sample stamped `t_stamp` was taken at table time `t_stamp / (1 + ppm 1e-6)`. The
    /// motion is re-timed exactly. Registry `clock_rate`.
    ClockRate {
        /// Clock rate error, ppm (positive: the IMU clock runs fast).
        ppm: f64,
    },
    /// The sample stamped `t_stamp` measured the motion at `t_stamp - tau` (table clock;
    /// with a clock rate, at `t_stamp / (1 + eps) - tau`). Registry `time_offset`.
    TimeOffset {
        /// tau, ms.
        tau_ms: f64,
    },
    /// `a += step` for `t >= at_s`. Not in the registry.
    AccelBiasStep {
        /// Table time of the step, s.
        at_s: f64,
        /// The jump, m/s^2.
        step_mps2: V3,
    },
    /// `g += A exp(-t / tau)`: a bias decaying from power-on at t = 0. Not in the registry.
    GyroWarmUp {
        /// A per axis at power-on, deg/s.
        amplitude_dps: V3,
        /// Time constant, s.
        tau_s: f64,
    },
    /// `g_i += sum_j G_ij f_j / g` (deg/s per g). Registry `g_sensitivity`.
    GSensitivity {
        /// `G_ij * g`, deg/s per g.
        dps_per_g: M3,
    },
    /// Accelerometer `i` senses at `R_i` (body axes, from the table axes' intersection):
    /// `s_i = e_i . (f + dw x R_i + w x (w x R_i))`, before `K_a`. Registry `lever_arm`.
    LeverArm {
        /// `r_mm[i][j]`: j-component of `R_i`, mm.
        r_mm: M3,
    },
    /// The table's encoders are eccentric (docs/effects.md): axis k (`[outer, inner]`)
    /// reads `theta_enc = theta + e_k sin(theta + phi_k)`, `theta` the true angle. The table
    /// reports `theta_enc` and servoes on it: the plan's motion is the encoders', the IMU
    /// turns by the true `theta`. Registry `table_encoder_eccentricity` (station side),
    /// `<axis>_sin_arcsec = e cos(phi)`, `<axis>_cos_arcsec = e sin(phi)`.
    TableEncoderEccentricity {
        /// `e` per axis, `[outer, inner]`, arcsec.
        e_arcsec: [f64; 2],
        /// `phi` per axis, `[outer, inner]`, deg.
        phi_deg: [f64; 2],
    },
    /// The outer bearing wobbles: the whole gimbal tilts about the lab axis
    /// `u = unit(a_o x up)` by `delta = w sin(2 th_o + phi)` (twice per outer revolution);
    /// the encoders read the angles exactly. A table error in no registry.
    TableWobble {
        /// `w`, arcsec.
        w_arcsec: f64,
        /// `phi`, deg.
        phi_deg: f64,
    },
    /// Anything else: `(da, dw)` added to the outputs.
    Custom {
        /// Short name (the truth's `id`).
        name: String,
        /// What was put in, for `truth.json`.
        truth: Value,
        /// The closed form.
        f: CustomFn,
    },
}

/// What `truth.json` says about one hidden effect.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HiddenTruth {
    /// Short name: the registry's id where the registry holds it (or will, issue 27 §4).
    pub id: String,
    /// Whether the effect registry names it (a right answer names it; otherwise a right
    /// answer reports it as unexplained on its sensor).
    pub registry: bool,
    /// The closed form added.
    pub form: String,
    /// Parameters, in the registry's names where it has them.
    pub parameters: Value,
    /// Unit of the parameters.
    pub unit: String,
    /// What a right answer says.
    pub right: String,
}

const AXES: [&str; 3] = ["x", "y", "z"];

fn per_axis(v: V3) -> Value {
    json!({ "x": v[0], "y": v[1], "z": v[2] })
}

fn per_pair(m: &M3, prefix: &str, suffix: &str, diagonal: bool) -> Value {
    let mut out = serde_json::Map::new();
    for i in 0..3 {
        for j in 0..3 {
            if i != j || diagonal {
                let key = format!("{prefix}{}{}{suffix}", AXES[i], AXES[j]);
                out.insert(key, json!(m[i][j]));
            }
        }
    }
    Value::Object(out)
}

/// The registry's linear components of `e sin(theta + phi)`:
/// `e sin(theta) cos(phi) + e cos(theta) sin(phi)`.
fn eccentricity_components(e: [f64; 2], phi_deg: [f64; 2]) -> Value {
    let (so, co) = phi_deg[0].to_radians().sin_cos();
    let (si, ci) = phi_deg[1].to_radians().sin_cos();
    json!({
        "outer_sin_arcsec": e[0] * co, "outer_cos_arcsec": e[0] * so,
        "inner_sin_arcsec": e[1] * ci, "inner_cos_arcsec": e[1] * si,
    })
}

impl Hidden {
    /// A custom effect named `name`, with `truth` for `truth.json`.
    pub fn custom(
        name: &str,
        truth: Value,
        f: impl Fn(&Instant) -> (V3, V3) + Send + Sync + 'static,
    ) -> Hidden {
        Hidden::Custom {
            name: name.into(),
            truth,
            f: Box::new(f),
        }
    }

    /// The short name.
    pub fn id(&self) -> &str {
        match self {
            Hidden::AccelSecondOrder { .. } => "accel_second_order",
            Hidden::AccelCrossCoupling { .. } => "accel_cross_coupling",
            Hidden::GyroG2 { .. } => "gyro_g2_sensitivity",
            Hidden::GyroScaleAsymmetry { .. } => "gyro_scale_asymmetry",
            Hidden::AccelScaleAsymmetry { .. } => "accel_scale_asymmetry",
            Hidden::ClockRate { .. } => "clock_rate",
            Hidden::TimeOffset { .. } => "time_offset",
            Hidden::AccelBiasStep { .. } => "accel_bias_step",
            Hidden::GyroWarmUp { .. } => "gyro_warm_up",
            Hidden::GSensitivity { .. } => "g_sensitivity",
            Hidden::LeverArm { .. } => "lever_arm",
            Hidden::TableEncoderEccentricity { .. } => "table_encoder_eccentricity",
            Hidden::TableWobble { .. } => "table_wobble",
            Hidden::Custom { name, .. } => name,
        }
    }

    /// What `truth.json` says about it.
    pub fn truth(&self) -> HiddenTruth {
        let (registry, form, parameters, unit, right) = match self {
            Hidden::AccelSecondOrder { k2_ug_per_g2 } => (
                true,
                "a_i += K2_i * 1e-6 * f_b.i^2 / g",
                per_axis(*k2_ug_per_g2),
                "ug/g^2",
                "accel_second_order with x, y, z",
            ),
            Hidden::AccelCrossCoupling { ug_per_g2 } => (
                false,
                "a_x += k_x * 1e-6 * f_b.y * f_b.z / g; a_y += k_y * 1e-6 * f_b.x * f_b.z / g; \
                 a_z += k_z * 1e-6 * f_b.x * f_b.y / g",
                per_axis(*ug_per_g2),
                "ug/g^2",
                "unexplained on the accelerometers, in the rate segments (gravity sweeping \
                 through two axes); no registry effect",
            ),
            Hidden::GyroG2 { dps_per_g2 } => (
                false,
                "g_i += k_i * f_b.i^2 / g^2",
                per_axis(*dps_per_g2),
                "deg/s per g^2",
                "unexplained on the gyros: each grows with the square of the specific force \
                 along its own axis; no registry effect",
            ),
            Hidden::GyroScaleAsymmetry { ppm } => (
                true,
                "g_i += A_i * 1e-6 * abs(w_ib.i)",
                per_axis(*ppm),
                "ppm",
                "gyro_scale_asymmetry (scale K + A for w > 0, K - A for w < 0)",
            ),
            Hidden::AccelScaleAsymmetry { ppm } => (
                true,
                "a_i += A_i * 1e-6 * abs(f_b.i)",
                per_axis(*ppm),
                "ppm",
                "accel_scale_asymmetry (scale K + A for +g, K - A for -g)",
            ),
            Hidden::ClockRate { ppm } => (
                true,
                "the sample stamped t_stamp measured the motion at table time \
                 t_stamp / (1 + ppm * 1e-6)",
                json!({ "ppm": ppm }),
                "ppm",
                "clock_rate (not a constant time_offset, not a lever_arm)",
            ),
            Hidden::TimeOffset { tau_ms } => (
                true,
                "the sample stamped t_stamp measured the motion at t_stamp - tau",
                json!({ "tau_ms": tau_ms }),
                "ms",
                "time_offset with tau_ms",
            ),
            Hidden::AccelBiasStep { at_s, step_mps2 } => (
                false,
                "a += step for t >= at_s",
                json!({ "at_s": at_s, "x": step_mps2[0], "y": step_mps2[1], "z": step_mps2[2] }),
                "m/s^2 (at_s: s)",
                "unexplained on the accelerometers, located in time at the step; no registry \
                 effect",
            ),
            Hidden::GyroWarmUp {
                amplitude_dps,
                tau_s,
            } => (
                false,
                "g += A * exp(-t / tau_s), t from power-on (t = 0)",
                json!({ "tau_s": tau_s, "x": amplitude_dps[0], "y": amplitude_dps[1],
                        "z": amplitude_dps[2] }),
                "deg/s (tau_s: s)",
                "unexplained on the gyros, a decay in time with its time constant; no \
                 registry effect",
            ),
            Hidden::GSensitivity { dps_per_g } => (
                true,
                "g_i += sum_j G_ij * f_b.j / g",
                per_pair(dps_per_g, "", "_dps_per_g", true),
                "deg/s per g",
                "g_sensitivity with <i><j>_dps_per_g",
            ),
            Hidden::LeverArm { r_mm } => (
                true,
                "s_i = e_i . (f_b + dw_b x R_i + w_b x (w_b x R_i)), before K_a",
                per_pair(r_mm, "r", "_mm", true),
                "mm",
                "lever_arm with r<i><j>_mm (those this plan can determine)",
            ),
            Hidden::TableEncoderEccentricity { e_arcsec, phi_deg } => (
                true,
                "theta_enc = theta + e * sin(theta + phi) per axis; the table reports and \
                 servoes on theta_enc, the IMU turns by theta",
                eccentricity_components(*e_arcsec, *phi_deg),
                "arcsec",
                "table_encoder_eccentricity (station side) with <axis>_sin_arcsec = \
                 e cos(phi), <axis>_cos_arcsec = e sin(phi); nothing credited to the IMU",
            ),
            Hidden::TableWobble { w_arcsec, phi_deg } => (
                false,
                "C_LB = R(u, w * sin(2 th_o + phi)) * C_LB, u = unit(a_o x up); angles \
                 reported exactly",
                json!({ "w_arcsec": w_arcsec, "phi_deg": phi_deg }),
                "arcsec (phi: deg)",
                "unexplained where the outer axis turns or stands at several angles; no \
                 IMU-side effect",
            ),
            Hidden::Custom { truth, .. } => (
                false,
                "custom closed form",
                truth.clone(),
                "",
                "see parameters",
            ),
        };
        HiddenTruth {
            id: self.id().into(),
            registry,
            form: form.into(),
            parameters,
            unit: unit.into(),
            right: right.into(),
        }
    }

    /// The true motion of the axes (`[outer, inner]` of angle deg, rate deg/s, acceleration
    /// deg/s^2) when the table's encoders follow `plan`.
    pub(crate) fn true_axes(&self, plan: AxesState) -> AxesState {
        let Hidden::TableEncoderEccentricity { e_arcsec, phi_deg } = self else {
            return plan;
        };
        [0, 1].map(|k| table::true_axis(e_arcsec[k], phi_deg[k], plan[k]))
    }

    /// What the IMU senses once the table's own tilt is added (`axes` the true motion).
    pub(crate) fn tilt(&self, st: &Station, inst: Instant, axes: &AxesState) -> Instant {
        let Hidden::TableWobble { w_arcsec, phi_deg } = self else {
            return inst;
        };
        table::wobble(st, &inst, *w_arcsec, *phi_deg, axes[0])
    }

    /// What it adds to the specific force each accelerometer senses, before `K_a`, m/s^2.
    pub(crate) fn accel_input(&self, inst: &Instant) -> V3 {
        let Hidden::LeverArm { r_mm } = self else {
            return [0.0; 3];
        };
        std::array::from_fn(|i| inst.f_at(r_mm[i].map(|r| r * 1e-3))[i] - inst.f_b[i])
    }

    /// What it adds to the outputs, after `K_a` and `K_g`: (accel m/s^2, gyro deg/s).
    pub(crate) fn outputs(&self, inst: &Instant) -> (V3, V3) {
        let (f, w, g) = (inst.f_b, inst.w_ib_dps, inst.g);
        let zero = [0.0; 3];
        match self {
            Hidden::AccelSecondOrder { k2_ug_per_g2: k } => {
                (std::array::from_fn(|i| k[i] * 1e-6 * f[i] * f[i] / g), zero)
            }
            Hidden::AccelCrossCoupling { ug_per_g2: k } => (
                [
                    k[0] * 1e-6 * f[1] * f[2] / g,
                    k[1] * 1e-6 * f[0] * f[2] / g,
                    k[2] * 1e-6 * f[0] * f[1] / g,
                ],
                zero,
            ),
            Hidden::GyroG2 { dps_per_g2: k } => {
                (zero, std::array::from_fn(|i| k[i] * f[i] * f[i] / (g * g)))
            }
            Hidden::GyroScaleAsymmetry { ppm } => {
                (zero, std::array::from_fn(|i| ppm[i] * 1e-6 * w[i].abs()))
            }
            Hidden::AccelScaleAsymmetry { ppm } => {
                (std::array::from_fn(|i| ppm[i] * 1e-6 * f[i].abs()), zero)
            }
            Hidden::AccelBiasStep { at_s, step_mps2 } => {
                (if inst.t >= *at_s { *step_mps2 } else { zero }, zero)
            }
            Hidden::GyroWarmUp {
                amplitude_dps,
                tau_s,
            } => (zero, amplitude_dps.map(|a| a * (-inst.t / tau_s).exp())),
            Hidden::GSensitivity { dps_per_g } => (
                zero,
                std::array::from_fn(|i| (0..3).map(|j| dps_per_g[i][j] * f[j] / g).sum()),
            ),
            Hidden::Custom { f: custom, .. } => custom(inst),
            Hidden::ClockRate { .. }
            | Hidden::TimeOffset { .. }
            | Hidden::LeverArm { .. }
            | Hidden::TableEncoderEccentricity { .. }
            | Hidden::TableWobble { .. } => (zero, zero),
        }
    }
}

impl fmt::Debug for Hidden {
    fn fmt(&self, out: &mut fmt::Formatter<'_>) -> fmt::Result {
        let t = self.truth();
        write!(out, "{}({})", t.id, t.parameters)
    }
}
