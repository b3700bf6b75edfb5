//! Which terms each reported quantity's budget has, from what the station file states
//! (`docs/certificate.md`, The budget). A Type B figure the station file does not give is a
//! term "not stated", never 0.
//!
//! - every quantity: the fit's Type A standard uncertainty, with the degrees of freedom of
//!   the noise estimate it rests on: the one-second block means of the segments that
//!   determine the quantity, less one per segment ([`super::type_a_dof`]);
//! - `gyro.scale.*` (ppm): the table's rate accuracy `a` (a ratio of the rate),
//!   rectangular, `u = a / sqrt(3)`, sensitivity 1;
//! - `accel.bias.*` (m/s^2): the table's position accuracy and axis orthogonality (angles
//!   `a`), rectangular, through the gravity projection: `u = g a / sqrt(3)`, sensitivity
//!   `g` per rad;
//! - `accel.scale.*` (ppm): the site's gravity (a standard uncertainty `u_g`), normal,
//!   `u = 1e6 u_g / g`, sensitivity `1e6 / g` ppm per m/s^2;
//! - `accel.misalignment.*`, `gyro.misalignment.*` (mrad or their unit): the table's
//!   position accuracy (accelerometers only) and axis orthogonality, rectangular, sensitivity
//!   1 rad/rad;
//! - `gyro.scale.*` (ppm): the DAQ clock's accuracy `a` (`daq.clock_accuracy`, a ratio): a
//!   rate is an angle over a time, so rectangular, `u = a / sqrt(3)`, sensitivity 1;
//! - `accel.bias.*`, `gyro.bias.*`, `accel.scale.*`, `gyro.scale.*`: temperature, the IMU's
//!   stated coefficient `c` (`imu.temperature_coefficients`, per degC) times the lab's
//!   temperature stability `dT` (`site.temperature_stability`, a bound): rectangular,
//!   `u = |c| dT / sqrt(3)`, sensitivity `c`. Not stated unless both are.

use super::{Budget, Evaluation, Term};
use serde::{Deserialize, Serialize};

/// What the station file states for the budget (`None`: not stated).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Stated {
    /// `table.rate_accuracy` as a ratio (10 ppm = 1e-5).
    pub rate_accuracy: Option<f64>,
    /// `table.position_accuracy`, rad.
    pub position_accuracy_rad: Option<f64>,
    /// `table.axis_orthogonality`, rad.
    pub axis_orthogonality_rad: Option<f64>,
    /// `site.gravity_u_mps2`.
    pub gravity_u_mps2: Option<f64>,
    /// `site.gravity_mps2`.
    pub gravity_mps2: f64,
    /// `daq.clock_accuracy` as a ratio (20 ppm = 2e-5).
    pub clock_accuracy: Option<f64>,
    /// `site.temperature_stability`, degC (a bound of the deviation from the mean).
    pub temperature_stability_c: Option<f64>,
    /// `imu.temperature_coefficients`, per degC in the results' units.
    pub temperature_coefficients: TemperatureCoefficients,
}

/// The IMU's temperature coefficients, per degC (`None`: not stated).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct TemperatureCoefficients {
    /// m/s^2 per degC.
    pub accel_bias: Option<f64>,
    /// deg/s per degC.
    pub gyro_bias: Option<f64>,
    /// ppm per degC.
    pub accel_scale: Option<f64>,
    /// ppm per degC.
    pub gyro_scale: Option<f64>,
}

const SQRT3: f64 = 1.732_050_807_568_877_2;
const ARCSEC: f64 = std::f64::consts::PI / 180.0 / 3600.0;

/// How a parameter's value converts an angle in rad into its unit (for misalignments).
fn per_rad(unit: &str) -> Option<f64> {
    match unit {
        "rad" => Some(1.0),
        "mrad" => Some(1e3),
        "urad" => Some(1e6),
        "deg" => Some(180.0 / std::f64::consts::PI),
        "arcsec" => Some(1.0 / ARCSEC),
        _ => None,
    }
}

fn arcsec(rad: f64) -> String {
    format!("{} arcsec", short(rad / ARCSEC))
}

/// A coefficient with four significant digits (they may be small: 1e-4 m/s^2 per degC).
fn short_sig(x: f64) -> String {
    format!("{x:.4e}")
        .parse::<f64>()
        .map_or_else(|_| x.to_string(), |v| v.to_string())
}

fn short(x: f64) -> String {
    let s = format!("{x:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    s.to_string()
}

/// The budget of quantity `name` (`value +- u_a unit` from the fit, `nu_a` its Type A
/// degrees of freedom) under what `stated` gives.
pub fn budget(name: &str, value: f64, u_a: f64, unit: &str, nu_a: f64, s: &Stated) -> Budget {
    let mut terms = vec![
        Term::stated("fit (Type A)", Evaluation::A, "normal")
            .dof(nu_a)
            .u(Some(u_a)),
    ];
    let g = s.gravity_mps2;
    let rect = |source: &str, figure: Option<String>, sens: String, u: Option<f64>| {
        let t = Term::stated(source, Evaluation::B, "rectangular").sensitivity(sens);
        match figure {
            Some(f) => t.figure(f).u(u),
            None => t.u(None),
        }
    };
    let parts: Vec<&str> = name.split('.').collect();
    let family = (parts.first().copied(), parts.get(1).copied());
    match family {
        (Some("gyro"), Some("scale")) => {
            for (source, a) in [
                ("table rate accuracy", s.rate_accuracy),
                ("DAQ clock accuracy", s.clock_accuracy),
            ] {
                terms.push(rect(
                    source,
                    a.map(|a| format!("{} ppm", short(a * 1e6))),
                    "1 ppm/ppm".into(),
                    a.map(|a| a * 1e6 / SQRT3),
                ));
            }
        }
        (Some("accel"), Some("bias")) => {
            for (source, a) in [
                ("table position accuracy", s.position_accuracy_rad),
                ("table axis orthogonality", s.axis_orthogonality_rad),
            ] {
                terms.push(rect(
                    source,
                    a.map(arcsec),
                    format!("{} m/s^2 per rad (g)", short(g)),
                    a.map(|a| g * a / SQRT3),
                ));
            }
        }
        (Some("accel"), Some("scale")) => {
            let t = Term::stated("reference gravity", Evaluation::B, "normal")
                .sensitivity(format!("{} ppm per m/s^2 (1e6 / g)", short(1e6 / g)));
            terms.push(match s.gravity_u_mps2 {
                Some(ug) => t.figure(format!("{ug} m/s^2")).u(Some(1e6 * ug / g)),
                None => t.u(None),
            });
        }
        (Some(sensor @ ("accel" | "gyro")), Some("misalignment")) => {
            let scale = per_rad(unit);
            let mut sources = vec![("table axis orthogonality", s.axis_orthogonality_rad)];
            if sensor == "accel" {
                sources.insert(0, ("table position accuracy", s.position_accuracy_rad));
            }
            for (source, a) in sources {
                terms.push(rect(
                    source,
                    a.map(arcsec),
                    "1 rad/rad".into(),
                    a.zip(scale).map(|(a, c)| a * c / SQRT3),
                ));
            }
        }
        _ => {}
    }
    let tc = &s.temperature_coefficients;
    let coefficient = match family {
        (Some("accel"), Some("bias")) => Some((tc.accel_bias, "m/s^2")),
        (Some("gyro"), Some("bias")) => Some((tc.gyro_bias, "deg/s")),
        (Some("accel"), Some("scale")) => Some((tc.accel_scale, "ppm")),
        (Some("gyro"), Some("scale")) => Some((tc.gyro_scale, "ppm")),
        _ => None,
    };
    if let Some((c, per)) = coefficient {
        let sens = match c {
            Some(c) => format!("{} {per} per degC", short_sig(c)),
            None => format!("not stated ({per} per degC)"),
        };
        let dt = s.temperature_stability_c;
        terms.push(rect(
            "temperature sensitivity",
            dt.map(|dt| format!("{} degC", short(dt))),
            sens,
            c.zip(dt).map(|(c, dt)| c.abs() * dt / SQRT3),
        ));
    }
    Budget::combine(name, unit, value, terms)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_family_gets_its_terms_and_a_missing_figure_is_not_stated() {
        let s = Stated {
            rate_accuracy: Some(10e-6),
            gravity_mps2: 9.8,
            ..Stated::default()
        };
        let b = budget("gyro.scale.x", 12.0, 3.0, "ppm", 28.0, &s);
        // fit, rate accuracy, clock accuracy, temperature
        assert_eq!(b.terms.len(), 4);
        assert!((b.terms[1].u.unwrap() - 10.0 / SQRT3).abs() < 1e-12);
        assert!(b.terms[2..].iter().all(|t| t.u.is_none()) && !b.complete);
        let b = budget("accel.bias.y", 0.01, 1e-5, "m/s^2", 12.0, &s);
        assert_eq!(b.terms.len(), 4);
        assert!(b.terms[1..].iter().all(|t| t.u.is_none()) && !b.complete);
        let b = budget("gyro.bias.x", 0.01, 1e-3, "deg/s", 28.0, &s);
        assert_eq!(b.terms.len(), 2);
        assert_eq!(b.terms[1].source, "temperature sensitivity");
        assert!(!b.complete);
        // A coefficient without the lab's stability (or the reverse) is still not stated.
        let half = Stated {
            temperature_coefficients: TemperatureCoefficients {
                gyro_bias: Some(1e-3),
                ..Default::default()
            },
            ..s.clone()
        };
        let b = budget("gyro.bias.x", 0.01, 1e-3, "deg/s", 28.0, &half);
        assert!(b.terms[1].u.is_none());
        let both = Stated {
            temperature_stability_c: Some(2.0),
            ..half
        };
        let b = budget("gyro.bias.x", 0.01, 1e-3, "deg/s", 28.0, &both);
        assert!((b.terms[1].u.unwrap() - 2e-3 / SQRT3).abs() < 1e-15);
        assert!(b.complete);
        // Misalignments have no temperature term.
        let b = budget("gyro.misalignment.xy", 0.1, 0.01, "mrad", 28.0, &both);
        assert!(
            b.terms
                .iter()
                .all(|t| t.source != "temperature sensitivity")
        );
    }
}
