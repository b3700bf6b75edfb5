//! What an acceptance check on the calibration may name: a fitted parameter
//! (`accel.bias.x`), or a derived quantity, a function of fitted parameters whose
//! uncertainty the analysis propagates through the fit's covariance:
//!
//! - `abs(P)`: the magnitude of one parameter (`abs(gyro.scale.x)`);
//! - `norm(S.bias)`, `norm(S.scale)`: the length of the triad's bias or scale-factor error
//!   vector (`norm(accel.bias)`);
//! - `norm(S.misalignment)`: the root sum of squares of the six cross-coupling terms;
//! - `norm(S.misalignment.X)`: the angle by which sensitive axis X is tilted off its ideal
//!   direction, `sqrt(m_XY^2 + m_XZ^2)` (small angles).
//!
//! The checker and the analysis both read a quantity's name through [`checked`], so what
//! the language accepts is what the analysis evaluates.

use crate::Dim;

/// The functions a check may apply.
pub const FUNCTIONS: &[&str] = &["abs", "norm"];

const AXES: [&str; 3] = ["x", "y", "z"];

/// A checked quantity over fitted parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct Derived {
    /// The function (`None` for the parameter itself).
    pub func: Option<&'static str>,
    /// The results.json parameter names it is a function of.
    pub parameters: Vec<String>,
    /// Dimension.
    pub dim: Dim,
}

/// Why a function cannot apply to its argument (the checker locates it).
#[derive(Debug, Clone, PartialEq)]
pub enum DerivedError {
    /// `abs(accel.bias)`: `abs` takes one parameter, not a triad.
    AbsOfVector,
    /// `norm(accel.bias.x)`: `norm` takes a triad, not one parameter.
    NormOfScalar,
    /// Not a function the language knows.
    UnknownFunction,
    /// Not a fitted parameter or triad.
    UnknownArgument,
}

/// The dimension of a calibrated parameter (`accel.bias.x`, `gyro.scale.y`,
/// `accel.misalignment.xy`), `None` when it is not one.
pub fn parameter_dim(name: &str) -> Option<Dim> {
    let parts: Vec<&str> = name.split('.').collect();
    let axis = |a: &str| AXES.contains(&a);
    let pair = |a: &str| {
        let c: Vec<char> = a.chars().collect();
        c.len() == 2 && c[0] != c[1] && c.iter().all(|c| "xyz".contains(*c))
    };
    match parts.as_slice() {
        ["accel", "bias", a] if axis(a) => Some(Dim::Accel),
        ["gyro", "bias", a] if axis(a) => Some(Dim::Rate),
        ["accel" | "gyro", "scale", a] if axis(a) => Some(Dim::Ratio),
        ["accel" | "gyro", "misalignment", a] if pair(a) => Some(Dim::Angle),
        _ => None,
    }
}

/// Every calibrated parameter a check may name (`accel.bias.x`, ..., `gyro.misalignment.zy`),
/// for suggestions.
pub fn parameter_names() -> Vec<String> {
    ["accel", "gyro"]
        .iter()
        .flat_map(|s| {
            ["bias", "scale", "misalignment"]
                .iter()
                .flat_map(move |q| vector(&format!("{s}.{q}")).map_or_else(Vec::new, |v| v.0))
        })
        .collect()
}

/// Whether `name` is shaped like a parameter (its last part a body axis or a pair of
/// them: `accel.bais.x`), so that a misspelling is matched against parameters.
pub fn looks_like_parameter(name: &str) -> bool {
    let last = name.rsplit('.').next().unwrap_or_default();
    name.contains('.')
        && !last.is_empty()
        && last.len() <= 2
        && last.chars().all(|c| "xyz".contains(c))
}

/// The parameters of a triad (`accel.bias`, `gyro.misalignment`, `accel.misalignment.x`)
/// and their dimension, `None` when `name` is not one.
pub fn vector(name: &str) -> Option<(Vec<String>, Dim)> {
    let parts: Vec<&str> = name.split('.').collect();
    let per_axis = |s: &str, q: &str| AXES.iter().map(|a| format!("{s}.{q}.{a}")).collect();
    match parts.as_slice() {
        [s @ ("accel" | "gyro"), "bias"] => Some((
            per_axis(s, "bias"),
            if *s == "accel" { Dim::Accel } else { Dim::Rate },
        )),
        [s @ ("accel" | "gyro"), "scale"] => Some((per_axis(s, "scale"), Dim::Ratio)),
        [s @ ("accel" | "gyro"), "misalignment"] => {
            let all = AXES
                .iter()
                .flat_map(|i| AXES.iter().filter(move |j| *j != i).map(move |j| (i, j)))
                .map(|(i, j)| format!("{s}.misalignment.{i}{j}"))
                .collect();
            Some((all, Dim::Angle))
        }
        [s @ ("accel" | "gyro"), "misalignment", i] if AXES.contains(i) => {
            let row = AXES
                .iter()
                .filter(|j| *j != i)
                .map(|j| format!("{s}.misalignment.{i}{j}"))
                .collect();
            Some((row, Dim::Angle))
        }
        _ => None,
    }
}

/// What `func(arg)` (or `arg` alone) names over the fitted parameters.
pub fn derived(func: Option<&str>, arg: &str) -> Result<Derived, DerivedError> {
    let func = match func {
        None => None,
        Some(f) => Some(
            *FUNCTIONS
                .iter()
                .find(|x| **x == f)
                .ok_or(DerivedError::UnknownFunction)?,
        ),
    };
    match (func, parameter_dim(arg), vector(arg)) {
        (None | Some("abs"), Some(dim), _) => Ok(Derived {
            func,
            parameters: vec![arg.to_string()],
            dim,
        }),
        (Some("norm"), _, Some((parameters, dim))) => Ok(Derived {
            func,
            parameters,
            dim,
        }),
        (Some("abs"), _, Some(_)) => Err(DerivedError::AbsOfVector),
        (Some("norm"), Some(_), _) => Err(DerivedError::NormOfScalar),
        _ => Err(DerivedError::UnknownArgument),
    }
}

/// Splits a plan quantity (`norm(accel.bias)`) into its function and argument.
pub fn split(quantity: &str) -> (Option<&str>, &str) {
    match quantity.split_once('(') {
        Some((f, rest)) if rest.ends_with(')') => (Some(f), &rest[..rest.len() - 1]),
        _ => (None, quantity),
    }
}

/// The value and standard uncertainty of a derived quantity from its parameters' values
/// `v`, standard uncertainties `u` and correlation `r` (row-major, `v.len()` squared; the
/// identity when the fit gives none), by the GUM's law of propagation (first order).
pub fn evaluate(func: Option<&str>, v: &[f64], u: &[f64], r: &[f64]) -> (f64, f64) {
    let n = v.len();
    let value = match func {
        Some("norm") => v.iter().map(|x| x * x).sum::<f64>().sqrt(),
        Some("abs") => v[0].abs(),
        _ => v[0],
    };
    // Sensitivity coefficients: d|x|/dx = sign(x); d norm/dx_i = x_i / norm (at the zero
    // vector, where the norm has no derivative, the components' RSS uncertainty).
    let c: Vec<f64> = match func {
        Some("norm") if value > 0.0 => v.iter().map(|x| x / value).collect(),
        Some("norm") => {
            return (0.0, u.iter().map(|x| x * x).sum::<f64>().sqrt());
        }
        _ => vec![1.0; n],
    };
    let mut var = 0.0;
    for i in 0..n {
        for j in 0..n {
            let rij = if i == j { 1.0 } else { r[i * n + j] };
            var += c[i] * c[j] * u[i] * u[j] * rij;
        }
    }
    (value, var.max(0.0).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn forms() {
        let d = derived(Some("norm"), "accel.misalignment.y").unwrap();
        assert_eq!(
            d.parameters,
            ["accel.misalignment.yx", "accel.misalignment.yz"]
        );
        assert_eq!(d.dim, Dim::Angle);
        assert_eq!(
            derived(Some("norm"), "gyro.misalignment")
                .unwrap()
                .parameters
                .len(),
            6
        );
        assert_eq!(
            derived(Some("abs"), "accel.bias"),
            Err(DerivedError::AbsOfVector)
        );
        assert_eq!(
            derived(Some("norm"), "accel.bias.x"),
            Err(DerivedError::NormOfScalar)
        );
        assert_eq!(
            derived(Some("max"), "accel.bias"),
            Err(DerivedError::UnknownFunction)
        );
        assert_eq!(split("norm(accel.bias)"), (Some("norm"), "accel.bias"));
        assert_eq!(split("accel.bias.x"), (None, "accel.bias.x"));
    }

    #[test]
    fn propagation_against_hand_values() {
        // |(3, 4)| = 5; c = (0.6, 0.8); u = (0.1, 0.2), r = 0.5:
        // var = 0.36*0.01 + 0.64*0.04 + 2*0.6*0.8*0.1*0.2*0.5 = 0.0036+0.0256+0.0096.
        let (v, u) = evaluate(
            Some("norm"),
            &[3.0, 4.0],
            &[0.1, 0.2],
            &[1.0, 0.5, 0.5, 1.0],
        );
        assert!((v - 5.0).abs() < 1e-12);
        assert!((u - 0.0388f64.sqrt()).abs() < 1e-12);
        let (v, u) = evaluate(Some("abs"), &[-2.0], &[0.3], &[1.0]);
        assert_eq!((v, u), (2.0, 0.3));
    }
}
