//! `earth_rate`: the gyros sense the Earth's rotation, projected on the body axes.
//!
//! Fitted as the two components of the Earth's rate in the lab frame (north and up, deg/h;
//! 15.04 deg/h in all), which the attitude turns into body axes; the latitude follows from
//! their ratio (physics.md names it as the effect's optional parameter).

use super::{Descriptor, Effect, Param, Partials, Sensor, Signals};
use crate::{DEG, EARTH_RATE_RADPS};

/// The `earth_rate` effect.
#[derive(Debug)]
pub struct EarthRate;

/// The registry's instance.
pub static EARTH_RATE: EarthRate = EarthRate;

const HOUR: f64 = 3600.0;

/// The Earth's rate, deg/h: no component of it can be larger (the plausible range of both
/// parameters; a fit's uncertainty is the caller's to allow for).
const OMEGA_DPH: f64 = EARTH_RATE_RADPS / DEG * HOUR;

static PARAMS: [Param; 2] = [
    Param {
        name: "north_dph",
        unit: "deg/h",
        channel: None,
        needs: "static attitudes that turn the north direction through the gyro axes",
        max_abs: OMEGA_DPH,
    },
    Param {
        name: "up_dph",
        unit: "deg/h",
        channel: None,
        needs: "static attitudes that turn the vertical through the gyro axes",
        max_abs: OMEGA_DPH,
    },
];

impl EarthRate {
    /// The parameters that a site at `latitude_deg` gives: `[north_dph, up_dph]`.
    pub fn values(latitude_deg: f64) -> [f64; 2] {
        let (s, c) = (latitude_deg * DEG).sin_cos();
        [OMEGA_DPH * c, OMEGA_DPH * s]
    }

    /// The latitude (deg) and its standard uncertainty from fitted components and their
    /// 2x2 covariance.
    pub fn latitude_deg(north: f64, up: f64, cov: [[f64; 2]; 2]) -> (f64, f64) {
        let r2 = north * north + up * up;
        let lat = up.atan2(north) / DEG;
        if r2 <= 0.0 {
            return (lat, f64::INFINITY);
        }
        // d lat / d north = -up / r2, d lat / d up = north / r2 (radians).
        let g = [-up / r2, north / r2];
        let var = g[0] * g[0] * cov[0][0] + 2.0 * g[0] * g[1] * cov[0][1] + g[1] * g[1] * cov[1][1];
        (lat, var.max(0.0).sqrt() / DEG)
    }
}

/// What `earth_rate` is.
static DESCRIPTOR: Descriptor = Descriptor {
    id: "earth_rate",
    explanation: "the gyros sense the Earth's rotation (15 deg/h), projected on the body axes by the attitude",
    follows: "the attitude (static segments differ by the Earth rate's projection)",
    params: &PARAMS,
    sensors: &[Sensor::Gyro],
    nominal: false,
    sensed: false,
    station_side: false,
    uses_temperature: false,
    varies_at_rest: false,
};

impl Effect for EarthRate {
    fn descriptor(&self) -> Option<&'static Descriptor> {
        Some(&DESCRIPTOR)
    }

    fn regressors(&self, s: &Signals, out: &mut [Partials]) {
        // Body components of lab north and lab up, per deg/h, in deg/s.
        let per = 1.0 / HOUR;
        out[0] = Partials {
            gyro: s.c_bl.column(1) * per,
            ..Default::default()
        };
        out[1] = Partials {
            gyro: s.c_bl.column(2) * per,
            ..Default::default()
        };
    }
}
