//! The forms of the probe library: what each regressor is, in the user-effect language, in
//! which unit its coefficient comes out, and what a term of that form means physically (the
//! dictionary of readings, docs/explain.md).
//!
//! Every regressor carries its own scale, so that the fitted coefficient is in a unit an
//! engineer writes (`ug/g^2`, `deg/h/g^2`, `ppm/degC`) and the draft effect file is the
//! expression times one parameter.

use ratecal_physics::effects::{Sensor, Signals};

/// Axis names.
pub(crate) const AXES: [&str; 3] = ["x", "y", "z"];

/// A form, per axis `i` of its sensor. `t0` is the recording's first whole second.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Form {
    /// `f_i^2`: even-order nonlinearity (accel K2) or g^2 sensitivity (gyro).
    ForceSquare,
    /// `f_j f_k` (the same pair on every axis).
    ForceProduct(usize, usize),
    /// `|f_i|`.
    ForceAbs,
    /// `f_i^3` (accel): odd third-order nonlinearity (K3).
    ForceCube,
    /// `f_i |w_b|^2 - w_i (w_b . f)`, i.e. `-(w x (w x f))_i` (accel): the specific force's
    /// second derivative under rotation, what a timing error leaves at second order.
    ForceRateSquare,
    /// `|w_i|` (gyro): scale asymmetry.
    RateAbs,
    /// `w_i^2` (gyro): even in the rate.
    RateSquare,
    /// `w_i^3` (gyro): cubic scale nonlinearity.
    RateCube,
    /// `(t - t0)`: a linear drift.
    Drift { t0: f64 },
    /// `(t - t0)^2`: a quadratic drift.
    Drift2 { t0: f64 },
    /// `exp(-(t - t0) / tau)`: a decay since the recording began (warm-up).
    Decay { t0: f64, tau: f64 },
    /// `1` after the instant, `0` before: a bias step (derived from the bias column).
    Step { at: f64 },
    /// `s_i` after the instant, `0` before: a scale-factor step (derived from the scale
    /// column).
    ScaleStep { at: f64 },
    /// `s_i (t - t0)`: a scale factor that drifts.
    ScaleDrift { t0: f64 },
    /// `s_i dtemp`: a scale factor that follows the temperature.
    ThermalScale,
}

impl Form {
    /// Whether the form is a function of the specific force alone (what a static attitude
    /// excites as well as a turn).
    pub(crate) fn of_force_alone(self) -> bool {
        matches!(
            self,
            Form::ForceSquare | Form::ForceProduct(..) | Form::ForceAbs | Form::ForceCube
        )
    }

    /// Whether the form is a function of time alone (a drift, decay or step of the bias).
    pub(crate) fn in_time(self) -> bool {
        matches!(
            self,
            Form::Drift { .. } | Form::Drift2 { .. } | Form::Decay { .. } | Form::Step { .. }
        )
    }

    /// The scaled regressor on axis `i` of `sensor`, in the user-effect language; the
    /// coefficient is in [`Form::unit`].
    pub(crate) fn expression(self, sensor: Sensor, i: usize) -> String {
        let a = AXES[i];
        let gyro = sensor == Sensor::Gyro;
        // A bias-like term: ug for the accelerometers, deg/h for the gyros.
        let bias = |x: String| {
            if gyro {
                format!("{x} / 3600")
            } else {
                format!("1e-6 * g * {x}")
            }
        };
        // The sensor's own input on axis i: specific force (ppm of it) or rate.
        let input = if gyro {
            format!("(w_ib.{a} / deg)")
        } else {
            format!("f_b.{a}")
        };
        match self {
            Form::ForceSquare if gyro => format!("f_b.{a}^2 / g^2 / 3600"),
            Form::ForceSquare => format!("1e-6 * f_b.{a}^2 / g"),
            Form::ForceProduct(j, k) if gyro => {
                format!("f_b.{} * f_b.{} / g^2 / 3600", AXES[j], AXES[k])
            }
            Form::ForceProduct(j, k) => format!("1e-6 * f_b.{} * f_b.{} / g", AXES[j], AXES[k]),
            Form::ForceAbs if gyro => format!("abs(f_b.{a}) / g / 3600"),
            Form::ForceAbs => format!("1e-6 * abs(f_b.{a})"),
            Form::ForceCube => format!("1e-6 * f_b.{a}^3 / g^2"),
            Form::ForceRateSquare => format!(
                "1e-6 * (f_b.{a} * (w_b.x^2 + w_b.y^2 + w_b.z^2) - w_b.{a} * (w_b.x * f_b.x + w_b.y * f_b.y + w_b.z * f_b.z))"
            ),
            Form::RateAbs => format!("1e-6 * abs(w_ib.{a} / deg)"),
            Form::RateSquare => format!("1e-6 * (w_ib.{a} / deg)^2"),
            Form::RateCube => format!("1e-6 * (w_ib.{a} / deg)^3"),
            Form::Drift { t0 } => bias(format!("(t_s - {t0}) / 3600")),
            Form::Drift2 { t0 } => bias(format!("((t_s - {t0}) / 3600)^2")),
            Form::Decay { t0, tau } => bias(format!("exp(-(t_s - {t0}) / {tau})")),
            Form::Step { at } => bias(format!("(sign(t_s - {at}) + 1) / 2")),
            Form::ScaleStep { at } => format!("1e-6 * {input} * (sign(t_s - {at}) + 1) / 2"),
            Form::ScaleDrift { t0 } => format!("1e-6 * {input} * (t_s - {t0}) / 3600"),
            Form::ThermalScale => format!("1e-6 * {input} * dtemp_c"),
        }
    }

    /// The scaled regressor on each axis (what [`Form::expression`] evaluates to there),
    /// what the axes share computed once.
    pub(crate) fn values(self, sensor: Sensor, s: &Signals) -> [f64; 3] {
        let gyro = sensor == Sensor::Gyro;
        let f = s.f_b;
        let g = s.g;
        let bias = |x: f64| [if gyro { x / 3600.0 } else { 1e-6 * g * x }; 3];
        let hours = |t0: f64| (s.t_s - t0) / 3600.0;
        let each = |v: &dyn Fn(usize) -> f64| [v(0), v(1), v(2)];
        let input = || if gyro { s.w_ib_dps() } else { f };
        match self {
            Form::ForceSquare if gyro => each(&|i| f[i] * f[i] / (g * g) / 3600.0),
            Form::ForceSquare => each(&|i| 1e-6 * f[i] * f[i] / g),
            Form::ForceProduct(j, k) if gyro => [f[j] * f[k] / (g * g) / 3600.0; 3],
            Form::ForceProduct(j, k) => [1e-6 * f[j] * f[k] / g; 3],
            Form::ForceAbs if gyro => each(&|i| f[i].abs() / g / 3600.0),
            Form::ForceAbs => each(&|i| 1e-6 * f[i].abs()),
            Form::ForceCube => each(&|i| 1e-6 * f[i].powi(3) / (g * g)),
            Form::ForceRateSquare => {
                let (w2, wf) = (s.w_b.norm_squared(), s.w_b.dot(&f));
                each(&|i| 1e-6 * (f[i] * w2 - s.w_b[i] * wf))
            }
            Form::RateAbs => {
                let w = s.w_ib_dps();
                each(&|i| 1e-6 * w[i].abs())
            }
            Form::RateSquare => {
                let w = s.w_ib_dps();
                each(&|i| 1e-6 * w[i] * w[i])
            }
            Form::RateCube => {
                let w = s.w_ib_dps();
                each(&|i| 1e-6 * w[i].powi(3))
            }
            Form::Drift { t0 } => bias(hours(t0)),
            Form::Drift2 { t0 } => bias(hours(t0).powi(2)),
            Form::Decay { t0, tau } => bias((-(s.t_s - t0) / tau).exp()),
            Form::Step { at } => bias(if s.t_s > at { 1.0 } else { 0.0 }),
            Form::ScaleStep { at } => {
                let (x, on) = (input(), if s.t_s > at { 1e-6 } else { 0.0 });
                each(&|i| x[i] * on)
            }
            Form::ScaleDrift { t0 } => {
                let (x, h) = (input(), hours(t0));
                each(&|i| 1e-6 * x[i] * h)
            }
            Form::ThermalScale => {
                let x = input();
                each(&|i| 1e-6 * x[i] * s.dtemp_c)
            }
        }
    }

    /// Whether the form reads the time or the temperature (it changes at rest).
    pub(crate) fn varies_at_rest(self) -> bool {
        matches!(
            self,
            Form::Drift { .. }
                | Form::Drift2 { .. }
                | Form::Decay { .. }
                | Form::Step { .. }
                | Form::ScaleStep { .. }
                | Form::ScaleDrift { .. }
                | Form::ThermalScale
        )
    }

    /// The coefficient's unit.
    pub(crate) fn unit(self, sensor: Sensor) -> &'static str {
        let gyro = sensor == Sensor::Gyro;
        match self {
            Form::ForceSquare | Form::ForceProduct(..) if gyro => "deg/h/g^2",
            Form::ForceSquare | Form::ForceProduct(..) => "ug/g^2",
            Form::ForceAbs if gyro => "deg/h/g",
            Form::ForceAbs | Form::RateAbs => "ppm",
            Form::ForceCube => "ug/g^3",
            Form::ForceRateSquare => "ms^2",
            Form::RateSquare => "ppm/(deg/s)",
            Form::RateCube => "ppm/(deg/s)^2",
            Form::Drift { .. } if gyro => "deg/h/h",
            Form::Drift { .. } => "ug/h",
            Form::Drift2 { .. } if gyro => "deg/h/h^2",
            Form::Drift2 { .. } => "ug/h^2",
            Form::Decay { .. } | Form::Step { .. } if gyro => "deg/h",
            Form::Decay { .. } | Form::Step { .. } => "ug",
            Form::ScaleDrift { .. } => "ppm/h",
            Form::ScaleStep { .. } => "ppm",
            Form::ThermalScale => "ppm/degC",
        }
    }

    /// A short name of the form on axis `i`, for a discovered effect's id (`fx_fz`).
    pub(crate) fn slug(self, sensor: Sensor, i: usize) -> String {
        let a = AXES[i];
        let s = if sensor == Sensor::Gyro { "w" } else { "f" };
        match self {
            Form::ForceSquare => format!("f{a}2"),
            Form::ForceProduct(j, k) => format!("f{}_f{}", AXES[j], AXES[k]),
            Form::ForceAbs => format!("abs_f{a}"),
            Form::ForceCube => format!("f{a}3"),
            Form::ForceRateSquare => format!("f{a}_w2"),
            Form::RateAbs => format!("abs_w{a}"),
            Form::RateSquare => format!("w{a}2"),
            Form::RateCube => format!("w{a}3"),
            Form::Drift { .. } => "drift".into(),
            Form::Drift2 { .. } => "drift2".into(),
            Form::Decay { tau, .. } => format!("decay_{tau:.0}s"),
            Form::Step { at } => format!("step_{at:.0}s"),
            Form::ScaleDrift { .. } => format!("{s}{a}_drift"),
            Form::ScaleStep { at } => format!("{s}{a}_step_{at:.0}s"),
            Form::ThermalScale => format!("{s}{a}_dtemp"),
        }
    }

    /// A short name of the form on every axis of its sensor (`f2` for `f_i^2`, `fx_fz` for a
    /// product, `step_42s`): a candidate's name in `not_observable`.
    pub(crate) fn family(self) -> String {
        match self {
            Form::ForceSquare => "f2".into(),
            Form::ForceProduct(j, k) => format!("f{}_f{}", AXES[j], AXES[k]),
            Form::ForceAbs => "abs_f".into(),
            Form::ForceCube => "f3".into(),
            Form::ForceRateSquare => "f_w2".into(),
            Form::RateAbs => "abs_w".into(),
            Form::RateSquare => "w2".into(),
            Form::RateCube => "w3".into(),
            Form::ScaleDrift { .. } => "scale_drift".into(),
            Form::ScaleStep { at } => format!("scale_step_{at:.0}s"),
            Form::ThermalScale => "scale_dtemp".into(),
            // Functions of time alone: the same on every axis.
            _ => self.slug(Sensor::Accel, 0),
        }
    }

    /// The motion that excites a term of this form (a draft effect file's `needs`).
    pub(crate) fn needs(self) -> &'static str {
        match self {
            Form::ForceSquare | Form::ForceAbs | Form::ForceCube => {
                "attitudes with gravity along the axis, up and down, and oblique ones"
            }
            Form::ForceProduct(..) => {
                "compound static attitudes with both axes of the product off vertical"
            }
            Form::ForceRateSquare => "rotation at several rates with gravity along the axis",
            Form::RateAbs | Form::RateSquare | Form::RateCube => {
                "rotation about the axis at several rates, in both directions"
            }
            Form::Drift { .. } | Form::Drift2 { .. } | Form::Decay { .. } | Form::Step { .. } => {
                "repeated attitudes spread over the recording's duration"
            }
            Form::ScaleDrift { .. } => "the same input repeated early and late in the recording",
            Form::ScaleStep { .. } => "the same input repeated before and after the instant",
            Form::ThermalScale => "the same input repeated at different temperatures",
        }
    }

    /// What a term of this form means, in an engineer's words (the dictionary).
    pub(crate) fn reading(self, sensor: Sensor) -> &'static str {
        let gyro = sensor == Sensor::Gyro;
        match self {
            Form::ForceSquare if gyro => {
                "the gyro output grows with the square of the specific force: g^2 (anisoelastic) sensitivity"
            }
            Form::ForceSquare => {
                "output grows with the square of the specific force along its own axis: an even-order nonlinearity (IEEE 1293 K2)"
            }
            Form::ForceProduct(..) if gyro => {
                "the gyro output follows a product of two specific-force components: g^2 (anisoelastic) cross sensitivity"
            }
            Form::ForceProduct(..) => {
                "the output follows a product of two specific-force components: cross-axis nonlinearity (IEEE 1293 cross-coupling)"
            }
            Form::ForceAbs if gyro => {
                "the gyro output depends on the magnitude of the specific force, not its sign"
            }
            Form::ForceAbs => {
                "the output depends on the sign of the specific force: scale asymmetry (+g and -g differ)"
            }
            Form::ForceCube => {
                "output grows with the cube of the specific force along its own axis: an odd third-order nonlinearity (IEEE 1293 K3)"
            }
            Form::ForceRateSquare => {
                "the output follows the second derivative of the specific force under rotation (-w x (w x f)): a timing error's second order (coefficient -tau^2/2)"
            }
            Form::RateAbs => "the output depends on the sign of the rate: scale asymmetry",
            Form::RateSquare => "the output grows with the square of the rate, whatever its sign",
            Form::RateCube => {
                "the scale factor grows with the square of the rate: a cubic scale nonlinearity"
            }
            Form::Drift { .. } => "the bias drifts linearly with time",
            Form::Drift2 { .. } => {
                "the bias drifts with the square of time: a drift that accelerates"
            }
            Form::Decay { .. } => "the bias decays with time since power-on: warm-up",
            Form::Step { .. } => "the bias jumps between two segments: a bias step",
            Form::ScaleDrift { .. } => "the scale factor drifts with time",
            Form::ScaleStep { .. } => {
                "the scale factor jumps between two segments: a scale-factor step"
            }
            Form::ThermalScale => {
                "the scale factor follows the temperature: a thermal scale coefficient"
            }
        }
    }
}
