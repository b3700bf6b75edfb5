//! The uncertainty budget of one reported quantity, GUM style: each term's standard
//! uncertainty in the quantity's unit (after its sensitivity coefficient), the combined
//! standard uncertainty `u_c = sqrt(sum u_i^2)`, the effective degrees of freedom
//! (Welch-Satterthwaite, `nu_eff = u_c^4 / sum(u_i^4 / nu_i)`, a Type B term from stated
//! bounds having infinitely many), the coverage factor `k` (Student's t, two-sided 95 %)
//! and the expanded uncertainty `U = k u_c`.
//!
//! Computed at analysis time wherever the station states Type B figures
//! ([`crate::fit::Options::stated`]) and stored in results.json (`budgets`): the run's
//! verdict, the report and the certificate use the same `U` and `k`.

mod derived;
mod dof;
pub mod terms;

pub use derived::{derived_budget, welch_satterthwaite};
pub use dof::{budgets, reported, type_a_dof};

use serde::{Deserialize, Serialize};
use statrs::distribution::{ContinuousCDF, Normal, StudentsT};

/// The coverage probability every result is stated at.
pub const COVERAGE: f64 = 0.95;

/// GUM's evaluation types.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Evaluation {
    /// Statistical analysis of the measurements (the fit).
    A,
    /// Other means (what the station file states).
    B,
}

/// Whether the station file gives the figure a term needs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TermStatus {
    /// Given: the term counts.
    Stated,
    /// Not given: shown as "not stated", never as 0, and left out of `u_c`.
    NotStated,
}

/// One line of a budget.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Term {
    /// Where it comes from (`fit (Type A)`, `table rate accuracy`...).
    pub source: String,
    /// `A` or `B`.
    #[serde(rename = "type")]
    pub evaluation: Evaluation,
    /// `normal` or `rectangular`.
    pub distribution: String,
    /// The figure as stated (`10 ppm`, `5 arcsec`), when stated.
    pub stated: Option<String>,
    /// The sensitivity coefficient, with its unit.
    pub sensitivity: String,
    /// Standard uncertainty in the quantity's unit after the sensitivity coefficient;
    /// `None` when not stated.
    pub u: Option<f64>,
    /// Degrees of freedom; `None` for infinitely many (a stated bound).
    pub dof: Option<f64>,
    /// `stated` or `not_stated`.
    pub status: TermStatus,
}

impl Term {
    /// A term whose figure is known: `u` after sensitivity, `dof` (`None`: infinite).
    pub fn stated(source: &str, evaluation: Evaluation, distribution: &str) -> TermBuilder {
        TermBuilder(Term {
            source: source.into(),
            evaluation,
            distribution: distribution.into(),
            stated: None,
            sensitivity: "1".into(),
            u: None,
            dof: None,
            status: TermStatus::Stated,
        })
    }
}

/// Fills a [`Term`] field by field.
pub struct TermBuilder(Term);

impl TermBuilder {
    /// The figure as the station file states it.
    pub fn figure(mut self, text: impl Into<String>) -> Self {
        self.0.stated = Some(text.into());
        self
    }
    /// The sensitivity coefficient, as text with its unit.
    pub fn sensitivity(mut self, text: impl Into<String>) -> Self {
        self.0.sensitivity = text.into();
        self
    }
    /// Degrees of freedom (a Type A term's).
    pub fn dof(mut self, nu: f64) -> Self {
        self.0.dof = Some(nu);
        self
    }
    /// The standard uncertainty after sensitivity, or `None`: "not stated".
    pub fn u(mut self, u: Option<f64>) -> Term {
        self.0.status = if u.is_some() {
            TermStatus::Stated
        } else {
            TermStatus::NotStated
        };
        self.0.u = u;
        self.0
    }
}

/// The budget of one reported quantity.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Budget {
    /// As results.json names it (`gyro.scale.x`).
    pub quantity: String,
    /// Its unit.
    pub unit: String,
    /// Its value.
    pub value: f64,
    /// Every term, Type A first.
    pub terms: Vec<Term>,
    /// Combined standard uncertainty of the stated terms.
    pub u_c: f64,
    /// Effective degrees of freedom; `None` when infinite (no term has finitely many).
    pub nu_eff: Option<f64>,
    /// Coverage factor for 95 %.
    pub k: f64,
    /// Expanded uncertainty `k u_c`.
    #[serde(rename = "U")]
    pub expanded: f64,
    /// Whether every term is stated (otherwise U understates and the certificate says so).
    pub complete: bool,
}

impl Budget {
    /// Combines `terms` (GUM 5.1.2 with unit sensitivities already applied, G.4.1, G.3).
    pub fn combine(quantity: &str, unit: &str, value: f64, terms: Vec<Term>) -> Budget {
        let stated: Vec<(f64, Option<f64>)> = terms
            .iter()
            .filter_map(|t| t.u.map(|u| (u, t.dof)))
            .collect();
        let u_c = stated.iter().map(|(u, _)| u * u).sum::<f64>().sqrt();
        let denom: f64 = stated
            .iter()
            .filter_map(|(u, nu)| nu.map(|nu| u.powi(4) / nu))
            .sum();
        let nu_eff = (denom > 0.0).then(|| u_c.powi(4) / denom);
        let k = coverage_factor(nu_eff);
        Budget {
            quantity: quantity.into(),
            unit: unit.into(),
            value,
            complete: terms.iter().all(|t| t.status == TermStatus::Stated),
            terms,
            u_c,
            nu_eff,
            k,
            expanded: k * u_c,
        }
    }
}

/// The two-sided 95 % coverage factor: Student's t with `nu` degrees of freedom (GUM G.3;
/// a fractional `nu` is used as it is), the normal's 1.96 for infinitely many.
pub fn coverage_factor(nu: Option<f64>) -> f64 {
    let p = 0.5 + COVERAGE / 2.0;
    match nu {
        // Past 1e6 degrees of freedom t and the normal agree to 1e-6 (and statrs's t
        // quantile search slows without bound as nu grows).
        Some(nu) if nu.is_finite() && nu > 0.0 && nu < 1e6 => StudentsT::new(0.0, 1.0, nu)
            .map(|t| t.inverse_cdf(p))
            .unwrap_or(f64::NAN),
        _ => Normal::standard().inverse_cdf(p),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_coverage_factor_is_students_t_and_the_normal_at_infinity() {
        // Tabulated two-sided 95 % points (GUM table G.2).
        for (nu, k) in [(1.0, 12.706), (4.0, 2.776), (10.0, 2.228), (30.0, 2.042)] {
            assert!((coverage_factor(Some(nu)) - k).abs() < 1e-3, "nu {nu}");
        }
        assert!((coverage_factor(None) - 1.960).abs() < 1e-3);
        // A huge nu_eff (a Type B term dwarfing the fit's) answers at once, as the normal.
        assert!((coverage_factor(Some(1e20)) - 1.960).abs() < 1e-3);
        assert!((coverage_factor(Some(999_999.0)) - 1.960).abs() < 1e-3);
    }

    #[test]
    fn a_term_not_stated_is_left_out_and_marks_the_budget_incomplete() {
        let a = Term::stated("fit", Evaluation::A, "normal")
            .dof(9.0)
            .u(Some(3.0));
        let b = Term::stated("table", Evaluation::B, "rectangular").u(None);
        let budget = Budget::combine("gyro.scale.x", "ppm", 1.0, vec![a, b]);
        assert_eq!(budget.u_c, 3.0);
        assert!(!budget.complete);
        assert_eq!(budget.terms[1].status, TermStatus::NotStated);
        // Type A alone: nu_eff is its own dof.
        assert!((budget.nu_eff.unwrap() - 9.0).abs() < 1e-12);
    }
}
