//! `accel_misalignment` and `gyro_misalignment`: off-diagonal terms of `K_a` and `K_g`
//! (cross-coupling; `<i><j>_mrad` = `K[i][j]` * 1000).

use super::{Descriptor, Effect, Param, Partials, Sensor, Signals};

/// Misalignment of one sensor triad.
#[derive(Debug)]
pub struct Misalignment {
    sensor: Sensor,
    descriptor: &'static Descriptor,
}

/// Index pairs `(i, j)` of the six off-diagonal terms, in the catalogue's order.
const PAIRS: [(usize, usize); 6] = [(0, 1), (0, 2), (1, 0), (1, 2), (2, 0), (2, 1)];

/// Largest plausible cross-coupling, mrad (about 3 deg: a consumer part soldered askew on
/// its board).
const MAX_MRAD: f64 = 50.0;

const fn p(sensor: Sensor, name: &'static str, i: usize, needs: &'static str) -> Param {
    Param {
        name,
        unit: "mrad",
        channel: Some((sensor, i)),
        needs,
        max_abs: MAX_MRAD,
    }
}

/// `accel_misalignment`.
pub static ACCEL_MISALIGNMENT: Misalignment = Misalignment {
    sensor: Sensor::Accel,
    descriptor: &Descriptor {
        id: "accel_misalignment",
        explanation: "the accelerometer axes are not exactly the body axes: each also senses the other two (cross-coupling)",
        follows: "the specific force along the other axes",
        params: &[
            p(
                Sensor::Accel,
                "xy_mrad",
                0,
                "an attitude with gravity along Y",
            ),
            p(
                Sensor::Accel,
                "xz_mrad",
                0,
                "an attitude with gravity along Z",
            ),
            p(
                Sensor::Accel,
                "yx_mrad",
                1,
                "an attitude with gravity along X",
            ),
            p(
                Sensor::Accel,
                "yz_mrad",
                1,
                "an attitude with gravity along Z",
            ),
            p(
                Sensor::Accel,
                "zx_mrad",
                2,
                "an attitude with gravity along X",
            ),
            p(
                Sensor::Accel,
                "zy_mrad",
                2,
                "an attitude with gravity along Y",
            ),
        ],
        sensors: Sensor::Accel.only(),
        nominal: false,
        sensed: false,
        station_side: false,
        uses_temperature: false,
        varies_at_rest: false,
    },
};

/// `gyro_misalignment`.
pub static GYRO_MISALIGNMENT: Misalignment = Misalignment {
    sensor: Sensor::Gyro,
    descriptor: &Descriptor {
        id: "gyro_misalignment",
        explanation: "the gyro axes are not exactly the body axes: each also senses rotation about the other two (cross-coupling)",
        follows: "the rate about the other axes",
        params: &[
            p(Sensor::Gyro, "xy_mrad", 0, "rotate about Y"),
            p(Sensor::Gyro, "xz_mrad", 0, "rotate about Z"),
            p(Sensor::Gyro, "yx_mrad", 1, "rotate about X"),
            p(Sensor::Gyro, "yz_mrad", 1, "rotate about Z"),
            p(Sensor::Gyro, "zx_mrad", 2, "rotate about X"),
            p(Sensor::Gyro, "zy_mrad", 2, "rotate about Y"),
        ],
        sensors: Sensor::Gyro.only(),
        nominal: false,
        sensed: false,
        station_side: false,
        uses_temperature: false,
        varies_at_rest: false,
    },
};

impl Effect for Misalignment {
    fn descriptor(&self) -> Option<&'static Descriptor> {
        Some(self.descriptor)
    }

    fn regressors(&self, s: &Signals, out: &mut [Partials]) {
        let input = match self.sensor {
            Sensor::Accel => s.f_b,
            Sensor::Gyro => s.w_ib_dps(),
        };
        for (k, &(i, j)) in PAIRS.iter().enumerate() {
            out[k] = Partials::axis(self.sensor, i, input[j] * 1e-3);
        }
    }
}

/// The `(i, j)` of a misalignment parameter index.
pub fn pair(k: usize) -> (usize, usize) {
    PAIRS[k]
}
