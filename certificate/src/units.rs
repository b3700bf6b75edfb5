//! Units as a reader expects them printed: `m/s²`, `°/s`, `°C`, `µrad`; the data (JSON,
//! results.json) keeps the plain spelling.

/// `unit` as printed.
pub fn pretty(unit: &str) -> String {
    if unit == "deg" {
        return "°".into();
    }
    unit.replace("^2", "²")
        .replace("^3", "³")
        .replace("degC", "°C")
        .replace("deg/s", "°/s")
        .replace("deg/h", "°/h")
        .replace("urad", "µrad")
}

/// A value and its unit, a space between (none before `°`).
pub fn with_unit(value: &str, unit: &str) -> String {
    match pretty(unit) {
        u if u.is_empty() => value.into(),
        u if u == "°" => format!("{value}°"),
        u => format!("{value} {u}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units_are_printed_with_their_signs() {
        assert_eq!(pretty("m/s^2"), "m/s²");
        assert_eq!(pretty("deg/s"), "°/s");
        assert_eq!(pretty("ppm per degC"), "ppm per °C");
        assert_eq!(with_unit("55.7", "deg"), "55.7°");
        assert_eq!(with_unit("3", "mrad"), "3 mrad");
    }
}
