//! Which quantities get a budget, and the degrees of freedom of their Type A term.

use super::Budget;
use super::terms::{Stated, budget};
use crate::results::{Parameter, Results};

/// Quantities that describe noise rather than calibrate the model: no budget, not stated
/// as results on a certificate.
pub fn reported(name: &str) -> bool {
    ![".noise.", ".arw.", ".bias_instability."]
        .iter()
        .any(|n| name.contains(n))
}

/// The budget of every reported parameter of `res` the fit estimated, under `stated`.
pub fn budgets(res: &Results, stated: &Stated) -> Vec<Budget> {
    res.parameters
        .iter()
        .filter_map(|(name, p)| match p {
            Parameter::Estimate { value, u, unit } if reported(name) => Some(budget(
                name,
                *value,
                *u,
                unit,
                type_a_dof(res, name),
                stated,
            )),
            _ => None,
        })
        .collect()
}

/// The fit's Type A degrees of freedom for `quantity` (`sensor.family.axis`): the fit's
/// uncertainty rests on the noise it estimates from the one-second block means of the
/// segments that determine the quantity (physics.md's noise model), so each of those
/// segments gives its one-second blocks less one (its mean). The segments are those used
/// for the quantity's own fit (`used_for` `gyro_bias` for `gyro.bias.x`), else for the
/// sensor's full model (`gyro_full`, `gyro`), else any of the sensor's fits. At least 1.
pub fn type_a_dof(results: &Results, quantity: &str) -> f64 {
    let mut parts = quantity.split('.');
    let sensor = parts.next().unwrap_or("");
    let family = parts.next().unwrap_or("");
    let own = format!("{sensor}_{family}");
    let prefix = format!("{sensor}_");
    let count = |wanted: &dyn Fn(&str) -> bool| -> (usize, f64) {
        results
            .segments
            .iter()
            .filter(|s| s.used_for.iter().any(|u| wanted(u)))
            .fold((0, 0.0), |(n, blocks), s| {
                (n + 1, blocks + (s.t_end - s.t_start).round().max(1.0))
            })
    };
    let full = format!("{sensor}_full");
    let mut used = count(&|u| u == own);
    if used.0 == 0 {
        used = count(&|u| u == full);
    }
    if used.0 == 0 {
        used = count(&|u| u == sensor);
    }
    if used.0 == 0 {
        used = count(&|u| u.starts_with(&prefix));
    }
    (used.1 - used.0 as f64).max(1.0)
}
