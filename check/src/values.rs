//! Values: resolving names (loop variables, parameters, symbols), converting quantities to
//! internal units and checking their dimensions, and did-you-mean suggestions.

use super::Ck;
use ratecal_grammar::ast::{Span, Value, ValueKind};
use ratecal_grammar::{Diagnostic, format_value};
use ratecal_physics::units;
use ratecal_plan::{Dim, Quantity};

/// A resolved value and where it came from (a list element, a literal, a use of a name).
#[derive(Debug, Clone)]
pub(crate) struct RVal {
    pub v: Val,
    pub span: Span,
}

/// Kinds of resolved values.
#[derive(Debug, Clone)]
pub(crate) enum Val {
    /// A quantity, with its number as written (for segment names).
    Num {
        q: Quantity,
        text: String,
    },
    Str(String),
    /// A name that is neither a variable nor a parameter (`outer`, `x`).
    Sym(String),
    List(Vec<RVal>),
    Tuple(Vec<RVal>),
}

/// Closest candidate to `name`, if close enough to be a likely typo.
pub(crate) fn did_you_mean<'a>(
    name: &str,
    candidates: impl IntoIterator<Item = &'a str>,
) -> Option<String> {
    candidates
        .into_iter()
        .map(|c| (strsim::jaro_winkler(name, c), c))
        .filter(|(s, _)| *s > 0.8)
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, c)| c.to_string())
}

/// A help line with a suggestion, or a list of what is allowed.
pub(crate) fn suggest(name: &str, candidates: &[&str]) -> String {
    match did_you_mean(name, candidates.iter().copied()) {
        Some(c) => format!("did you mean `{c}`?"),
        None => format!("expected one of: {}", candidates.join(", ")),
    }
}

impl Ck<'_> {
    /// Resolves a value: names are looked up in loop variables, then parameters.
    /// `list_unit` is the unit written after an enclosing list, with its span (a unit
    /// error is located on that unit, not on the number it applies to).
    pub(crate) fn resolve(&mut self, v: &Value, list_unit: Option<(&str, Span)>) -> Option<RVal> {
        let span = v.span;
        let val = match &v.kind {
            ValueKind::Quantity { number, unit } => {
                let written: f64 = match number.parse() {
                    Ok(x) => x,
                    Err(_) => {
                        self.err(
                            Diagnostic::error(
                                "check::bad_number",
                                format!("`{number}` is not a number"),
                            )
                            .label(span, "here"),
                        );
                        return None;
                    }
                };
                let unit_at = unit
                    .as_ref()
                    .map(|u| (u.node.as_str(), u.span))
                    .or(list_unit);
                let q = match unit_at.map(|(u, _)| u) {
                    None => Quantity {
                        written,
                        unit: String::new(),
                        dim: Dim::Number,
                        value: written,
                    },
                    Some(u) => match units::to_internal(written, u) {
                        Some((dim, value)) => Quantity {
                            written,
                            unit: u.to_string(),
                            dim,
                            value,
                        },
                        None => {
                            let names: Vec<&str> =
                                units::UNITS.iter().map(|(n, _, _)| *n).collect();
                            let uspan = unit_at.map_or(span, |(_, s)| s);
                            self.err(
                                Diagnostic::error(
                                    "check::unknown_unit",
                                    format!("unknown unit `{u}`"),
                                )
                                .label(uspan, "not a unit ratecal knows")
                                .help(suggest(u, &names)),
                            );
                            return None;
                        }
                    },
                };
                if !q.value.is_finite() {
                    self.err(
                        Diagnostic::error("check::bad_number", "number out of range")
                            .label(span, "not finite"),
                    );
                    return None;
                }
                Val::Num {
                    q,
                    text: number.clone(),
                }
            }
            ValueKind::Str(s) => Val::Str(s.clone()),
            ValueKind::Name(n) => {
                if let Some(r) = self.lookup(n, span) {
                    return Some(r);
                }
                Val::Sym(n.clone())
            }
            ValueKind::List { items, unit } => {
                let u = unit
                    .as_ref()
                    .map(|u| (u.node.as_str(), u.span))
                    .or(list_unit);
                let mut out = Vec::with_capacity(items.len());
                for i in items {
                    out.push(self.resolve(i, u)?);
                }
                Val::List(out)
            }
            ValueKind::Tuple(items) => {
                let mut out = Vec::with_capacity(items.len());
                for i in items {
                    out.push(self.resolve(i, list_unit)?);
                }
                Val::Tuple(out)
            }
        };
        Some(RVal { v: val, span })
    }

    fn lookup(&self, name: &str, use_span: Span) -> Option<RVal> {
        for scope in self.scopes.iter().rev() {
            if let Some((_, v)) = scope.iter().find(|(n, _)| n == name) {
                return Some(v.clone());
            }
        }
        let (v, imported) = self.params.get(name)?;
        // Values from an imported file carry spans of that file: report at the use site.
        Some(if *imported {
            respan(v.clone(), use_span)
        } else {
            v.clone()
        })
    }

    /// Names a value could have referred to (for did-you-mean).
    pub(crate) fn known_names(&self) -> Vec<String> {
        let mut out: Vec<String> = self
            .scopes
            .iter()
            .flatten()
            .map(|(n, _)| n.clone())
            .collect();
        out.extend(self.params.keys().cloned());
        out
    }

    /// Resolves a value that must be a quantity of dimension `dim`.
    pub(crate) fn quantity(&mut self, v: &Value, dim: Dim, what: &str) -> Option<Quantity> {
        let r = self.resolve(v, None)?;
        self.as_quantity(&r, v, dim, what)
    }

    /// Checks that a resolved value is a quantity of dimension `dim`.
    pub(crate) fn as_quantity(
        &mut self,
        r: &RVal,
        v: &Value,
        dim: Dim,
        what: &str,
    ) -> Option<Quantity> {
        let span = if r.span == Span::default() {
            v.span
        } else {
            r.span
        };
        match &r.v {
            Val::Num { q, .. } if q.dim == dim => Some(q.clone()),
            Val::Num { q, text } if q.dim == Dim::Number => {
                let example = example_unit(dim);
                self.err(
                    Diagnostic::error("check::missing_unit", format!("{what} needs a unit"))
                        .label(
                            span,
                            format!(
                                "a bare number where {} {} is expected",
                                article(dim),
                                dim.name()
                            ),
                        )
                        .help(format!("write it with its unit, e.g. `{text} {example}`")),
                );
                None
            }
            Val::Num { q, .. } => {
                self.err(
                    Diagnostic::error(
                        "check::unit_mismatch",
                        format!(
                            "{what} must be {} {}, not {} {}",
                            article(dim),
                            dim.name(),
                            article(q.dim),
                            q.dim.name()
                        ),
                    )
                    .label(
                        span,
                        format!("`{}` is {} {}", q.unit, article(q.dim), q.dim.name()),
                    )
                    .help(format!(
                        "use a unit of {}, e.g. {}",
                        dim.name(),
                        example_unit(dim)
                    )),
                );
                None
            }
            Val::Sym(n) => {
                self.unknown_name(n, span);
                None
            }
            _ => {
                let shown = format_value(v);
                self.err(
                    Diagnostic::error("check::type_mismatch", format!("{what} must be a quantity"))
                        .label(span, format!("`{shown}` is not a quantity"))
                        .help(format!(
                            "write {} {}, e.g. `1 {}`",
                            article(dim),
                            dim.name(),
                            example_unit(dim)
                        )),
                );
                None
            }
        }
    }

    /// Reports an unknown name with a suggestion among variables and parameters.
    pub(crate) fn unknown_name(&mut self, name: &str, span: Span) {
        let names = self.known_names();
        let help = match did_you_mean(name, names.iter().map(String::as_str)) {
            Some(c) => format!("did you mean `{c}`?"),
            None if names.is_empty() => {
                "no loop variable or parameter is in scope here".to_string()
            }
            None => format!("names in scope: {}", names.join(", ")),
        };
        self.err(
            Diagnostic::error("check::unknown_name", format!("unknown name `{name}`"))
                .label(span, "not a loop variable or parameter")
                .help(help),
        );
    }

    /// Resolves a positive integer count.
    pub(crate) fn count(&mut self, v: &Value, what: &str) -> Option<u64> {
        let q = self.quantity(v, Dim::Number, what)?;
        if q.value < 0.0 || q.value.fract() != 0.0 || q.value > 1e18 {
            self.err(
                Diagnostic::error("check::bad_count", format!("{what} must be a whole number"))
                    .label(v.span, "not a whole non-negative number"),
            );
            return None;
        }
        Some(q.value as u64)
    }
}

fn respan(mut r: RVal, span: Span) -> RVal {
    r.span = span;
    r.v = match r.v {
        Val::List(items) => Val::List(items.into_iter().map(|i| respan(i, span)).collect()),
        Val::Tuple(items) => Val::Tuple(items.into_iter().map(|i| respan(i, span)).collect()),
        other => other,
    };
    r
}

fn article(d: Dim) -> &'static str {
    if d.name().starts_with(['a', 'e', 'i', 'o', 'u']) {
        "an"
    } else {
        "a"
    }
}

fn example_unit(d: Dim) -> &'static str {
    match d {
        Dim::Angle => "deg",
        Dim::Rate => "deg/s",
        Dim::Accel => "g",
        Dim::Time => "s",
        Dim::Frequency => "Hz",
        Dim::Temperature => "degC",
        Dim::TemperatureRate => "degC/h",
        Dim::Length => "mm",
        Dim::Ratio => "%",
        Dim::Pressure => "kPa",
        Dim::Number => "",
    }
}
