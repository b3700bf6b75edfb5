//! The units of a map: the language's own table (`ratecal_physics::units`), plus counts
//! (`"0.000488 g/count"` or `"16384 count/g"`) for raw ADC output.

use ratecal_physics::units::{Dim, parse_quantity, unit};

/// Suffixes and prefixes that name one ADC count.
const COUNT: [&str; 3] = ["counts", "count", "LSB"];

/// The factor from one unit of `text` (a unit name or a count form) to the internal unit
/// of `dim` (m/s^2, deg/s), or a message for people.
pub fn scale_of(text: &str, dim: Dim) -> Result<f64, String> {
    let t = text.trim();
    let (got, factor) = if let Some((d, f)) = unit(t) {
        (d, f)
    } else if let Some(body) = COUNT
        .iter()
        .find_map(|c| t.strip_suffix(&format!("/{c}")[..]))
    {
        // `0.000488 g/count`: one count is that quantity.
        parse_quantity(body).ok_or_else(|| not_a_unit(t, dim))?
    } else if let Some((n, u)) = COUNT
        .iter()
        .find_map(|c| t.split_once(&format!(" {c}/")[..]))
    {
        // `16384 count/g`: that many counts make one unit.
        let n: f64 = n.trim().parse().map_err(|_| not_a_unit(t, dim))?;
        let (d, f) = unit(u.trim()).ok_or_else(|| not_a_unit(t, dim))?;
        if n == 0.0 {
            return Err(format!("`{t}`: a count scale cannot be zero"));
        }
        (d, f / n)
    } else {
        return Err(not_a_unit(t, dim));
    };
    if got != dim {
        return Err(format!(
            "`{t}` is a unit of {}, but this key takes a unit of {}",
            got.name(),
            dim.name()
        ));
    }
    if !factor.is_finite() || factor == 0.0 {
        return Err(format!(
            "`{t}` is not a usable scale (zero or out of range)"
        ));
    }
    Ok(factor)
}

fn not_a_unit(t: &str, dim: Dim) -> String {
    let e = if dim == Dim::Accel {
        "g, mg, m/s^2, \"0.000488 g/count\" or \"16384 count/g\""
    } else {
        "deg/s, rad/s, \"0.00763 deg/s/count\" or \"131 count/deg/s\""
    };
    format!("`{t}` is not a unit of {} (expected {e})", dim.name())
}

/// Seconds per unit of a time column (`s`, `ms`, `us`).
pub fn seconds_per(text: &str) -> Option<f64> {
    match text.trim() {
        "us" | "µs" => Some(1e-6),
        t => unit(t).filter(|u| u.0 == Dim::Time).map(|u| u.1),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn language_units_and_counts() {
        let g = ratecal_physics::STANDARD_GRAVITY;
        assert_eq!(scale_of("g", Dim::Accel), Ok(g));
        assert_eq!(scale_of("mg", Dim::Accel), Ok(g * 1e-3));
        assert_eq!(scale_of("m/s^2", Dim::Accel), Ok(1.0));
        assert_eq!(scale_of("0.000488 g/count", Dim::Accel), Ok(0.000488 * g));
        assert_eq!(scale_of("16384 count/g", Dim::Accel), Ok(g / 16384.0));
        assert_eq!(scale_of("131 LSB/deg/s", Dim::Rate), Ok(1.0 / 131.0));
        let rad = scale_of("rad/s", Dim::Rate).unwrap();
        assert!((rad - 57.29577951308232).abs() < 1e-12);
        assert!(
            scale_of("deg/s", Dim::Accel)
                .unwrap_err()
                .contains("angular rate")
        );
        assert!(scale_of("furlong", Dim::Accel).is_err());
        assert!(scale_of("0 count/g", Dim::Accel).is_err());
        assert_eq!(seconds_per("ms"), Some(1e-3));
        assert_eq!(seconds_per("us"), Some(1e-6));
        assert_eq!(seconds_per("deg"), None);
    }
}
