//! `g_sensitivity`: the gyro bias depends on specific force (`G`; `<i><j>_dps_per_g` =
//! `G[i][j]` * g).

use super::{Descriptor, Effect, Param, Partials, Sensor, Signals};

/// The `g_sensitivity` effect.
#[derive(Debug)]
pub struct GSensitivity;

/// The registry's instance.
pub static G_SENSITIVITY: GSensitivity = GSensitivity;

/// Largest plausible g-sensitivity, deg/s per g (consumer MEMS gyros: up to about 0.1;
/// the range allows an order of magnitude more).
const MAX_DPS_PER_G: f64 = 1.0;

const fn p(name: &'static str, i: usize, needs: &'static str) -> Param {
    Param {
        name,
        unit: "deg/s per g",
        channel: Some((Sensor::Gyro, i)),
        needs,
        max_abs: MAX_DPS_PER_G,
    }
}

static PARAMS: [Param; 9] = [
    p("xx_dps_per_g", 0, "attitudes with gravity along +X and -X"),
    p("xy_dps_per_g", 0, "attitudes with gravity along +Y and -Y"),
    p("xz_dps_per_g", 0, "attitudes with gravity along +Z and -Z"),
    p("yx_dps_per_g", 1, "attitudes with gravity along +X and -X"),
    p("yy_dps_per_g", 1, "attitudes with gravity along +Y and -Y"),
    p("yz_dps_per_g", 1, "attitudes with gravity along +Z and -Z"),
    p("zx_dps_per_g", 2, "attitudes with gravity along +X and -X"),
    p("zy_dps_per_g", 2, "attitudes with gravity along +Y and -Y"),
    p("zz_dps_per_g", 2, "attitudes with gravity along +Z and -Z"),
];

/// What `g_sensitivity` is.
static DESCRIPTOR: Descriptor = Descriptor {
    id: "g_sensitivity",
    explanation: "the gyro bias depends on the specific force: it changes with the attitude relative to gravity",
    follows: "the attitude relative to gravity (specific force)",
    params: &PARAMS,
    sensors: &[Sensor::Gyro],
    nominal: false,
    sensed: false,
    station_side: false,
    uses_temperature: false,
    varies_at_rest: false,
};

impl Effect for GSensitivity {
    fn descriptor(&self) -> Option<&'static Descriptor> {
        Some(&DESCRIPTOR)
    }

    fn regressors(&self, s: &Signals, out: &mut [Partials]) {
        for i in 0..3 {
            for j in 0..3 {
                out[3 * i + j] = Partials::axis(Sensor::Gyro, i, s.f_b[j] / s.g);
            }
        }
    }
}
