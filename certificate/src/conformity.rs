//! Statements of conformity (ILAC-G8:2019) as the run decided them: the certificate never
//! decides again. Each row states its rule (simple or guarded) and the `U` and `k` the
//! analysis judged with, the full budget's for a calibrated parameter or a function of
//! several (results.json `budgets`), the run's Type A uncertainty at k = 2 otherwise.

use crate::model::{Conformity, ConformityCheck};
use ratecal_analysis::results::{Acceptance, Results};

const SIMPLE: &str = "simple acceptance (shared risk): the value itself is compared with the \
                      limit; U is stated beside it";
const GUARDED: &str = "guarded acceptance: the guard band is the expanded uncertainty U \
                       (w = U); a value within U of the limit is neither pass nor fail";

/// The rule of one check, as its row names it.
fn rule_of(a: &Acceptance) -> &'static str {
    if a.rule == "simple" {
        "simple"
    } else {
        "guarded"
    }
}

/// The statements of the run's acceptance checks, `None` when the procedure has none.
pub fn conformity(r: &Results) -> Option<Conformity> {
    if r.acceptance.is_empty() {
        return None;
    }
    let guarded = r.acceptance.iter().filter(|a| a.rule != "simple").count();
    let rule = match guarded {
        0 => format!("ILAC-G8:2019 {SIMPLE}"),
        n if n == r.acceptance.len() => format!("ILAC-G8:2019 {GUARDED}"),
        _ => format!("ILAC-G8:2019, each check under the rule its row names: {SIMPLE}; {GUARDED}"),
    };
    Some(Conformity {
        rule,
        checks: r.acceptance.iter().map(check).collect(),
    })
}

fn check(a: &Acceptance) -> ConformityCheck {
    let verdict = serde_json::to_value(a.verdict)
        .ok()
        .and_then(|v| v.as_str().map(String::from))
        .unwrap_or_default();
    let magnitude = |v: f64| if a.op == "within" { v.abs() } else { v };
    let near = matches!((a.value, a.expanded_u),
        (Some(v), Some(u)) if (magnitude(v) - a.limit).abs() < u);
    let statement = match (a.value, verdict.as_str()) {
        (None, "deferred") => format!("{}: decided over several runs, not by this one", a.name),
        (None, _) => format!("{}: not evaluated", a.name),
        (Some(_), "indeterminate") => format!(
            "{}: the value lies within the guard band around the limit: conformity can be \
             neither stated nor rejected",
            a.name
        ),
        (Some(_), v) => format!(
            "{}: {}{}",
            a.name,
            if v == "pass" {
                "conforms"
            } else {
                "does not conform"
            },
            if near {
                " (the value lies within U of the limit)"
            } else {
                ""
            }
        ),
    };
    let guarded = rule_of(a) == "guarded";
    ConformityCheck {
        name: a.name.clone(),
        value: a.value,
        op: a.op.clone(),
        limit: a.limit,
        unit: a.unit.clone(),
        expanded: a.expanded_u,
        k: a.k.or(a.expanded_u.map(|_| 2.0)),
        rule: rule_of(a).into(),
        guard_band: a.expanded_u.filter(|_| guarded),
        verdict,
        statement,
    }
}
