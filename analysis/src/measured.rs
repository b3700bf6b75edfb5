//! Numbers the way a metrology lab writes them (GUM, JCGM 100 section 7.2.6; ISO 80000-1):
//! a value with its standard uncertainty `u`, `u` rounded to two significant digits and the
//! value rounded to match, `0.01234 ± 0.00056 m/s^2`, `-1119 ± 190 ppm`.
//!
//! The one implementation: the terminal (`analyze`, `run`, `explain`, `archive show` and
//! `trend`) and the report filter `measured` all print through [`format_measured`] (and
//! [`format_value`] for a value without an uncertainty). The rule:
//! - `u` to two significant digits, rounded half up on its decimal form (`0.0995` -> `0.10`,
//!   `0.0125` -> `0.013`); the value rounded half up (away from zero) at the place of `u`'s
//!   second digit, but never into its integer digits (`-1118.87 ± 190.1` -> `-1119 ± 190`,
//!   as the issue that asked for this rule writes it: a lab does not write `-1120` for a
//!   value it knows to the unit, and the trailing `0` of `190` only holds a place).
//! - Plain decimals while the larger of the rounded `|value|` and `u` lies in
//!   `[1e-3, 1e5)`; otherwise one power of ten factored out of both, from the larger one:
//!   `(3.20 ± 0.41)e-6 deg/s`.
//! - No `-0.00`: a value that rounds to zero prints unsigned.
//! - `u` that is not a positive finite number: the value to six significant digits
//!   (trailing zeros dropped) and `u` as it is: `1.5 ± 0 s`, `1.5 ± NaN s`, `1.5 ± ∞ s`.
//!   A value that is not finite prints as `NaN`, `∞` or `−∞`, with `u` at two digits.
//!
//! Rounding works on the shortest decimal form of each `f64` (what Rust prints), so it
//! follows the digits a person sees: `2.345 ± 0.011` -> `2.345`, `2.345 ± 0.11` -> `2.35`.

/// Values printed without a power of ten: `[10^PLAIN_LO, 10^PLAIN_HI]` by leading digit.
const PLAIN_LO: i32 = -3;
const PLAIN_HI: i32 = 4;

/// `value ± u unit` (no unit when `unit` is empty), as the module doc says.
pub fn format_measured(value: f64, u: f64, unit: &str) -> String {
    let text = measured_number(value, u);
    if unit.is_empty() {
        text
    } else {
        format!("{text} {unit}")
    }
}

/// A value without an uncertainty (a limit, a condition recorded once): six significant
/// digits, trailing zeros dropped (`20 degC`, `0.0200037 degC/h`, `-2.1e-7`).
pub fn format_value(value: f64, unit: &str) -> String {
    let text = special(value);
    if unit.is_empty() {
        text
    } else {
        format!("{text} {unit}")
    }
}

/// A reading whose uncertainty is not stated (an environmental condition beside its
/// limit): four significant digits, trailing zeros dropped (`0.02 degC/h`, `101.3 kPa`),
/// since no `U` says which digits hold.
pub fn format_reading(value: f64, unit: &str) -> String {
    let text = if value.is_finite() {
        short(value, 4)
    } else {
        special(value)
    };
    if unit.is_empty() {
        text
    } else {
        format!("{text} {unit}")
    }
}

/// A coverage factor as a certificate writes it: `2` when it is a whole number, else two
/// decimals (`2.05`, from the effective degrees of freedom).
pub fn format_k(k: f64) -> String {
    if (k - k.round()).abs() < 1e-9 {
        format!("{k:.0}")
    } else {
        format!("{k:.2}")
    }
}

/// `value ± u` without a unit (`0.01234 ± 0.00056`, `(3.20 ± 0.41)e-6`).
pub fn measured_number(value: f64, u: f64) -> String {
    let (v, u, e) = measured_parts(value, u);
    match e {
        None => format!("{v} ± {u}"),
        Some(e) => format!("({v} ± {u})e{e}"),
    }
}

/// The value and `u` of [`measured_number`] apart, for a table that prints them in two
/// columns, each with the power of ten they share (`8.54e-6`, `0.16e-6`).
pub fn measured_columns(value: f64, u: f64) -> (String, String) {
    match measured_parts(value, u) {
        (v, u, None) => (v, u),
        (v, u, Some(e)) => (format!("{v}e{e}"), format!("{u}e{e}")),
    }
}

/// The digits of the value and of `u`, and the power of ten factored out of both.
fn measured_parts(value: f64, u: f64) -> (String, String, Option<i32>) {
    if !value.is_finite() {
        let u = if u.is_finite() && u > 0.0 {
            let (n, p) = round_sig(u, 2);
            plain(&n, p)
        } else {
            special(u)
        };
        return (special(value), u, None);
    }
    if !(u.is_finite() && u > 0.0) {
        let shown = if u < 0.0 && u.is_finite() {
            short(u, 2)
        } else {
            special(u)
        };
        return (short(value, 6), shown, None);
    }
    let (nu, p) = round_sig(u, 2);
    let nv = Dec::of(value).round_at(p);
    let e = lead(&nu, p).max(lead(&nv, p));
    if (PLAIN_LO..=PLAIN_HI).contains(&e) {
        // Plain decimals: the value keeps its units digit when u's place is above it.
        let pv = p.min(0);
        let nv = Dec::of(value).round_at(pv);
        let sign = if value < 0.0 && nv != "0" { "-" } else { "" };
        (format!("{sign}{}", plain(&nv, pv)), plain(&nu, p), None)
    } else {
        let sign = if value < 0.0 && nv != "0" { "-" } else { "" };
        (
            format!("{sign}{}", plain(&nv, p - e)),
            plain(&nu, p - e),
            Some(e),
        )
    }
}

/// `x` to `sig` significant digits, trailing zeros dropped (`1.5`, `-2.1e-7`, `0`).
fn short(x: f64, sig: i32) -> String {
    if x == 0.0 {
        return "0".into();
    }
    let (n, p) = round_sig(x, sig);
    let sign = if x < 0.0 { "-" } else { "" };
    let e = lead(&n, p);
    let trim = |s: String| -> String {
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    };
    if (PLAIN_LO..=PLAIN_HI).contains(&e) {
        format!("{sign}{}", trim(plain(&n, p)))
    } else {
        format!("{sign}{}e{e}", trim(plain(&n, p - e)))
    }
}

/// `NaN`, `∞`, `−∞` for numbers that are not finite; `0` for zero.
fn special(x: f64) -> String {
    if x.is_nan() {
        "NaN".into()
    } else if x == f64::INFINITY {
        "∞".into()
    } else if x == f64::NEG_INFINITY {
        "−∞".into()
    } else {
        short(x, 6)
    }
}

/// `|x|` (finite, non-zero) rounded to `sig` significant digits: the digits `n` and the
/// place `p` of the last one (`|x| ≈ n × 10^p`); a carry (`0.0995` -> `0.10`) moves `p` up.
fn round_sig(x: f64, sig: i32) -> (String, i32) {
    let d = Dec::of(x);
    let p = d.exp - (sig - 1);
    let n = d.round_at(p);
    if n.len() as i32 > sig {
        // 99.5 -> 100 at this place is 10 at the next: drop the trailing zero.
        (n[..n.len() - 1].to_string(), p + 1)
    } else {
        (n, p)
    }
}

/// Exponent of the leading digit of `n × 10^p` (`i32::MIN` for zero).
fn lead(n: &str, p: i32) -> i32 {
    if n == "0" {
        i32::MIN
    } else {
        p + n.len() as i32 - 1
    }
}

/// `n × 10^p` in plain decimals (`-p` of them when `p < 0`).
fn plain(n: &str, p: i32) -> String {
    if p >= 0 {
        return if n == "0" {
            "0".into()
        } else {
            format!("{n}{}", "0".repeat(p as usize))
        };
    }
    let d = (-p) as usize;
    let padded = format!("{n:0>width$}", width = d + 1);
    let (int, frac) = padded.split_at(padded.len() - d);
    format!("{int}.{frac}")
}

/// `|x|` in decimal as Rust prints it (shortest round trip): digits `d1 d2 ...` with `d1`
/// at the place `exp`.
struct Dec {
    digits: Vec<u8>,
    exp: i32,
}

impl Dec {
    fn of(x: f64) -> Dec {
        let s = format!("{:e}", x.abs());
        let (mantissa, exp) = s.split_once('e').unwrap_or((&s, "0"));
        Dec {
            digits: mantissa
                .bytes()
                .filter(u8::is_ascii_digit)
                .map(|b| b - b'0')
                .collect(),
            exp: exp.parse().unwrap_or(0),
        }
    }

    /// The integer `round(|x| / 10^p)`, half up, as decimal digits (`"0"` for zero).
    fn round_at(&self, p: i32) -> String {
        if self.digits.iter().all(|&d| d == 0) {
            return "0".into();
        }
        let keep = self.exp - p + 1;
        if keep < 0 {
            return "0".into();
        }
        let keep = keep as usize;
        let mut n: Vec<u8> = (0..keep)
            .map(|i| self.digits.get(i).copied().unwrap_or(0))
            .collect();
        if self.digits.get(keep).is_some_and(|&d| d >= 5) {
            let mut i = n.len();
            loop {
                if i == 0 {
                    n.insert(0, 1);
                    break;
                }
                i -= 1;
                if n[i] == 9 {
                    n[i] = 0;
                } else {
                    n[i] += 1;
                    break;
                }
            }
        }
        let s: String = n.iter().map(|d| char::from(b'0' + d)).collect();
        let s = s.trim_start_matches('0');
        if s.is_empty() { "0".into() } else { s.into() }
    }
}

#[cfg(test)]
mod tests {
    use super::format_measured as f;

    #[test]
    fn uncertainty_has_two_significant_digits_and_the_value_its_place() {
        assert_eq!(f(0.01234, 0.00056, "m/s^2"), "0.01234 ± 0.00056 m/s^2");
        assert_eq!(f(0.0123456, 0.000346, "m/s^2"), "0.01235 ± 0.00035 m/s^2");
        assert_eq!(f(15.04, 1.0, "deg/h"), "15.0 ± 1.0 deg/h");
        assert_eq!(f(802.14, 31.4, ""), "802 ± 31");
        assert_eq!(f(-0.0812, 0.0001, "deg/s"), "-0.08120 ± 0.00010 deg/s");
        assert_eq!(f(12345.678, 0.0012, ""), "12345.6780 ± 0.0012");
    }

    #[test]
    fn the_value_keeps_its_units_digit() {
        // The issue's own example.
        assert_eq!(f(-1118.874315, 190.1, "ppm"), "-1119 ± 190 ppm");
        assert_eq!(f(12345.0, 2345.0, "ppm"), "12345 ± 2300 ppm");
        assert_eq!(f(8021.4, 314.0, ""), "8021 ± 310");
    }

    #[test]
    fn carries_move_the_place() {
        // u = 0.0995 rounds to 0.10: the place is hundredths, not thousandths.
        assert_eq!(f(9.96, 0.0995, "mm"), "9.96 ± 0.10 mm");
        assert_eq!(f(6.137, 0.0996, "mm"), "6.14 ± 0.10 mm");
        assert_eq!(f(0.5, 0.995, ""), "0.5 ± 1.0");
        assert_eq!(f(42.0, 9.96, ""), "42 ± 10");
        // The value's own carry: 9.9996 at thousandths is 10.000.
        assert_eq!(f(9.9996, 0.011, ""), "10.000 ± 0.011");
        // A carry across 1e5 switches to a power of ten.
        assert_eq!(f(99999.0, 950.0, ""), "(1.0000 ± 0.0095)e5");
    }

    #[test]
    fn halves_round_up_on_the_digits_a_person_sees() {
        // 2.345 is 2.34499999... in binary; written 2.345, it rounds to 2.35.
        assert_eq!(f(2.345, 0.11, ""), "2.35 ± 0.11");
        assert_eq!(f(2.345, 0.011, ""), "2.345 ± 0.011");
        assert_eq!(f(1.0, 0.0125, ""), "1.000 ± 0.013");
        assert_eq!(f(-2.345, 0.11, ""), "-2.35 ± 0.11");
    }

    #[test]
    fn negative_values_and_values_that_round_to_zero() {
        assert_eq!(f(-0.004, 0.1, "deg/s"), "0.00 ± 0.10 deg/s");
        assert_eq!(f(-0.006, 0.1, ""), "-0.01 ± 0.10");
        assert_eq!(f(0.0, 0.25, ""), "0.00 ± 0.25");
        assert_eq!(f(1e-9, 0.5, ""), "0.00 ± 0.50");
    }

    #[test]
    fn small_and_large_magnitudes_share_a_power_of_ten() {
        assert_eq!(f(3.2e-6, 4.1e-7, "deg/s"), "(3.20 ± 0.41)e-6 deg/s");
        assert_eq!(f(-3.2e-6, 4.1e-7, "deg/s"), "(-3.20 ± 0.41)e-6 deg/s");
        assert_eq!(f(1.234e-6, 5.6e-8, ""), "(1.234 ± 0.056)e-6");
        assert_eq!(f(2.1e-11, 2e-14, ""), "(2.1000 ± 0.0020)e-11");
        assert_eq!(f(6.02214076e23, 1.2e21, ""), "(6.022 ± 0.012)e23");
        assert_eq!(f(3.0e6, 2.5e5, "Pa"), "(3.00 ± 0.25)e6 Pa");
        // A tiny value under a large u takes the power of ten of u.
        assert_eq!(f(0.001, 2.0e7, ""), "(0.0 ± 2.0)e7");
        assert_eq!(
            f(4.0e-8, 4.549e-7, "m/s^2/degC"),
            "(0.4 ± 4.5)e-7 m/s^2/degC"
        );
        // Edges of the plain range: 1e-3 and just under 1e5 stay plain.
        assert_eq!(f(0.00123, 0.00012, ""), "0.00123 ± 0.00012");
        assert_eq!(f(0.000987, 0.00012, ""), "(9.9 ± 1.2)e-4");
        // 0.000999 rounds to 0.00100: back in the plain range.
        assert_eq!(f(0.000999, 0.00012, ""), "0.00100 ± 0.00012");
        assert_eq!(f(54321.0, 12.0, ""), "54321 ± 12");
    }

    #[test]
    fn an_uncertainty_that_is_not_positive_and_finite_is_shown_as_it_is() {
        assert_eq!(f(1.5, 0.0, "s"), "1.5 ± 0 s");
        assert_eq!(f(1.23456789, 0.0, ""), "1.23457 ± 0");
        assert_eq!(f(-2.1e-7, 0.0, ""), "-2.1e-7 ± 0");
        assert_eq!(f(1.5, f64::NAN, "s"), "1.5 ± NaN s");
        assert_eq!(f(1.5, f64::INFINITY, "s"), "1.5 ± ∞ s");
        assert_eq!(f(1.5, -0.25, "s"), "1.5 ± -0.25 s");
    }

    #[test]
    fn a_value_alone_has_six_significant_digits() {
        use super::format_value as v;
        assert_eq!(v(20.0, "degC"), "20 degC");
        assert_eq!(v(0.02000372589853021, "degC/h"), "0.0200037 degC/h");
        assert_eq!(v(101.3, "kPa"), "101.3 kPa");
        assert_eq!(v(-8.660729817769845e-6, ""), "-8.66073e-6");
        assert_eq!(v(f64::NAN, "g"), "NaN g");
    }

    #[test]
    fn a_reading_without_u_has_four_digits_and_k_is_whole_when_it_is() {
        use super::{format_k, format_reading as r};
        assert_eq!(r(0.02000372589853021, "degC/h"), "0.02 degC/h");
        assert_eq!(r(101.3, "kPa"), "101.3 kPa");
        assert_eq!(r(20.0, "degC"), "20 degC");
        assert_eq!(r(12345.678, "s"), "12350 s");
        assert_eq!(r(f64::NAN, "g"), "NaN g");
        assert_eq!(format_k(2.0), "2");
        assert_eq!(format_k(2.0466), "2.05");
    }

    #[test]
    fn a_value_that_is_not_finite_keeps_its_uncertainty() {
        assert_eq!(f(f64::NAN, 0.0995, "mm"), "NaN ± 0.10 mm");
        assert_eq!(f(f64::NEG_INFINITY, f64::NAN, ""), "−∞ ± NaN");
    }
}
