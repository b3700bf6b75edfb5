//! Direction-aware comparison of limits: whether a change makes a threshold or a rule
//! stricter (`Tightened`) or more permissive (`Loosened`). Values are compared in
//! internal units, so `0.002 g` and `2 mg` are the same limit.

use super::change::{ChangeKind, same};
use ratecal_plan::{AbortAction, Cmp, DecisionRule, OnTimeout};

/// Which side a comparison bounds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Bound {
    /// `<=`, `<`: the value must stay below.
    Upper,
    /// `>=`, `>`: the value must stay above.
    Lower,
}

fn bound(op: Cmp) -> (Bound, bool) {
    match op {
        Cmp::Le => (Bound::Upper, false),
        Cmp::Lt => (Bound::Upper, true),
        Cmp::Ge => (Bound::Lower, false),
        Cmp::Gt => (Bound::Lower, true),
    }
}

/// The operator as written (`<=`).
pub fn op_str(op: Cmp) -> &'static str {
    match op {
        Cmp::Le => "<=",
        Cmp::Lt => "<",
        Cmp::Ge => ">=",
        Cmp::Gt => ">",
    }
}

/// How `value op limit` changed, or `None` when it means the same. Raising an upper limit
/// loosens it, lowering a lower limit loosens it; `<=` to `<` at the same value tightens;
/// flipping the side (`<=` to `>=`) is a plain `Changed`.
pub fn threshold(old_op: Cmp, old: f64, new_op: Cmp, new: f64) -> Option<ChangeKind> {
    let (ob, ostrict) = bound(old_op);
    let (nb, nstrict) = bound(new_op);
    if ob != nb {
        return Some(ChangeKind::Changed);
    }
    if same(old, new) {
        return match (ostrict, nstrict) {
            (false, true) => Some(ChangeKind::Tightened),
            (true, false) => Some(ChangeKind::Loosened),
            _ => None,
        };
    }
    let raised = new > old;
    Some(match (ob, raised) {
        (Bound::Upper, true) | (Bound::Lower, false) => ChangeKind::Loosened,
        _ => ChangeKind::Tightened,
    })
}

/// An upper limit (`<= limit`, a rule's `> limit`, a persistence): raising loosens.
pub fn upper(old: f64, new: f64) -> Option<ChangeKind> {
    threshold(Cmp::Le, old, Cmp::Le, new)
}

/// A lower limit (`>= limit`, a minimum time): lowering loosens.
pub fn lower(old: f64, new: f64) -> Option<ChangeKind> {
    threshold(Cmp::Ge, old, Cmp::Ge, new)
}

/// A plain value with no direction of strictness.
pub fn plain(old: f64, new: f64) -> Option<ChangeKind> {
    (!same(old, new)).then_some(ChangeKind::Changed)
}

/// An optional upper limit: gaining one tightens, losing one loosens.
pub fn optional_upper(old: Option<f64>, new: Option<f64>) -> Option<ChangeKind> {
    match (old, new) {
        (Some(o), Some(n)) => upper(o, n),
        (None, Some(_)) => Some(ChangeKind::Tightened),
        (Some(_), None) => Some(ChangeKind::Loosened),
        (None, None) => None,
    }
}

/// An optional lower limit: gaining one tightens, losing one loosens.
pub fn optional_lower(old: Option<f64>, new: Option<f64>) -> Option<ChangeKind> {
    match (old, new) {
        (Some(o), Some(n)) => lower(o, n),
        (None, Some(_)) => Some(ChangeKind::Tightened),
        (Some(_), None) => Some(ChangeKind::Loosened),
        (None, None) => None,
    }
}

/// One direction for several changes of one item: all the same way, or `Changed`.
pub fn combine(kinds: impl IntoIterator<Item = Option<ChangeKind>>) -> Option<ChangeKind> {
    let mut out: Option<ChangeKind> = None;
    for k in kinds.into_iter().flatten() {
        out = match out {
            None => Some(k),
            Some(prev) if prev == k => Some(k),
            Some(_) => Some(ChangeKind::Changed),
        };
    }
    out
}

/// An abort rule's action: `abort` to `warn` weakens the rule.
pub fn abort_action(old: AbortAction, new: AbortAction) -> Option<ChangeKind> {
    match (old, new) {
        (AbortAction::Abort, AbortAction::Warn) => Some(ChangeKind::Loosened),
        (AbortAction::Warn, AbortAction::Abort) => Some(ChangeKind::Tightened),
        _ => None,
    }
}

fn timeout_rank(t: OnTimeout) -> u8 {
    match t {
        OnTimeout::Continue => 0,
        OnTimeout::Warn => 1,
        OnTimeout::Abort => 2,
    }
}

/// A settle timeout's consequence: from `abort` towards `continue` loosens.
pub fn on_timeout(old: OnTimeout, new: OnTimeout) -> Option<ChangeKind> {
    match timeout_rank(new).cmp(&timeout_rank(old)) {
        std::cmp::Ordering::Less => Some(ChangeKind::Loosened),
        std::cmp::Ordering::Greater => Some(ChangeKind::Tightened),
        std::cmp::Ordering::Equal => None,
    }
}

/// A decision rule: guard-banded is stricter than simple.
pub fn decision_rule(old: DecisionRule, new: DecisionRule) -> Option<ChangeKind> {
    match (old, new) {
        (DecisionRule::Simple, DecisionRule::GuardBanded) => Some(ChangeKind::Tightened),
        (DecisionRule::GuardBanded, DecisionRule::Simple) => Some(ChangeKind::Loosened),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ChangeKind::*;

    #[test]
    fn raising_an_upper_limit_loosens_it() {
        assert_eq!(threshold(Cmp::Le, 0.002, Cmp::Le, 0.003), Some(Loosened));
        assert_eq!(threshold(Cmp::Le, 0.003, Cmp::Le, 0.002), Some(Tightened));
        assert_eq!(threshold(Cmp::Lt, 1.0, Cmp::Lt, 2.0), Some(Loosened));
    }

    #[test]
    fn lowering_a_lower_limit_loosens_it() {
        assert_eq!(threshold(Cmp::Ge, 1800.0, Cmp::Ge, 600.0), Some(Loosened));
        assert_eq!(threshold(Cmp::Ge, 600.0, Cmp::Ge, 1800.0), Some(Tightened));
        assert_eq!(threshold(Cmp::Gt, 5.0, Cmp::Ge, 5.0), Some(Loosened));
    }

    #[test]
    fn strictness_at_equal_limits() {
        assert_eq!(threshold(Cmp::Le, 5.0, Cmp::Lt, 5.0), Some(Tightened));
        assert_eq!(threshold(Cmp::Lt, 5.0, Cmp::Le, 5.0), Some(Loosened));
        assert_eq!(threshold(Cmp::Le, 5.0, Cmp::Le, 5.0), None);
        // 0.002 g against 2 mg, both in m/s^2
        assert_eq!(
            threshold(Cmp::Le, 0.002 * 9.80665, Cmp::Le, 2.0 * 9.80665e-3),
            None
        );
    }

    #[test]
    fn flipping_the_side_is_a_plain_change() {
        assert_eq!(threshold(Cmp::Le, 5.0, Cmp::Ge, 5.0), Some(Changed));
    }

    #[test]
    fn optional_limits_and_rules() {
        assert_eq!(optional_upper(Some(1.0), None), Some(Loosened));
        assert_eq!(optional_upper(None, Some(1.0)), Some(Tightened));
        assert_eq!(optional_lower(Some(1.0), None), Some(Loosened));
        assert_eq!(
            abort_action(AbortAction::Abort, AbortAction::Warn),
            Some(Loosened)
        );
        assert_eq!(
            on_timeout(OnTimeout::Abort, OnTimeout::Continue),
            Some(Loosened)
        );
        assert_eq!(
            on_timeout(OnTimeout::Warn, OnTimeout::Abort),
            Some(Tightened)
        );
        assert_eq!(
            decision_rule(DecisionRule::GuardBanded, DecisionRule::Simple),
            Some(Loosened)
        );
        assert_eq!(
            combine([Some(Loosened), None, Some(Loosened)]),
            Some(Loosened)
        );
        assert_eq!(combine([Some(Loosened), Some(Tightened)]), Some(Changed));
        assert_eq!(combine([None, None]), None);
    }
}
