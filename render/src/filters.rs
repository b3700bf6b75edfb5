//! Number and unit formatting for templates. The analysis hands over plain numbers in their
//! internal units; how a lab wants to read them (significant digits, `±`, SI prefixes,
//! unit symbols) is decided here and in the templates, never in `fit`.

use minijinja::value::ValueKind;
use minijinja::{Environment, Value};

/// What a filter prints for a missing number.
pub const MISSING: &str = "—";

/// What `measured` prints for a parameter the data could not determine.
pub const NOT_DETERMINED: &str = "not determined";

/// Registers every report filter on `env`.
pub fn register(env: &mut Environment<'_>) {
    env.add_filter("measured", measured);
    // The filter's first name, kept for the labs' templates that use it.
    env.add_filter("fmt_value", measured);
    env.add_filter("fmt_num", fmt_num);
    env.add_filter("si", si);
    env.add_filter("ppm", ppm);
    env.add_filter("unit", |u: Option<String>| {
        pretty_unit(u.as_deref().unwrap_or(""))
    });
    env.add_filter("verdict_label", verdict_label);
    env.add_filter("cmp", cmp);
    env.add_filter("value_of", value_of);
    env.add_filter("expanded", expanded);
    env.add_filter("as_written", as_written);
}

/// What a U column prints where no uncertainty is stated (a condition recorded once).
pub const NOT_STATED: &str = "not stated";

/// The expanded uncertainty `u` when it is one (positive and finite).
fn stated(u: Option<Value>) -> Option<f64> {
    u.as_ref()
        .and_then(number)
        .filter(|u| *u > 0.0 && u.is_finite())
}

/// `{{ c.value | value_of(c.expanded_u, c.unit) }}`: a value in a column beside its U,
/// rounded at the place of U's second significant digit (GUM 7.2.6, the rule of
/// `measured`); without a stated U, six significant digits.
pub fn value_of(value: Value, u: Option<Value>, unit: Option<String>) -> String {
    let Some(x) = number(&value) else {
        return MISSING.to_string();
    };
    let unit = pretty_unit(unit.as_deref().unwrap_or(""));
    let text = match stated(u) {
        Some(u) => ratecal_analysis::measured::measured_columns(x, u).0,
        None => ratecal_analysis::measured::format_value(x, ""),
    };
    join_unit(text, &unit)
}

/// `{{ c.expanded_u | expanded(c.unit) }}`: U to two significant digits, or `not stated`
/// where there is none (zero or missing).
pub fn expanded(u: Value, unit: Option<String>) -> String {
    let Some(u) = stated(Some(u)) else {
        return NOT_STATED.to_string();
    };
    let unit = pretty_unit(unit.as_deref().unwrap_or(""));
    join_unit(ratecal_analysis::measured::measured_columns(u, u).1, &unit)
}

/// `{{ c.limit | as_written(c.unit) }}`: a limit as the procedure wrote it (six significant
/// digits, no prefix added: `100.325 kPa`, never `100 kPa`).
pub fn as_written(value: Value, unit: Option<String>) -> String {
    match number(&value) {
        Some(x) => join_unit(
            ratecal_analysis::measured::format_value(x, ""),
            &pretty_unit(unit.as_deref().unwrap_or("")),
        ),
        None => MISSING.to_string(),
    }
}

/// `{{ check.op | cmp }}`: `<=` -> `≤`, `>=` -> `≥` (also the plan's `Le`, `Ge`...); `≤` when absent.
pub fn cmp(op: Option<String>) -> String {
    match op.as_deref().unwrap_or("<=") {
        "<=" | "Le" | "le" => "≤".into(),
        ">=" | "Ge" | "ge" => "≥".into(),
        "<" | "Lt" | "lt" => "<".into(),
        ">" | "Gt" | "gt" => ">".into(),
        other => other.to_string(),
    }
}

/// `{{ x | measured(u, unit) }}`: value and standard uncertainty the way a lab writes them,
/// `u` to two significant digits and the value to the same place (GUM 7.2.6; the rule is
/// [`ratecal_analysis::measured`]'s). Without `u`, four significant digits. Given a parameter entry or
/// an explain parameter (`{{ p | measured }}`), reads its `value`, `u` and `unit`, and prints
/// `not determined` when it is not observable.
pub fn measured(value: Value, u: Option<Value>, unit: Option<String>) -> String {
    let (value, u, unit) = if value.kind() == ValueKind::Map {
        let attr = |k: &str| value.get_attr(k).ok().filter(|v| !v.is_undefined());
        if attr("observable").is_some_and(|o| !o.is_true()) {
            return NOT_DETERMINED.to_string();
        }
        let unit = unit.or_else(|| attr("unit").and_then(|v| v.as_str().map(String::from)));
        (attr("value").unwrap_or_default(), u.or(attr("u")), unit)
    } else {
        (value, u, unit)
    };
    let Some(x) = number(&value) else {
        return MISSING.to_string();
    };
    let unit = unit.map(|s| pretty_unit(&s)).unwrap_or_default();
    let text = match u.as_ref().and_then(number) {
        Some(u) => ratecal_analysis::measured::measured_number(x, u),
        None => sig(x, 4),
    };
    join_unit(text, &unit)
}

/// `{{ x | fmt_num(digits) }}`: `digits` significant digits (4 by default).
pub fn fmt_num(value: Value, digits: Option<u32>) -> String {
    match number(&value) {
        Some(x) => sig(x, digits.unwrap_or(4).clamp(1, 15)),
        None => MISSING.to_string(),
    }
}

/// `{{ x | si(unit, digits) }}`: with an SI prefix when the unit takes one (`2.1e-5 m/s^2`
/// prints `21.0 µm/s²`); other units (deg/s, ppm, degC) keep the number as it is.
pub fn si(value: Value, unit: Option<String>, digits: Option<u32>) -> String {
    let Some(x) = number(&value) else {
        return MISSING.to_string();
    };
    let digits = digits.unwrap_or(3).clamp(1, 15);
    let unit = unit.unwrap_or_default();
    if !prefixable(&unit) || x == 0.0 || !x.is_finite() {
        return join_unit(sig(x, digits), &pretty_unit(&unit));
    }
    const PREFIXES: [(i32, &str); 9] = [
        (-12, "p"),
        (-9, "n"),
        (-6, "µ"),
        (-3, "m"),
        (0, ""),
        (3, "k"),
        (6, "M"),
        (9, "G"),
        (12, "T"),
    ];
    let e3 = ((x.abs().log10() / 3.0).floor() as i32 * 3).clamp(-12, 12);
    let prefix = PREFIXES.iter().find(|p| p.0 == e3).map_or("", |p| p.1);
    let mantissa = x / 10f64.powi(e3);
    // `kPa` already carries a prefix: scale from the base unit instead.
    let (base, factor) = match unit.as_str() {
        "kPa" => ("Pa", 1e3),
        _ => (unit.as_str(), 1.0),
    };
    if factor != 1.0 {
        return si(
            Value::from(x * factor),
            Some(base.to_string()),
            Some(digits),
        );
    }
    format!(
        "{} {prefix}{}",
        plain_sig(mantissa, digits),
        pretty_unit(base)
    )
}

/// `{{ ratio | ppm }}`: a plain ratio (0.0008) as parts per million (`800.0 ppm`).
pub fn ppm(value: Value) -> String {
    match number(&value) {
        Some(x) => format!("{} ppm", sig(x * 1e6, 4)),
        None => MISSING.to_string(),
    }
}

/// `{{ check.verdict | verdict_label }}`: `pass` -> `PASS`, `not_evaluated` -> `NOT EVALUATED`.
pub fn verdict_label(v: Option<String>) -> String {
    match v {
        Some(v) if !v.is_empty() => v.replace(['_', '-'], " ").to_uppercase(),
        _ => MISSING.to_string(),
    }
}

/// Unit symbols as people write them: `m/s^2` -> `m/s²`, `degC` -> `°C`, `deg/s` -> `°/s`.
pub fn pretty_unit(unit: &str) -> String {
    let mut s = unit
        .replace("sqrt(h)", "√h")
        .replace("sqrt(Hz)", "√Hz")
        .replace("degC", "°C")
        .replace("deg", "°")
        .replace("^2", "²")
        .replace("^3", "³")
        .replace("^-1", "⁻¹")
        .replace("ohm", "Ω");
    if let Some(rest) = s.strip_prefix("u")
        && rest
            .chars()
            .next()
            .is_some_and(|c| c.is_ascii_alphabetic() || c == '°')
    {
        s = format!("µ{rest}");
    }
    s
}

fn prefixable(unit: &str) -> bool {
    matches!(
        unit,
        "m/s^2" | "m" | "s" | "Hz" | "Pa" | "kPa" | "V" | "A" | "W"
    )
}

fn join_unit(text: String, unit: &str) -> String {
    if unit.is_empty() {
        text
    } else if unit == "%" || unit == "°" {
        format!("{text}{unit}")
    } else {
        format!("{text} {unit}")
    }
}

/// A number from a template value: integers and floats; none/undefined/strings are missing.
pub fn number(v: &Value) -> Option<f64> {
    if v.is_undefined() || v.is_none() {
        return None;
    }
    f64::try_from(v.clone()).ok()
}

/// `digits` significant digits; scientific notation outside 1e-4 ..= 1e7.
pub fn sig(x: f64, digits: u32) -> String {
    if !x.is_finite() {
        return if x.is_nan() {
            "NaN".into()
        } else if x > 0.0 {
            "∞".into()
        } else {
            "−∞".into()
        };
    }
    if x != 0.0 && (x.abs() < 1e-4 || x.abs() >= 1e7) {
        return format!("{:.*e}", (digits - 1) as usize, x);
    }
    plain_sig(x, digits)
}

fn plain_sig(x: f64, digits: u32) -> String {
    if x == 0.0 {
        return format!("{:.*}", (digits - 1) as usize, 0.0);
    }
    let mag = x.abs().log10().floor() as i32;
    let decimals = (digits as i32 - 1 - mag).max(0) as usize;
    // Rounding can carry into a new digit (9.9996 -> 10.000): recompute once.
    let s = format!("{x:.decimals$}");
    let rounded: f64 = s.parse().unwrap_or(x);
    if rounded != 0.0 && rounded.abs().log10().floor() as i32 > mag && decimals > 0 {
        return format!("{x:.*}", decimals - 1);
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64) -> Value {
        Value::from(x)
    }

    #[test]
    fn measured_rounds_as_the_terminal_does() {
        let m = |x: f64, u: f64, unit: &str| measured(v(x), Some(v(u)), Some(unit.into()));
        assert_eq!(m(0.0210, 0.00002, "m/s^2"), "0.021000 ± 0.000020 m/s²");
        assert_eq!(m(802.1, 3.1, "ppm"), "802.1 ± 3.1 ppm");
        assert_eq!(m(-1118.874315, 190.1, "ppm"), "-1119 ± 190 ppm");
        assert_eq!(m(9.96, 0.0995, "mm"), "9.96 ± 0.10 mm");
        assert_eq!(m(-0.0812, 0.0001, "deg/s"), "-0.08120 ± 0.00010 °/s");
        assert_eq!(m(3.2e-6, 4.1e-7, "deg/s"), "(3.20 ± 0.41)e-6 °/s");
        assert_eq!(m(12.5, 0.25, "%"), "12.50 ± 0.25%");
        // The old name is the same filter.
        let env = {
            let mut e = Environment::new();
            register(&mut e);
            e
        };
        let out = |t: &str| env.render_str(t, ()).unwrap();
        assert_eq!(
            out("{{ 0.01234 | fmt_value(0.00056, 'm/s^2') }}"),
            "0.01234 ± 0.00056 m/s²"
        );
        assert_eq!(
            out("{{ 0.0041 | measured(none, 'deg/s') }}"),
            "0.004100 °/s"
        );
    }

    #[test]
    fn measured_reads_parameter_entries() {
        let env = {
            let mut e = Environment::new();
            register(&mut e);
            e
        };
        let p = serde_json::json!({
            "est": { "observable": true, "value": 350.576388, "u": 0.4771, "unit": "ppm" },
            "explain": { "value": 50.0612, "u": 6.43, "unit": "deg" },
            "unobs": { "observable": false, "reason": "rotate about Z" },
            "needs": { "observable": false, "needs": "accelerate about Z" },
        });
        let ctx = minijinja::context! { p => Value::from(minijinja::value::Serde(&p)) };
        let out = |t: &str| env.render_str(t, ctx.clone()).unwrap();
        assert_eq!(out("{{ p.est | measured }}"), "350.58 ± 0.48 ppm");
        assert_eq!(out("{{ p.explain | measured }}"), "50.1 ± 6.4°");
        assert_eq!(out("{{ p.unobs | measured }}"), "not determined");
        assert_eq!(out("{{ p.needs | measured }}"), "not determined");
        assert_eq!(out("{{ p.missing | measured }}"), MISSING);
    }

    #[test]
    fn missing_numbers_print_a_dash() {
        assert_eq!(measured(Value::UNDEFINED, None, None), MISSING);
        assert_eq!(fmt_num(Value::from(()), None), MISSING);
        assert_eq!(si(Value::from("x"), None, None), MISSING);
    }

    #[test]
    fn conformity_columns_round_as_a_lab_writes_them() {
        // The value at U's second digit, U at two digits, the limit as written.
        let u = Some(v(1.57e-7));
        assert_eq!(
            value_of(v(8.5432e-6), u.clone(), Some("g".into())),
            "8.54e-6 g"
        );
        assert_eq!(expanded(v(1.57e-7), Some("g".into())), "1.6e-7 g");
        assert_eq!(
            value_of(v(20.0), Some(v(0.0)), Some("degC".into())),
            "20 °C"
        );
        assert_eq!(expanded(v(0.0), Some("degC".into())), NOT_STATED);
        assert_eq!(as_written(v(100.325), Some("kPa".into())), "100.325 kPa");
        assert_eq!(
            value_of(v(416.96137), Some(v(16.79)), Some("ppm".into())),
            "417 ppm"
        );
        assert_eq!(expanded(v(16.79), Some("ppm".into())), "17 ppm");
    }

    #[test]
    fn significant_digits() {
        assert_eq!(sig(0.0123456, 3), "0.0123");
        assert_eq!(sig(9.9996, 4), "10.00");
        assert_eq!(sig(123456.0, 3), "123456");
        assert_eq!(sig(2.5e-6, 2), "2.5e-6");
        assert_eq!(fmt_num(Value::from(3), None), "3.000");
    }

    #[test]
    fn si_prefixes() {
        assert_eq!(si(v(2.1e-5), Some("m/s^2".into()), None), "21.0 µm/s²");
        assert_eq!(si(v(0.0196), Some("m/s^2".into()), None), "19.6 mm/s²");
        assert_eq!(si(v(101.3), Some("kPa".into()), Some(4)), "101.3 kPa");
        assert_eq!(si(v(0.05), Some("deg/s".into()), None), "0.0500 °/s");
    }

    #[test]
    fn units_and_ratios() {
        assert_eq!(pretty_unit("deg/sqrt(h)"), "°/√h");
        assert_eq!(pretty_unit("degC"), "°C");
        assert_eq!(pretty_unit("ug"), "µg");
        assert_eq!(ppm(v(0.000802)), "802.0 ppm");
        assert_eq!(verdict_label(Some("not_evaluated".into())), "NOT EVALUATED");
    }
}
