//! `accel_second_order`: each accelerometer output gains `K2_i f_i^2 / g` (IEEE 1293's
//! second-order nonlinearity coefficient, ug/g^2).

use super::{Descriptor, Effect, Param, Partials, Sensor, Signals, per_axis};

/// The `accel_second_order` effect.
#[derive(Debug)]
pub struct SecondOrder;

/// The registry's instance.
pub static ACCEL_SECOND_ORDER: SecondOrder = SecondOrder;

static PARAMS: [Param; 3] = per_axis!(
    Sensor::Accel,
    "ug/g^2",
    [
        "attitudes with gravity along X and across it (the square of the specific force changes)",
        "attitudes with gravity along Y and across it (the square of the specific force changes)",
        "attitudes with gravity along Z and across it (the square of the specific force changes)"
    ],
    // Navigation-grade pendulous accelerometers: 10 to 50 ug/g^2; consumer MEMS: a
    // nonlinearity of 0.5 % of a 2 g full scale is about 2500 ug/g^2.
    5000.0
);

/// What `accel_second_order` is.
static DESCRIPTOR: Descriptor = Descriptor {
    id: "accel_second_order",
    explanation: "the accelerometer output grows with the square of the specific force (second-order nonlinearity, K2)",
    follows: "the square of the specific force along the axis",
    params: &PARAMS,
    sensors: &[Sensor::Accel],
    nominal: false,
    sensed: false,
    station_side: false,
    uses_temperature: false,
    varies_at_rest: false,
};

impl Effect for SecondOrder {
    fn descriptor(&self) -> Option<&'static Descriptor> {
        Some(&DESCRIPTOR)
    }

    /// `K2 [ug/g^2] * 1e-6 g (f_i / g)^2 = K2 * 1e-6 f_i^2 / g` (m/s^2), with `g` the
    /// station's gravity: the `g` of the unit is the local one, as for the g-sensitivity.
    fn regressors(&self, s: &Signals, out: &mut [Partials]) {
        for (i, p) in out.iter_mut().enumerate() {
            *p = Partials::axis(Sensor::Accel, i, 1e-6 * s.f_b[i] * s.f_b[i] / s.g);
        }
    }
}
