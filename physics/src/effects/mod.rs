//! The effect registry: every term of the IMU measurement model (spec/physics.md), the
//! nominal ones (bias, scale) and every catalogue effect, as one piece of code each.
//!
//! An effect knows its canonical id and parameters, explains itself in one line, gives
//! its forward contribution (what the simulator adds to the ideal outputs) and its
//! regressors (the partial derivatives of the six outputs with respect to its parameters),
//! all from the same [`Signals`] of one instant. The simulator, the station loader, the
//! checker, the analysis and explain read this one list: adding an effect is adding a
//! file here and a line to [`REGISTRY`].

mod asymmetry;
mod bias;
mod clock_rate;
mod earth_rate;
mod eccentricity;
mod g_sensitivity;
mod lever_arm;
mod misalignment;
mod model;
mod nonlinearity;
mod scale;
mod scale_thermal;
mod second_order;
mod signals;
mod thermal;
mod time_offset;

pub use clock_rate::ClockRate;
pub use earth_rate::EarthRate;
pub use eccentricity::{Eccentricity, EncoderError};
pub use misalignment::pair as misalignment_pair;
pub use model::{ImuModel, Term};
pub use signals::Signals;

use crate::Vec3;

/// Which sensor triad an output or a parameter belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Sensor {
    /// Accelerometers, m/s^2.
    Accel,
    /// Gyroscopes, deg/s.
    Gyro,
}

impl Sensor {
    /// This sensor alone: the `sensors()` of an effect on one triad.
    pub const fn only(self) -> &'static [Sensor] {
        match self {
            Sensor::Accel => &[Sensor::Accel],
            Sensor::Gyro => &[Sensor::Gyro],
        }
    }

    /// `accel` or `gyro`.
    pub fn name(self) -> &'static str {
        match self {
            Sensor::Accel => "accel",
            Sensor::Gyro => "gyro",
        }
    }
}

/// One parameter of an effect, as physics.md names it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Param {
    /// Canonical name, e.g. `rxz_mm`.
    pub name: &'static str,
    /// Unit as reported, e.g. `mm`.
    pub unit: &'static str,
    /// The output channels it acts on: `(sensor, axis)`; `None` for every axis of the
    /// effect's sensors.
    pub channel: Option<(Sensor, usize)>,
    /// The motion that excites it, in an engineer's words ("rotate about Z").
    pub needs: &'static str,
    /// Its physically plausible range, `-max_abs..=max_abs` in `unit`: the largest
    /// magnitude a real part (consumer to navigation grade; for a station-side term, a
    /// real rate table) can have. A fit beyond it is not that physics. Infinite for a
    /// user effect, which declares none.
    pub max_abs: f64,
}

impl Param {
    /// Whether `value` (in `unit`) lies within the plausible range.
    pub fn plausible(&self, value: f64) -> bool {
        value.abs() <= self.max_abs
    }
}

/// The six output channels' partial derivatives with respect to one parameter.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Partials {
    /// d(accel outputs)/d(param), m/s^2 per parameter unit.
    pub accel: Vec3,
    /// d(gyro outputs)/d(param), deg/s per parameter unit.
    pub gyro: Vec3,
}

impl Partials {
    /// `v` on axis `i` of `sensor`, zero on every other output.
    #[inline]
    pub fn axis(sensor: Sensor, i: usize, v: f64) -> Self {
        let mut p = Partials::default();
        match sensor {
            Sensor::Accel => p.accel[i] = v,
            Sensor::Gyro => p.gyro[i] = v,
        }
        p
    }

    /// The partials of one sensor.
    #[inline]
    pub fn of(&self, s: Sensor) -> &Vec3 {
        match s {
            Sensor::Accel => &self.accel,
            Sensor::Gyro => &self.gyro,
        }
    }
}

/// What an effect is, apart from its maths: its id, its parameters, its words for a report
/// and how the simulator and the analysis treat it. Every registry effect has one, a
/// constant, that [`Effect::descriptor`] returns.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Descriptor {
    /// Canonical id (`lever_arm`; the nominal terms are `accel_bias`, `gyro_scale`, ...).
    pub id: &'static str,
    /// What physics it is, in one line an engineer reads in a report.
    pub explanation: &'static str,
    /// What a residual that this term explains correlates with, for locating it.
    pub follows: &'static str,
    /// Its parameters, in the catalogue's order.
    pub params: &'static [Param],
    /// The sensors whose outputs it touches.
    pub sensors: &'static [Sensor],
    /// Whether it belongs to the nominal model (bias, scale) rather than the catalogue.
    pub nominal: bool,
    /// Whether its accelerometer contribution is part of the specific force the
    /// accelerometers sense (the lever arm), to which scale and cross-coupling then apply
    /// (`a = K_a s + b_a`).
    pub sensed: bool,
    /// Whether it is an error of the station (the table's feedback), not of the IMU:
    /// reports call it a station error, and the simulator applies it to the table's
    /// motion rather than to the IMU's outputs.
    pub station_side: bool,
    /// Whether its regressors read the IMU temperature (`Signals::dtemp_c`): the analysis
    /// then needs the reference temperature before the samples pass.
    pub uses_temperature: bool,
    /// Whether its regressors can change while the motion does not: they read the time
    /// stamp or the temperature (`Signals::t_s`, `Signals::dtemp_c`). The analysis
    /// evaluates a term that says no once for a stretch at rest. Yes is always right; a
    /// term that says no must be a function of the motion alone.
    pub varies_at_rest: bool,
}

/// One term of the measurement model: a [`Descriptor`] and its maths.
///
/// A registry effect answers [`Effect::descriptor`], and the accessors (`id`, `params`,
/// ...) read it. An effect made at run time (explain's user effects and probes) has no
/// constant descriptor: it answers the accessors itself, and the flags it does not answer
/// keep their catalogue defaults.
pub trait Effect: Send + Sync + std::fmt::Debug {
    /// What it is, apart from its maths (`None`: an effect made at run time, which answers
    /// the accessors itself).
    fn descriptor(&self) -> Option<&'static Descriptor> {
        None
    }
    /// Canonical id: [`Descriptor::id`].
    fn id(&self) -> &'static str {
        described(self).id
    }
    /// [`Descriptor::explanation`].
    fn explanation(&self) -> &'static str {
        described(self).explanation
    }
    /// [`Descriptor::follows`].
    fn follows(&self) -> &'static str {
        described(self).follows
    }
    /// Its parameters, in the catalogue's order: [`Descriptor::params`].
    fn params(&self) -> &'static [Param] {
        described(self).params
    }
    /// [`Descriptor::nominal`] (no for an effect made at run time).
    fn nominal(&self) -> bool {
        self.descriptor().is_some_and(|d| d.nominal)
    }
    /// Partial derivatives of the outputs with respect to each parameter at this instant,
    /// written to `out` (as long as [`Effect::params`]).
    fn regressors(&self, s: &Signals, out: &mut [Partials]);
    /// What this term adds to the ideal outputs for these parameter values. The default is
    /// linear in the parameters; effects that are not override it.
    fn forward(&self, values: &[f64], s: &Signals) -> Partials {
        // Most effects have three parameters or four: their scratch is that short (the
        // simulator calls this for every term at every sample that moves).
        match self.params().len() {
            n @ 0..=4 => linear::<4>(self, n, values, s),
            n => linear::<16>(self, n, values, s),
        }
    }
    /// [`Descriptor::sensed`] (no for an effect made at run time).
    fn sensed(&self) -> bool {
        self.descriptor().is_some_and(|d| d.sensed)
    }
    /// How much later than the motion the samples are stamped, s (the time offset).
    fn delay_s(&self, _values: &[f64]) -> f64 {
        0.0
    }
    /// How much later than the motion the sample stamped `t_s` (the IMU's clock, s) is
    /// stamped, s: the simulator evaluates the motion at `t_s - delay_at_s`. The default
    /// is the constant [`Effect::delay_s`]; the clock rate's delay grows with `t_s`.
    fn delay_at_s(&self, values: &[f64], _t_s: f64) -> f64 {
        self.delay_s(values)
    }
    /// [`Descriptor::station_side`] (no for an effect made at run time).
    fn station_side(&self) -> bool {
        self.descriptor().is_some_and(|d| d.station_side)
    }
    /// The sensors whose outputs it touches: [`Descriptor::sensors`].
    fn sensors(&self) -> &'static [Sensor] {
        described(self).sensors
    }
    /// [`Descriptor::uses_temperature`] (no for an effect made at run time).
    fn uses_temperature(&self) -> bool {
        self.descriptor().is_some_and(|d| d.uses_temperature)
    }
    /// [`Descriptor::varies_at_rest`] (yes, always right, for an effect made at run time).
    fn varies_at_rest(&self) -> bool {
        self.descriptor().is_none_or(|d| d.varies_at_rest)
    }
}

/// The descriptor of an effect that reads its accessors from it.
fn described<E: Effect + ?Sized>(e: &E) -> &'static Descriptor {
    e.descriptor()
        .expect("an effect without a descriptor answers id, explanation, follows, params and sensors itself")
}

/// Every effect, the nominal terms first, then the catalogue in physics.md's order, then
/// the model-equation terms of the IEEE standards (1293, 952, 528) that a rate table
/// excites.
pub static REGISTRY: &[&dyn Effect] = &[
    &bias::ACCEL_BIAS,
    &scale::ACCEL_SCALE,
    &bias::GYRO_BIAS,
    &scale::GYRO_SCALE,
    &earth_rate::EARTH_RATE,
    &lever_arm::LEVER_ARM,
    &time_offset::TIME_OFFSET,
    &misalignment::ACCEL_MISALIGNMENT,
    &misalignment::GYRO_MISALIGNMENT,
    &g_sensitivity::G_SENSITIVITY,
    &thermal::GYRO_THERMAL_DRIFT,
    &thermal::ACCEL_THERMAL_DRIFT,
    &nonlinearity::GYRO_SCALE_NONLINEARITY,
    &second_order::ACCEL_SECOND_ORDER,
    &asymmetry::ACCEL_SCALE_ASYMMETRY,
    &asymmetry::GYRO_SCALE_ASYMMETRY,
    &scale_thermal::ACCEL_SCALE_THERMAL,
    &scale_thermal::GYRO_SCALE_THERMAL,
    &clock_rate::CLOCK_RATE,
    &eccentricity::TABLE_ENCODER_ECCENTRICITY,
];

/// Looks an effect up by its canonical id.
pub fn effect(id: &str) -> Option<&'static dyn Effect> {
    REGISTRY.iter().copied().find(|e| e.id() == id)
}

/// The catalogue ids (every effect that is not a nominal term), in physics.md's order.
pub fn catalogue() -> impl Iterator<Item = &'static dyn Effect> {
    REGISTRY.iter().copied().filter(|e| !e.nominal())
}

/// Per-axis parameters `x`, `y`, `z` of one sensor, with a unit, what excites them and
/// their plausible magnitude.
macro_rules! per_axis {
    ($sensor:expr, $unit:expr, $needs:expr, $max_abs:expr) => {
        [
            $crate::effects::Param {
                name: "x",
                unit: $unit,
                channel: Some(($sensor, 0)),
                needs: $needs[0],
                max_abs: $max_abs,
            },
            $crate::effects::Param {
                name: "y",
                unit: $unit,
                channel: Some(($sensor, 1)),
                needs: $needs[1],
                max_abs: $max_abs,
            },
            $crate::effects::Param {
                name: "z",
                unit: $unit,
                channel: Some(($sensor, 2)),
                needs: $needs[2],
                max_abs: $max_abs,
            },
        ]
    };
}
pub(crate) use per_axis;

/// The default [`Effect::forward`]: the `n` regressors (at most `N`) times the values.
fn linear<const N: usize>(
    fx: &(impl Effect + ?Sized),
    n: usize,
    values: &[f64],
    s: &Signals,
) -> Partials {
    let mut parts = [Partials::default(); N];
    fx.regressors(s, &mut parts[..n]);
    let mut out = Partials::default();
    for (v, p) in values.iter().zip(&parts[..n]) {
        out.accel += p.accel * *v;
        out.gyro += p.gyro * *v;
    }
    out
}
#[cfg(test)]
mod tests;
