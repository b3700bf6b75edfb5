//! Random-effects pooling (DerSimonian and Laird, 1986): values with their own standard
//! uncertainties, pooled with a spread between them beyond those uncertainties. Pure
//! statistics: nothing here knows explain.

/// One value and its standard uncertainty.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Obs {
    /// Value.
    pub y: f64,
    /// Standard uncertainty (> 0).
    pub u: f64,
}

/// A random-effects pool.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Pooled {
    /// The pooled value.
    pub mean: f64,
    /// Its standard uncertainty (the spread included).
    pub u: f64,
    /// The spread between the values beyond their own uncertainties (tau).
    pub tau: f64,
    /// Heterogeneity I^2 in [0, 1]: the share of the variation that is spread, not noise.
    pub i2: f64,
    /// Cochran's Q.
    pub q: f64,
    /// Its degrees of freedom (values less one).
    pub dof: usize,
}

/// DerSimonian-Laird: the fixed-effect weights `1/u^2` give Cochran's `Q`; the spread is
/// `tau^2 = max(0, (Q - (k-1)) / (S1 - S2/S1))`; the pool weighs `1/(u^2 + tau^2)`. One
/// value is its own pool. `None` without any value.
pub(crate) fn dersimonian_laird(obs: &[Obs]) -> Option<Pooled> {
    let obs: Vec<Obs> = obs
        .iter()
        .copied()
        .filter(|o| o.y.is_finite() && o.u.is_finite() && o.u > 0.0)
        .collect();
    let k = obs.len();
    if k == 0 {
        return None;
    }
    let w: Vec<f64> = obs.iter().map(|o| 1.0 / (o.u * o.u)).collect();
    let s1: f64 = w.iter().sum();
    let s2: f64 = w.iter().map(|w| w * w).sum();
    let fixed = obs.iter().zip(&w).map(|(o, w)| w * o.y).sum::<f64>() / s1;
    let q: f64 = obs
        .iter()
        .zip(&w)
        .map(|(o, w)| w * (o.y - fixed).powi(2))
        .sum();
    let dof = k - 1;
    let denom = s1 - s2 / s1;
    let tau2 = if dof == 0 || denom <= 0.0 {
        0.0
    } else {
        ((q - dof as f64) / denom).max(0.0)
    };
    let wr: Vec<f64> = obs.iter().map(|o| 1.0 / (o.u * o.u + tau2)).collect();
    let sr: f64 = wr.iter().sum();
    let mean = obs.iter().zip(&wr).map(|(o, w)| w * o.y).sum::<f64>() / sr;
    let i2 = if q > dof as f64 && q > 0.0 {
        (q - dof as f64) / q
    } else {
        0.0
    };
    Some(Pooled {
        mean,
        u: (1.0 / sr).sqrt(),
        tau: tau2.sqrt(),
        i2,
        q,
        dof,
    })
}

/// Two-sided p-value of a standard normal statistic.
pub(crate) fn p_normal(z: f64) -> f64 {
    super::super::stats::p_value(z * z, 1)
}

/// Benjamini-Hochberg at level `q` over `p`: which hypotheses are rejected.
pub(crate) fn benjamini_hochberg(p: &[f64], q: f64) -> Vec<bool> {
    let m = p.len();
    let mut order: Vec<usize> = (0..m).collect();
    order.sort_by(|&a, &b| p[a].total_cmp(&p[b]));
    let last = (0..m)
        .rev()
        .find(|&r| p[order[r]] <= q * (r + 1) as f64 / m as f64);
    let mut out = vec![false; m];
    if let Some(last) = last {
        for &i in &order[..=last] {
            out[i] = true;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn obs(v: &[(f64, f64)]) -> Vec<Obs> {
        v.iter().map(|&(y, u)| Obs { y, u }).collect()
    }

    #[test]
    fn equal_values_have_no_spread() {
        let p = dersimonian_laird(&obs(&[(2.0, 1.0), (2.0, 1.0), (2.0, 1.0), (2.0, 1.0)])).unwrap();
        assert!((p.mean - 2.0).abs() < 1e-12);
        assert!((p.u - 0.5).abs() < 1e-12, "{}", p.u);
        assert_eq!((p.tau, p.i2), (0.0, 0.0));
    }

    #[test]
    fn spread_beyond_the_uncertainties_is_tau() {
        // Two pairs 10 apart with u = 1: Q = 4 * 25 = 100 on 3 dof; S1 = 4, S2 = 4:
        // tau^2 = (100 - 3) / (4 - 1) = 32.33.
        let p =
            dersimonian_laird(&obs(&[(0.0, 1.0), (0.0, 1.0), (10.0, 1.0), (10.0, 1.0)])).unwrap();
        assert!((p.mean - 5.0).abs() < 1e-12);
        assert!((p.tau * p.tau - 97.0 / 3.0).abs() < 1e-9, "{}", p.tau);
        assert!((p.i2 - 0.97).abs() < 1e-12);
        assert!((p.u - ((1.0f64 + 97.0 / 3.0) / 4.0).sqrt()).abs() < 1e-12);
    }

    #[test]
    fn bh_rejects_up_to_the_largest_passing_rank() {
        let r = benjamini_hochberg(&[0.01, 0.04, 0.03, 0.5], 0.05);
        // Ranks: 0.01 <= 0.0125, 0.03 <= 0.025? no, 0.04 <= 0.0375? no: only the first.
        assert_eq!(r, vec![true, false, false, false]);
        let r = benjamini_hochberg(&[0.001, 0.02, 0.03, 0.04], 0.05);
        assert_eq!(r, vec![true, true, true, true]);
    }
}
