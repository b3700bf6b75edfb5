//! `lever_arm`: accelerometer sensing points away from the table's centre of rotation
//! feel centripetal and tangential acceleration (mounting offset and size effect).

use super::{Descriptor, Effect, Param, Partials, Sensor, Signals};

/// The `lever_arm` effect: `r<i><j>_mm` is the j-component (body axes) of accelerometer
/// i's sensing point, mm.
#[derive(Debug)]
pub struct LeverArm;

/// The registry's instance.
pub static LEVER_ARM: LeverArm = LeverArm;

/// Largest plausible sensing-point coordinate, mm: an IMU mounted anywhere on a table's
/// platform is within 300 mm of the axes' intersection.
const MAX_MM: f64 = 300.0;

const fn p(name: &'static str, i: usize, needs: &'static str) -> Param {
    Param {
        name,
        unit: "mm",
        channel: Some((Sensor::Accel, i)),
        needs,
        max_abs: MAX_MM,
    }
}

// M_ij = [dw]x_ij + w_i w_j - delta_ij |w|^2: the diagonal needs rotation about another
// axis; an off-diagonal term needs angular acceleration about the third axis or rotation
// about an axis between i and j.
static PARAMS: [Param; 9] = [
    p("rxx_mm", 0, "rotate about Y or Z"),
    p(
        "rxy_mm",
        0,
        "accelerate about Z, or rotate about an axis between X and Y",
    ),
    p(
        "rxz_mm",
        0,
        "accelerate about Y, or rotate about an axis between X and Z",
    ),
    p(
        "ryx_mm",
        1,
        "accelerate about Z, or rotate about an axis between X and Y",
    ),
    p("ryy_mm", 1, "rotate about X or Z"),
    p(
        "ryz_mm",
        1,
        "accelerate about X, or rotate about an axis between Y and Z",
    ),
    p(
        "rzx_mm",
        2,
        "accelerate about Y, or rotate about an axis between X and Z",
    ),
    p(
        "rzy_mm",
        2,
        "accelerate about X, or rotate about an axis between Y and Z",
    ),
    p("rzz_mm", 2, "rotate about X or Y"),
];

/// What `lever_arm` is.
static DESCRIPTOR: Descriptor = Descriptor {
    id: "lever_arm",
    explanation: "the accelerometers' sensing points are not at the table's centre of rotation: they feel centripetal and tangential acceleration",
    follows: "the rate squared and the angular acceleration",
    params: &PARAMS,
    sensors: &[Sensor::Accel],
    nominal: false,
    sensed: true,
    station_side: false,
    uses_temperature: false,
    varies_at_rest: false,
};

impl Effect for LeverArm {
    fn descriptor(&self) -> Option<&'static Descriptor> {
        Some(&DESCRIPTOR)
    }

    fn regressors(&self, s: &Signals, out: &mut [Partials]) {
        let m = s.lever_matrix();
        for i in 0..3 {
            for j in 0..3 {
                out[3 * i + j] = Partials::axis(Sensor::Accel, i, m[(i, j)] * 1e-3);
            }
        }
    }
}
