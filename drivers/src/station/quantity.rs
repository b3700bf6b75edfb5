//! Quantities written with units in the station file (`"300 deg/s"`, `"5 arcsec"`,
//! `"0.0003 deg/s/rtHz"`). Each type checks its dimension while deserializing, so a wrong
//! unit is an error located at the offending value. A bare `0` is accepted everywhere
//! (zero needs no unit); any other bare number is refused: a unit is never guessed.

use ratecal_physics::units::{Dim, parse_quantity};
use serde::de::{self, Deserializer, Visitor};
use serde::{Deserialize, Serialize};
use std::fmt;

/// How a quantity's text relates to the unit table: plain, a noise density (`/rtHz`) or
/// a random-walk coefficient (`/rts`, per root second).
#[derive(Clone, Copy, PartialEq, Eq)]
enum Form {
    Plain,
    Delta,
    Density,
    Walk,
}

/// Parses `text` as a quantity of dimension `dim` in `form`; returns the internal value or
/// a message for people.
fn parse(text: &str, dim: Dim, form: Form, example: &str) -> Result<f64, String> {
    let (body, suffix) = match form {
        Form::Plain | Form::Delta => (text.trim(), ""),
        Form::Density => strip_any(text, &["/rtHz", "/sqrt(Hz)", "/√Hz"], "/rtHz")?,
        Form::Walk => strip_any(text, &["/rts", "/sqrt(s)", "/√s"], "/rts")?,
    };
    let Some((got, value)) = parse_quantity(body) else {
        return Err(format!(
            "`{text}` is not {}{suffix} (expected e.g. \"{example}\")",
            article(dim)
        ));
    };
    if !value.is_finite() {
        return Err(format!(
            "`{text}` is out of range (expected {}, e.g. \"{example}\")",
            article(dim)
        ));
    }
    if got == Dim::Number {
        if value == 0.0 {
            return Ok(0.0);
        }
        return Err(format!(
            "`{text}` has no unit (expected {}, e.g. \"{example}\")",
            article(dim)
        ));
    }
    if got != dim {
        let unit_name =
            body.trim_start_matches(|c: char| c.is_ascii_digit() || "+-.eE ".contains(c));
        return Err(format!(
            "`{unit_name}` is a unit of {}, but this key takes {}{suffix} (e.g. \"{example}\")",
            got.name(),
            article(dim)
        ));
    }
    // Kelvin is absolute in parse_quantity; a temperature *difference* in K equals degC.
    if form == Form::Delta && body.trim_end().ends_with('K') {
        return Ok(value + 273.15);
    }
    Ok(value)
}

fn article(dim: Dim) -> String {
    let name = dim.name();
    if name.starts_with(['a', 'e', 'i', 'o', 'u']) {
        format!("an {name}")
    } else {
        format!("a {name}")
    }
}

fn strip_any<'a>(
    text: &'a str,
    suffixes: &[&str],
    canonical: &'static str,
) -> Result<(&'a str, &'static str), String> {
    let t = text.trim();
    for s in suffixes {
        if let Some(body) = t.strip_suffix(s) {
            return Ok((body, canonical));
        }
    }
    Err(format!(
        "`{text}` lacks the `{canonical}` suffix this key takes"
    ))
}

/// Anything with one number in an internal unit (for validation helpers).
pub trait Value {
    /// The number, internal unit.
    fn value(&self) -> f64;
}

impl Value for f64 {
    fn value(&self) -> f64 {
        *self
    }
}

/// `deserialize_with` helper: the value must be finite and strictly positive.
pub fn positive<'de, D: Deserializer<'de>, T: Deserialize<'de> + Value>(
    d: D,
) -> Result<T, D::Error> {
    let v = T::deserialize(d)?;
    if v.value().is_finite() && v.value() > 0.0 {
        Ok(v)
    } else {
        Err(de::Error::custom(format!(
            "must be positive, found {}",
            v.value()
        )))
    }
}

/// A number for a message: plain, or in exponent form when very large or small.
pub fn shown(v: f64) -> String {
    if v != 0.0 && !(1e-6..1e9).contains(&v.abs()) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// Lowest and highest frequency a station file may give (Hz): below, sample times and
/// the servo's response leave the range of `f64` (1e-300 Hz: a period of 1e300 s, NaN
/// angles); above, the simulated station would generate samples without end.
pub const FREQ_RANGE_HZ: (f64, f64) = (1e-3, 1e6);

/// `deserialize_with` helper: a frequency within `FREQ_RANGE_HZ`.
pub fn frequency<'de, D: Deserializer<'de>>(d: D) -> Result<Freq, D::Error> {
    let v = Freq::deserialize(d)?;
    let (lo, hi) = FREQ_RANGE_HZ;
    if (lo..=hi).contains(&v.0) {
        Ok(v)
    } else if v.0.is_nan() || v.0 <= 0.0 {
        Err(de::Error::custom(format!(
            "must be positive, found {}",
            shown(v.0)
        )))
    } else {
        Err(de::Error::custom(format!(
            "must be between 0.001 Hz and 1000 kHz, found {} Hz",
            shown(v.0)
        )))
    }
}

/// `deserialize_with` helper: a servo damping ratio, above 0 and at most 100 (beyond, the
/// loop's slow root `wn (zeta - sqrt(zeta^2 - 1))` is lost to cancellation, and past
/// 1e154 `zeta^2` overflows: NaN angles).
pub fn damping<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    let v = f64::deserialize(d)?;
    if v.is_nan() || v <= 0.0 {
        Err(de::Error::custom(format!("must be positive, found {v}")))
    } else if v > 100.0 {
        Err(de::Error::custom(format!(
            "must be at most 100 (below 1 overshoots), found {}",
            shown(v)
        )))
    } else {
        Ok(v)
    }
}

/// `deserialize_with` helper: a plain number that is finite (not `.nan`, not `.inf`).
pub fn finite<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    let v = f64::deserialize(d)?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(de::Error::custom(format!(
            "must be a finite number, found {}",
            shown(v)
        )))
    }
}

/// `deserialize_with` helper: a plain number from 0 to 1.
pub fn fraction<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    let v = f64::deserialize(d)?;
    if (0.0..=1.0).contains(&v) {
        Ok(v)
    } else {
        Err(de::Error::custom(format!(
            "must be between 0 and 1, found {v}"
        )))
    }
}

/// A unit vector written `[x, y, z]` (checked to 1e-6; then normalised exactly).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct UnitVec(pub [f64; 3]);

impl<'de> Deserialize<'de> for UnitVec {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v = <[f64; 3]>::deserialize(d)?;
        let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        if !n.is_finite() || (n - 1.0).abs() > 1e-6 {
            return Err(de::Error::custom(format!(
                "an axis must be a unit vector; this one has length {n}"
            )));
        }
        Ok(UnitVec([v[0] / n, v[1] / n, v[2] / n]))
    }
}

/// A rotation matrix, row-major, checked orthonormal with determinant +1 (to 1e-6).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Rotation(pub [[f64; 3]; 3]);

impl<'de> Deserialize<'de> for Rotation {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let r = <[[f64; 3]; 3]>::deserialize(d)?;
        let m = ratecal_physics::Mat3::from_fn(|i, j| r[i][j]);
        if let Err(why) = ratecal_physics::check_rotation(&m, 1e-6) {
            return Err(de::Error::custom(format!(
                "a mount rotation must be orthonormal with determinant +1; this one {why}"
            )));
        }
        Ok(Rotation(r))
    }
}

macro_rules! quantity {
    ($(#[$doc:meta])* $name:ident, $dim:expr, $form:expr, $example:literal) => {
        $(#[$doc])*
        #[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
        pub struct $name(pub f64);

        impl $name {
            /// The value in the internal unit.
            pub fn get(self) -> f64 {
                self.0
            }
        }

        impl Value for $name {
            fn value(&self) -> f64 {
                self.0
            }
        }

        impl<'de> Deserialize<'de> for $name {
            fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                struct V;
                impl Visitor<'_> for V {
                    type Value = $name;
                    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                        write!(f, "{} with its unit, e.g. \"{}\"", article($dim), $example)
                    }
                    fn visit_str<E: de::Error>(self, s: &str) -> Result<$name, E> {
                        parse(s, $dim, $form, $example).map($name).map_err(E::custom)
                    }
                    fn visit_f64<E: de::Error>(self, v: f64) -> Result<$name, E> {
                        if v == 0.0 {
                            Ok($name(0.0))
                        } else {
                            Err(E::custom(format!(
                                "`{v}` has no unit (expected {}, e.g. \"{}\")",
                                article($dim),
                                $example
                            )))
                        }
                    }
                    fn visit_i64<E: de::Error>(self, v: i64) -> Result<$name, E> {
                        self.visit_f64(v as f64)
                    }
                    fn visit_u64<E: de::Error>(self, v: u64) -> Result<$name, E> {
                        self.visit_f64(v as f64)
                    }
                }
                d.deserialize_any(V)
            }
        }
    };
}

quantity!(
    /// An angle, internal unit deg.
    Angle, Dim::Angle, Form::Plain, "5 arcsec");
quantity!(
    /// An angular rate, internal unit deg/s.
    Rate, Dim::Rate, Form::Plain, "300 deg/s");
quantity!(
    /// An acceleration, internal unit m/s^2.
    Accel, Dim::Accel, Form::Plain, "1.5 mg");
quantity!(
    /// A duration, internal unit s.
    Time, Dim::Time, Form::Plain, "30 s");
quantity!(
    /// A frequency, internal unit Hz.
    Freq, Dim::Frequency, Form::Plain, "100 Hz");
quantity!(
    /// A temperature (or temperature difference), internal unit degC.
    Temp, Dim::Temperature, Form::Plain, "20 degC");
quantity!(
    /// A temperature difference, internal unit degC (`"3 K"` is 3 degC here).
    TempDelta, Dim::Temperature, Form::Delta, "0.5 degC");
quantity!(
    /// A temperature rate, internal unit degC/h.
    TempRate, Dim::TemperatureRate, Form::Plain, "0.05 degC/h");
quantity!(
    /// A ratio, internal unit 1 (`"300 ppm"`, `"45 %"`).
    Ratio, Dim::Ratio, Form::Plain, "300 ppm");
quantity!(
    /// A pressure, internal unit kPa.
    Pressure, Dim::Pressure, Form::Plain, "101.3 kPa");
quantity!(
    /// A gyro white-noise density, internal unit (deg/s)/sqrt(Hz).
    RateDensity, Dim::Rate, Form::Density, "0.0003 deg/s/rtHz");
quantity!(
    /// An accelerometer white-noise density, internal unit (m/s^2)/sqrt(Hz).
    AccelDensity, Dim::Accel, Form::Density, "20 ug/rtHz");
quantity!(
    /// A gyro bias random-walk coefficient: the bias's standard deviation grows as
    /// `k sqrt(t)`; internal unit (deg/s)/sqrt(s).
    RateWalk, Dim::Rate, Form::Walk, "2e-6 deg/s/rts");

#[cfg(test)]
mod tests {
    use super::*;

    fn rate(s: &str) -> Result<f64, String> {
        parse(s, Dim::Rate, Form::Plain, "1 deg/s")
    }

    #[test]
    fn plain_units_convert() {
        assert_eq!(rate("300 deg/s"), Ok(300.0));
        assert_eq!(rate("1 rpm"), Ok(6.0));
        assert!(rate("3 arcsec").unwrap_err().contains("unit of angle"));
        assert!(rate("3").unwrap_err().contains("no unit"));
        assert_eq!(rate("0"), Ok(0.0));
    }

    #[test]
    fn densities_and_walks() {
        let d = parse("20 ug/rtHz", Dim::Accel, Form::Density, "").unwrap();
        assert!((d - 20e-6 * 9.80665).abs() < 1e-15);
        assert!(parse("20 ug", Dim::Accel, Form::Density, "").is_err());
        assert_eq!(parse("2e-6 deg/s/rts", Dim::Rate, Form::Walk, ""), Ok(2e-6));
    }
}
