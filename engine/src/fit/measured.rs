//! Numbers the way a metrology lab writes them: the uncertainty to two significant digits
//! and the value rounded to the same decimal place (`-1119 ± 190 ppm`).

/// `value ± u unit`, the uncertainty to two significant digits and the value to match.
pub fn format_measured(value: f64, u: f64, unit: &str) -> String {
    let sep = if unit.is_empty() { "" } else { " " };
    if !value.is_finite() {
        return format!("{value}{sep}{unit}");
    }
    if !(u.is_finite() && u > 0.0) {
        return format!("{}{sep}{unit}", trim(value, 6));
    }
    // Decimal exponent of the uncertainty's second significant digit.
    let mut e = u.log10().floor() as i32 - 1;
    // Rounding may carry into another digit (0.0996 -> 0.10).
    if (u / 10f64.powi(e)).round() >= 100.0 {
        e += 1;
    }
    let scale = 10f64.powi(e);
    // The value keeps the uncertainty's decimals (never rounded into its integer digits:
    // `-1119 ± 190`, as labs write it).
    let du = (u / scale).round() * scale;
    let v = if e < 0 {
        (value / scale).round() * scale
    } else {
        value.round()
    };
    let big = value.abs().max(u);
    if !(1e-4..1e6).contains(&big) {
        // Scientific: a common exponent for both.
        let ex = big.log10().floor() as i32;
        let m = 10f64.powi(ex);
        let dec = (ex - e).max(0) as usize;
        return format!("({:.dec$} ± {:.dec$})e{ex}{sep}{unit}", v / m, du / m,);
    }
    let dec = (-e).max(0) as usize;
    format!("{v:.dec$} ± {du:.dec$}{sep}{unit}")
}

fn trim(v: f64, sig: i32) -> String {
    if v == 0.0 {
        return "0".into();
    }
    let dec = (sig - 1 - v.abs().log10().floor() as i32).max(0) as usize;
    format!("{v:.dec$}")
}

#[cfg(test)]
mod tests {
    use super::format_measured as f;

    #[test]
    fn uncertainty_has_two_significant_digits_and_the_value_matches() {
        assert_eq!(f(-1118.874315, 190.1, "ppm"), "-1119 ± 190 ppm");
        assert_eq!(f(0.0123456, 0.000346, "m/s^2"), "0.01235 ± 0.00035 m/s^2");
        assert_eq!(f(6.137, 0.0996, "mm"), "6.14 ± 0.10 mm");
        assert_eq!(f(15.04, 1.0, "deg/h"), "15.0 ± 1.0 deg/h");
        assert_eq!(f(12345.0, 2345.0, "ppm"), "12345 ± 2300 ppm");
        assert_eq!(f(3.2e-6, 4.1e-7, "deg/s"), "(3.20 ± 0.41)e-6 deg/s");
        assert_eq!(f(1.5, 0.0, "s"), "1.50000 s");
    }
}
