//! The budget of a derived quantity (`norm(accel.bias)`, `abs(gyro.scale.x)`): the
//! components' combined standard uncertainties propagated (GUM 5.1.2, with the fit's
//! correlations), the effective degrees of freedom by Welch-Satterthwaite over the
//! components' contributions, the coverage factor from Student's t.

use super::{Budget, coverage_factor};

/// `nu_eff = u^4 / sum(u_i^4 / nu_i)` over contributions `u_i` (after sensitivity) with
/// `nu_i` degrees of freedom (`None`: infinitely many); `None` when infinite.
pub fn welch_satterthwaite(u: f64, parts: &[(f64, Option<f64>)]) -> Option<f64> {
    let denom: f64 = parts
        .iter()
        .filter_map(|(ui, nu)| nu.map(|nu| ui.powi(4) / nu))
        .sum();
    (denom > 0.0).then(|| u.powi(4) / denom)
}

/// Value, combined standard uncertainty and coverage factor of `func` (`norm`, `abs` or a
/// bare parameter) of `components`' budgets, each scaled by `to_base` into the limit's base
/// unit, correlated as `r` (row-major, n x n) says.
pub fn derived_budget(
    func: Option<&str>,
    components: &[(&Budget, f64)],
    r: &[f64],
) -> (f64, f64, f64) {
    let v: Vec<f64> = components.iter().map(|(b, f)| b.value * f).collect();
    let u: Vec<f64> = components.iter().map(|(b, f)| b.u_c * f).collect();
    let (value, u_c) = ratecal_plan::derived::evaluate(func, &v, &u, r);
    let c: Vec<f64> = match func {
        Some("norm") if value > 0.0 => v.iter().map(|x| x / value).collect(),
        _ => vec![1.0; v.len()],
    };
    let parts: Vec<(f64, Option<f64>)> = components
        .iter()
        .zip(&u)
        .zip(&c)
        .map(|(((b, _), ui), ci)| ((ci * ui).abs(), b.nu_eff))
        .collect();
    let nu = welch_satterthwaite(u_c, &parts);
    (value, u_c, coverage_factor(nu))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::budget::{Evaluation, Term};

    fn b(value: f64, u: f64, nu: f64) -> Budget {
        let t = Term::stated("fit (Type A)", Evaluation::A, "normal")
            .dof(nu)
            .u(Some(u));
        Budget::combine("q", "mg", value, vec![t])
    }

    #[test]
    fn a_norm_propagates_the_components_budgets_and_their_dof() {
        let (x, y) = (b(3.0, 0.3, 10.0), b(4.0, 0.4, 20.0));
        let (v, u, k) =
            derived_budget(Some("norm"), &[(&x, 1.0), (&y, 1.0)], &[1.0, 0.0, 0.0, 1.0]);
        assert!((v - 5.0).abs() < 1e-12);
        // c = (0.6, 0.8): u^2 = 0.18^2 + 0.32^2
        let want = (0.18f64.powi(2) + 0.32f64.powi(2)).sqrt();
        assert!((u - want).abs() < 1e-12, "{u}");
        let nu = want.powi(4) / (0.18f64.powi(4) / 10.0 + 0.32f64.powi(4) / 20.0);
        assert!((k - coverage_factor(Some(nu))).abs() < 1e-12);
        assert!(k > 2.0, "few degrees of freedom give k above 2: {k}");
    }
}
