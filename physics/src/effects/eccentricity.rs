//! `table_encoder_eccentricity`: a station-side error. Each table axis's angle encoder
//! reads the true angle plus a once-per-revolution error (an encoder disc mounted off its
//! axis), and the table reports, and servoes on, what its encoder reads.
//!
//! Convention: with `theta` the true angle of an axis, its encoder reads
//! `theta_enc = theta + e sin(theta + phi)`. The table's angle feedback is `theta_enc`, its
//! rate feedback `d theta_enc / dt = dtheta/dt (1 + e cos(theta + phi))`, and its servo
//! follows the commanded profile in encoder angle: the IMU turns with the true `theta`.
//! The error is fitted linearly, `e sin(theta + phi) = s sin(theta) + c cos(theta)`
//! (`s = e cos(phi)`, `c = e sin(phi)`; parameters `<axis>_sin_arcsec`,
//! `<axis>_cos_arcsec`); [`Eccentricity::amplitude_phase`] gives `e` and `phi` back.

use super::{Descriptor, Effect, Param, Partials, Sensor, Signals};
use crate::{AxisMotion, DEG, TableState};

/// One arc second, rad.
const ARCSEC: f64 = DEG / 3600.0;

/// The `table_encoder_eccentricity` effect.
#[derive(Debug)]
pub struct Eccentricity;

/// The registry's instance.
pub static TABLE_ENCODER_ECCENTRICITY: Eccentricity = Eccentricity;

/// Largest plausible eccentricity component, arcsec: a table's angle accuracy is a few
/// arc seconds for a navigation-grade table, a few arc minutes for the cheapest (5 arcmin
/// is a 30 um offset on a 20 mm encoder disc).
const MAX_ARCSEC: f64 = 300.0;

const fn p(name: &'static str, needs: &'static str) -> Param {
    Param {
        name,
        unit: "arcsec",
        channel: None,
        needs,
        max_abs: MAX_ARCSEC,
    }
}

const OUTER: &str = "outer-axis angles spread around the turn (a full revolution, or attitudes 90 deg apart) that turn gravity through the accelerometers";
const INNER: &str = "inner-axis angles spread around the turn (a full revolution, or attitudes 90 deg apart) that turn gravity through the accelerometers";

static PARAMS: [Param; 4] = [
    p("outer_sin_arcsec", OUTER),
    p("outer_cos_arcsec", OUTER),
    p("inner_sin_arcsec", INNER),
    p("inner_cos_arcsec", INNER),
];

impl Eccentricity {
    /// Amplitude `e` (arcsec) and phase `phi` (deg) of `s sin(theta) + c cos(theta)`, each
    /// with its standard uncertainty from the 2x2 covariance of `(s, c)`:
    /// `((e, u_e), (phi_deg, u_phi_deg))`. The phase is undetermined (infinite `u`) at
    /// zero amplitude.
    pub fn amplitude_phase(s: f64, c: f64, cov: [[f64; 2]; 2]) -> ((f64, f64), (f64, f64)) {
        let e = s.hypot(c);
        let phi = c.atan2(s) / DEG;
        let var = |g: [f64; 2]| {
            (g[0] * g[0] * cov[0][0] + 2.0 * g[0] * g[1] * cov[0][1] + g[1] * g[1] * cov[1][1])
                .max(0.0)
                .sqrt()
        };
        if e <= 0.0 {
            return (
                (0.0, var([1.0, 0.0]).max(var([0.0, 1.0]))),
                (phi, f64::INFINITY),
            );
        }
        let u_e = var([s / e, c / e]);
        // d phi / d s = -c / e^2, d phi / d c = s / e^2 (radians).
        let u_phi = var([-c / (e * e), s / (e * e)]) / DEG;
        ((e, u_e), (phi, u_phi))
    }

    /// The linear parameters `(s, c)` of an amplitude (arcsec) and phase (deg).
    pub fn components(e_arcsec: f64, phi_deg: f64) -> (f64, f64) {
        let (sp, cp) = (phi_deg * DEG).sin_cos();
        (e_arcsec * cp, e_arcsec * sp)
    }
}

/// What `table_encoder_eccentricity` is.
static DESCRIPTOR: Descriptor = Descriptor {
    id: "table_encoder_eccentricity",
    explanation: "the table's angle encoders are eccentric: the reported angle and rate carry an error that repeats once per revolution (a station error, not the IMU's)",
    follows: "the sine and cosine of a table angle (once per revolution)",
    params: &PARAMS,
    sensors: &[Sensor::Accel, Sensor::Gyro],
    nominal: false,
    sensed: false,
    station_side: true,
    uses_temperature: false,
    varies_at_rest: false,
};

impl Effect for Eccentricity {
    fn descriptor(&self) -> Option<&'static Descriptor> {
        Some(&DESCRIPTOR)
    }

    /// The signals are those of the reported (encoder) motion; the true motion differs by
    /// `dtheta = -eps(theta)`, `domega = -omega eps'(theta)` to first order, and the ideal
    /// outputs change by their derivatives with respect to the angle and the rate.
    fn regressors(&self, s: &Signals, out: &mut [Partials]) {
        let t = &s.table;
        for (k, (m, a_b)) in [(t.outer, s.outer_b), (t.inner, s.inner_b)]
            .into_iter()
            .enumerate()
        {
            // Turning the platform by dtheta about a turns lab vectors in body axes by
            // -dtheta about it: du/dtheta = u x a.
            let mut d_angle = Partials {
                accel: s.f_b.cross(&a_b),
                gyro: s.earth_b.cross(&a_b) / DEG,
            };
            if k == 1 {
                // w_P holds R(a_i, th_i)^T a_o dth_o: the inner angle turns it.
                d_angle.gyro -= s.inner_b.cross(&s.outer_b) * t.outer.rate / DEG;
            }
            let d_rate = a_b / DEG;
            let (sn, cs) = m.angle.sin_cos();
            out[2 * k] = Partials {
                accel: d_angle.accel * (-sn * ARCSEC),
                gyro: (d_angle.gyro * -sn - d_rate * (m.rate * cs)) * ARCSEC,
            };
            out[2 * k + 1] = Partials {
                accel: d_angle.accel * (-cs * ARCSEC),
                gyro: (d_angle.gyro * -cs + d_rate * (m.rate * sn)) * ARCSEC,
            };
        }
    }

    /// Nothing on the IMU's outputs: the simulator turns the IMU with the true motion
    /// ([`EncoderError::true_motion`]).
    fn forward(&self, _values: &[f64], _s: &Signals) -> Partials {
        Partials::default()
    }
}

/// The encoder errors of both table axes, `[s, c]` per axis in radians: what the simulator
/// needs to turn the table's (encoder) motion into the true motion.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct EncoderError {
    /// Outer axis `[s, c]`, rad.
    pub outer: [f64; 2],
    /// Inner axis `[s, c]`, rad.
    pub inner: [f64; 2],
}

impl EncoderError {
    /// From the effect's parameter values (arcsec, in the registry's order).
    pub fn from_values(values: &[f64]) -> Self {
        EncoderError {
            outer: [values[0] * ARCSEC, values[1] * ARCSEC],
            inner: [values[2] * ARCSEC, values[3] * ARCSEC],
        }
    }

    /// Whether both axes are exact.
    pub fn is_zero(&self) -> bool {
        self.outer == [0.0; 2] && self.inner == [0.0; 2]
    }

    /// The true motion of a table whose encoders read `reported` (exact: the angle by
    /// fixed-point iteration, the rate and acceleration by differentiating
    /// `theta_enc = theta + eps(theta)`).
    pub fn true_motion(&self, reported: &TableState) -> TableState {
        TableState {
            outer: true_axis(self.outer, &reported.outer),
            inner: true_axis(self.inner, &reported.inner),
        }
    }
}

/// One axis: `theta + eps(theta) = theta_enc`, `eps = s sin + c cos`.
fn true_axis([s, c]: [f64; 2], enc: &AxisMotion) -> AxisMotion {
    if s == 0.0 && c == 0.0 {
        return *enc;
    }
    let eps = |th: f64| s * th.sin() + c * th.cos();
    // |eps'| <= e << 1: a contraction, converged to rounding in a few steps.
    let mut th = enc.angle - eps(enc.angle);
    for _ in 0..20 {
        let next = enc.angle - eps(th);
        let done = (next - th).abs() <= 1e-16 * enc.angle.abs().max(1.0);
        th = next;
        if done {
            break;
        }
    }
    let (sn, cs) = th.sin_cos();
    let d1 = 1.0 + s * cs - c * sn;
    let rate = enc.rate / d1;
    // rate_enc = rate (1 + eps'); accel_enc = accel (1 + eps') + rate^2 eps'', eps'' = -eps.
    let accel = (enc.accel + rate * rate * eps(th)) / d1;
    AxisMotion {
        angle: th,
        rate,
        accel,
    }
}
