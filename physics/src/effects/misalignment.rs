//! `accel_misalignment` and `gyro_misalignment`: off-diagonal terms of `K_a` and `K_g`
//! (cross-coupling; `<i><j>_mrad` = `K[i][j]` * 1000).

use super::{Effect, Param, Partials, Sensor, Signals};

/// Misalignment of one sensor triad.
#[derive(Debug)]
pub struct Misalignment {
    sensor: Sensor,
    params: &'static [Param],
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
};

/// `gyro_misalignment`.
pub static GYRO_MISALIGNMENT: Misalignment = Misalignment {
    sensor: Sensor::Gyro,
    params: &[
        p(Sensor::Gyro, "xy_mrad", 0, "rotate about Y"),
        p(Sensor::Gyro, "xz_mrad", 0, "rotate about Z"),
        p(Sensor::Gyro, "yx_mrad", 1, "rotate about X"),
        p(Sensor::Gyro, "yz_mrad", 1, "rotate about Z"),
        p(Sensor::Gyro, "zx_mrad", 2, "rotate about X"),
        p(Sensor::Gyro, "zy_mrad", 2, "rotate about Y"),
    ],
};

impl Effect for Misalignment {
    fn varies_at_rest(&self) -> bool {
        false
    }

    fn id(&self) -> &'static str {
        match self.sensor {
            Sensor::Accel => "accel_misalignment",
            Sensor::Gyro => "gyro_misalignment",
        }
    }

    fn explanation(&self) -> &'static str {
        match self.sensor {
            Sensor::Accel => {
                "the accelerometer axes are not exactly the body axes: each also senses the other two (cross-coupling)"
            }
            Sensor::Gyro => {
                "the gyro axes are not exactly the body axes: each also senses rotation about the other two (cross-coupling)"
            }
        }
    }

    fn follows(&self) -> &'static str {
        match self.sensor {
            Sensor::Accel => "the specific force along the other axes",
            Sensor::Gyro => "the rate about the other axes",
        }
    }

    fn params(&self) -> &'static [Param] {
        self.params
    }

    fn sensors(&self) -> &'static [Sensor] {
        self.sensor.only()
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
