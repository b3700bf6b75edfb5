//! Units the procedure language and the station file accept, with their dimension and the
//! factor to the internal unit of that dimension (deg, deg/s, m/s^2, s, Hz, degC, degC/h,
//! m, plain ratio, kPa).

use serde::{Deserialize, Serialize};

/// Physical dimension of a quantity.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Dim {
    /// deg, rad, arcmin, arcsec, mrad, urad (internal: deg).
    Angle,
    /// deg/s, rad/s, deg/h, deg/min, rpm (internal: deg/s).
    Rate,
    /// g, mg, ug, m/s^2 (internal: m/s^2, g = 9.80665 standard gravity as a unit).
    Accel,
    /// ms, s, min, h (internal: s).
    Time,
    /// Hz, kHz (internal: Hz).
    Frequency,
    /// degC, K (internal: degC).
    Temperature,
    /// degC/h, degC/min, K/h (internal: degC/h).
    TemperatureRate,
    /// mm, cm, m (internal: m).
    Length,
    /// %, ppm (internal: plain ratio, 1 % = 0.01).
    Ratio,
    /// kPa, Pa, hPa (internal: kPa).
    Pressure,
    /// A bare number.
    Number,
}

impl Dim {
    /// Name for messages (`angular rate`).
    pub fn name(self) -> &'static str {
        match self {
            Dim::Angle => "angle",
            Dim::Rate => "angular rate",
            Dim::Accel => "acceleration",
            Dim::Time => "time",
            Dim::Frequency => "frequency",
            Dim::Temperature => "temperature",
            Dim::TemperatureRate => "temperature rate",
            Dim::Length => "length",
            Dim::Ratio => "ratio",
            Dim::Pressure => "pressure",
            Dim::Number => "number",
        }
    }

    /// The internal unit's name (`deg/s`).
    pub fn internal_unit(self) -> &'static str {
        match self {
            Dim::Angle => "deg",
            Dim::Rate => "deg/s",
            Dim::Accel => "m/s^2",
            Dim::Time => "s",
            Dim::Frequency => "Hz",
            Dim::Temperature => "degC",
            Dim::TemperatureRate => "degC/h",
            Dim::Length => "m",
            Dim::Ratio => "",
            Dim::Pressure => "kPa",
            Dim::Number => "",
        }
    }
}

const G: f64 = crate::STANDARD_GRAVITY;
const RAD: f64 = 180.0 / std::f64::consts::PI;

/// Every unit: name, dimension, factor to the internal unit (offset only for K).
pub const UNITS: &[(&str, Dim, f64)] = &[
    ("deg", Dim::Angle, 1.0),
    ("rad", Dim::Angle, RAD),
    ("mrad", Dim::Angle, RAD * 1e-3),
    ("urad", Dim::Angle, RAD * 1e-6),
    ("arcmin", Dim::Angle, 1.0 / 60.0),
    ("arcsec", Dim::Angle, 1.0 / 3600.0),
    ("deg/s", Dim::Rate, 1.0),
    ("rad/s", Dim::Rate, RAD),
    ("deg/min", Dim::Rate, 1.0 / 60.0),
    ("deg/h", Dim::Rate, 1.0 / 3600.0),
    ("rpm", Dim::Rate, 6.0),
    ("g", Dim::Accel, G),
    ("mg", Dim::Accel, G * 1e-3),
    ("ug", Dim::Accel, G * 1e-6),
    ("m/s^2", Dim::Accel, 1.0),
    ("ms", Dim::Time, 1e-3),
    ("s", Dim::Time, 1.0),
    ("min", Dim::Time, 60.0),
    ("h", Dim::Time, 3600.0),
    ("Hz", Dim::Frequency, 1.0),
    ("kHz", Dim::Frequency, 1e3),
    ("degC", Dim::Temperature, 1.0),
    ("K", Dim::Temperature, 1.0),
    ("degC/h", Dim::TemperatureRate, 1.0),
    ("degC/min", Dim::TemperatureRate, 60.0),
    ("K/h", Dim::TemperatureRate, 1.0),
    ("mm", Dim::Length, 1e-3),
    ("cm", Dim::Length, 1e-2),
    ("m", Dim::Length, 1.0),
    ("%", Dim::Ratio, 1e-2),
    ("ppm", Dim::Ratio, 1e-6),
    ("kPa", Dim::Pressure, 1.0),
    ("hPa", Dim::Pressure, 0.1),
    ("Pa", Dim::Pressure, 1e-3),
];

/// Looks a unit up by name.
pub fn unit(name: &str) -> Option<(Dim, f64)> {
    UNITS.iter().find(|(n, _, _)| *n == name).map(|&(_, d, f)| (d, f))
}

/// Converts `value unit` to the internal unit of its dimension. Kelvin is an absolute
/// temperature (273.15 K = 0 degC) except inside a difference, which callers handle by
/// converting `K` bands as differences themselves.
pub fn to_internal(value: f64, unit_name: &str) -> Option<(Dim, f64)> {
    let (dim, factor) = unit(unit_name)?;
    let v = if unit_name == "K" { value - 273.15 } else { value * factor };
    Some((dim, v))
}

/// Parses `"0.5 deg/s"` (a number, optional spaces, a unit) to its dimension and internal value.
pub fn parse_quantity(text: &str) -> Option<(Dim, f64)> {
    let text = text.trim();
    let split = text
        .char_indices()
        .find(|&(i, c)| !(c.is_ascii_digit() || c == '.' || c == 'e' || c == 'E' || ((c == '-' || c == '+') && (i == 0 || text[..i].ends_with(['e', 'E'])))))
        .map(|(i, _)| i)
        .unwrap_or(text.len());
    let value: f64 = text[..split].trim().parse().ok()?;
    let u = text[split..].trim();
    if u.is_empty() {
        return Some((Dim::Number, value));
    }
    to_internal(value, u)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn conversions() {
        assert_eq!(parse_quantity("5 arcsec"), Some((Dim::Angle, 5.0 / 3600.0)));
        assert_eq!(parse_quantity("0.001 g"), Some((Dim::Accel, 0.001 * 9.80665)));
        assert_eq!(parse_quantity("-100 deg/s"), Some((Dim::Rate, -100.0)));
        assert_eq!(parse_quantity("1e-3 m/s^2"), Some((Dim::Accel, 1e-3)));
        assert_eq!(parse_quantity("293.15 K"), Some((Dim::Temperature, 0.0 + 20.0)));
        assert_eq!(parse_quantity("3 furlongs"), None);
        assert_eq!(parse_quantity("60 min").map(|q| q.1), Some(3600.0));
    }
}
