//! Which terms each reported quantity's budget has, from what the station file states
//! (`docs/certificate.md`, The budget). A Type B figure the station file does not give is a
//! term "not stated", never 0.
//!
//! - every quantity: the fit's Type A standard uncertainty, with the fit's degrees of
//!   freedom counted per segment (each segment's mean is one observation per channel:
//!   `3 x segments - fitted parameters of the sensor`, at least 1), since the samples within
//!   a segment are correlated (low-pass filtered, bias noise);
//! - `gyro.scale.*` (ppm): the table's rate accuracy `a` (a ratio of the rate),
//!   rectangular, `u = a / sqrt(3)`, sensitivity 1;
//! - `accel.bias.*` (m/s^2): the table's position accuracy and axis orthogonality (angles
//!   `a`), rectangular, through the gravity projection: `u = g a / sqrt(3)`, sensitivity
//!   `g` per rad;
//! - `accel.scale.*` (ppm): the site's gravity (a standard uncertainty `u_g`), normal,
//!   `u = 1e6 u_g / g`, sensitivity `1e6 / g` ppm per m/s^2;
//! - `accel.misalignment.*`, `gyro.misalignment.*` (mrad or their unit): the table's
//!   position accuracy (accelerometers only) and axis orthogonality, rectangular, sensitivity
//!   1 rad/rad.

use crate::budget::{Budget, Evaluation, Term};

/// What the station file states for the budget (`None`: not stated).
#[derive(Debug, Clone, Default, PartialEq)]
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
    match (parts.first().copied(), parts.get(1).copied()) {
        (Some("gyro"), Some("scale")) => {
            let a = s.rate_accuracy;
            terms.push(rect(
                "table rate accuracy",
                a.map(|a| format!("{} ppm", short(a * 1e6))),
                "1 ppm/ppm".into(),
                a.map(|a| a * 1e6 / SQRT3),
            ));
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
        assert_eq!(b.terms.len(), 2);
        assert!((b.terms[1].u.unwrap() - 10.0 / SQRT3).abs() < 1e-12);
        let b = budget("accel.bias.y", 0.01, 1e-5, "m/s^2", 12.0, &s);
        assert_eq!(b.terms.len(), 3);
        assert!(b.terms[1..].iter().all(|t| t.u.is_none()) && !b.complete);
        let b = budget("gyro.bias.x", 0.01, 1e-3, "deg/s", 28.0, &s);
        assert_eq!(b.terms.len(), 1);
        assert!(b.complete);
    }
}
