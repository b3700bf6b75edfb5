//! The Earth's rate as explain tries it: physics it already knows, not a free vector.
//!
//! The Earth turns at 15.041 deg/h about its axis and the manifest gives the site's
//! latitude, so the only legitimate unknown is the table's true heading (the azimuth of
//! its axes, which a lab may not know to the degree). The candidate has two columns: the
//! Earth's rate at the manifest's latitude as the station believes it is oriented (its
//! coefficient `scale` is 1 when the physics holds) and the rate along the lab's East axis
//! (`east_dph`), which a heading error turns the horizontal component into. A `scale` far
//! from 1 means the gyros see an attitude-dependent rate that is not the Earth's; the final
//! model then holds the Earth's rate at its physical value, and what mimics it is left to
//! the tests for what remains unexplained.

use ratecal_physics::DEG;
use ratecal_physics::effects::{EarthRate, Effect, Param, Partials, Sensor, Signals};

/// The candidate (its id is the registry's `earth_rate`).
#[derive(Debug)]
pub(crate) struct EarthHeld;

/// The instance explain adds to its layout.
pub(crate) static EARTH_HELD: EarthHeld = EarthHeld;

static PARAMS: [Param; 2] = [
    Param {
        name: "scale",
        unit: "1",
        channel: None,
        needs: "static attitudes that turn the Earth's axis through the gyro axes",
        // Judged against 1 by explain itself, not by a magnitude.
        max_abs: f64::INFINITY,
    },
    Param {
        name: "east_dph",
        unit: "deg/h",
        channel: None,
        needs: "static attitudes that turn the lab's East axis through the gyro axes",
        // No component of the Earth's rate exceeds it.
        max_abs: ratecal_physics::EARTH_RATE_RADPS / DEG * 3600.0,
    },
];

impl Effect for EarthHeld {
    fn varies_at_rest(&self) -> bool {
        false
    }

    fn id(&self) -> &'static str {
        "earth_rate"
    }

    fn explanation(&self) -> &'static str {
        ratecal_physics::effect("earth_rate").map_or("", |e| e.explanation())
    }

    fn follows(&self) -> &'static str {
        ratecal_physics::effect("earth_rate").map_or("", |e| e.follows())
    }

    fn params(&self) -> &'static [Param] {
        &PARAMS
    }

    fn sensors(&self) -> &'static [Sensor] {
        &[Sensor::Gyro]
    }

    fn regressors(&self, s: &Signals, out: &mut [Partials]) {
        out[0] = Partials {
            gyro: s.earth_b / DEG,
            ..Default::default()
        };
        out[1] = Partials {
            gyro: s.c_bl.column(0) / 3600.0,
            ..Default::default()
        };
    }
}

/// The horizontal and vertical components of the Earth's rate at a latitude, deg/h.
pub(crate) fn components(latitude_deg: f64) -> (f64, f64) {
    let [n, u] = EarthRate::values(latitude_deg);
    (n, u)
}

/// The heading (deg) a fitted East component gives, with its u: the lab's North axis
/// points `heading` east of true north, so true north has an East component of
/// `-h sin(heading)` in lab axes. `None` when the component exceeds the horizontal rate
/// itself by more than its uncertainty allows.
pub(crate) fn heading_deg(east_dph: f64, u_dph: f64, latitude_deg: f64) -> Option<(f64, f64)> {
    let (h, _) = components(latitude_deg);
    if h <= 0.0 {
        return None;
    }
    let x = -east_dph / h;
    if x.abs() > 1.0 + 3.0 * u_dph / h {
        return None;
    }
    let x = x.clamp(-1.0, 1.0);
    let psi = x.asin();
    let u = u_dph / (h * psi.cos().max(1e-3));
    Some((psi / DEG, u / DEG))
}
