//! The drift of one parameter: a weighted straight line through its calibrations, and the
//! time its confidence bound needs to reach an acceptance limit.

use serde::Serialize;

/// A calibration value at a time: days since 1970, value, standard uncertainty.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Point {
    /// Days since 1970-01-01.
    pub t_days: f64,
    /// Value.
    pub value: f64,
    /// Standard uncertainty (k = 1).
    pub u: f64,
}

/// A fitted drift line, anchored at the last calibration.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Drift {
    /// Drift rate, unit per year.
    pub rate_per_year: f64,
    /// Its standard uncertainty, unit per year.
    pub u_rate_per_year: f64,
    /// Fitted value at the last calibration.
    pub value_at_last: f64,
    /// Its standard uncertainty.
    pub u_value_at_last: f64,
    /// Birge ratio sqrt(chi2/dof) (1 when not estimable); uncertainties are scaled by it
    /// when above 1 (the scatter says more than the stated uncertainties).
    pub birge_ratio: f64,
    #[serde(skip)]
    cov_per_day: f64,
    #[serde(skip)]
    t_last: f64,
}

const YEAR_DAYS: f64 = 365.25;

/// Fits the drift; `None` with fewer than two calibrations on different dates.
pub fn drift(points: &[Point]) -> Option<Drift> {
    let mut days: Vec<i64> = points.iter().map(|p| p.t_days.floor() as i64).collect();
    days.sort_unstable();
    days.dedup();
    if days.len() < 2 {
        return None;
    }
    let t_last = points.iter().map(|p| p.t_days).fold(f64::MIN, f64::max);
    // Weights 1/u^2; a zero or missing uncertainty falls back to equal weights.
    let equal = points.iter().any(|p| !(p.u.is_finite() && p.u > 0.0));
    let (mut s, mut sx, mut sxx, mut sy, mut sxy) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for p in points {
        let w = if equal { 1.0 } else { 1.0 / (p.u * p.u) };
        let x = p.t_days - t_last;
        s += w;
        sx += w * x;
        sxx += w * x * x;
        sy += w * p.value;
        sxy += w * x * p.value;
    }
    let det = s * sxx - sx * sx;
    if det <= 0.0 || !det.is_finite() {
        return None;
    }
    let b = (s * sxy - sx * sy) / det;
    let a = (sxx * sy - sx * sxy) / det;
    let (mut va, mut vb, mut cab) = (sxx / det, s / det, -sx / det);
    let dof = points.len() as f64 - 2.0;
    let chi2: f64 = points
        .iter()
        .map(|p| {
            let w = if equal { 1.0 } else { 1.0 / (p.u * p.u) };
            let r = p.value - a - b * (p.t_days - t_last);
            w * r * r
        })
        .sum();
    let mut birge = 1.0;
    if dof > 0.0 {
        let ratio = chi2 / dof;
        // Equal weights carry no scale of their own: the scatter is the only one.
        if equal || ratio > 1.0 {
            birge = ratio.sqrt();
            va *= ratio;
            vb *= ratio;
            cab *= ratio;
        }
    }
    Some(Drift {
        rate_per_year: b * YEAR_DAYS,
        u_rate_per_year: vb.sqrt() * YEAR_DAYS,
        value_at_last: a,
        u_value_at_last: va.sqrt(),
        birge_ratio: birge,
        cov_per_day: cab,
        t_last,
    })
}

impl Drift {
    /// Predicted value and its standard uncertainty `tau_days` after the last calibration.
    pub fn predict(&self, tau_days: f64) -> (f64, f64) {
        let b = self.rate_per_year / YEAR_DAYS;
        let vb = (self.u_rate_per_year / YEAR_DAYS).powi(2);
        let v = self.u_value_at_last.powi(2)
            + 2.0 * tau_days * self.cov_per_day
            + tau_days * tau_days * vb;
        (self.value_at_last + b * tau_days, v.max(0.0).sqrt())
    }

    /// The fitted line's value at day `t_days` (for plots).
    pub fn at(&self, t_days: f64) -> f64 {
        self.predict(t_days - self.t_last).0
    }
}

/// How a limit bounds a parameter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Bound {
    /// value <= limit (or <).
    Upper,
    /// value >= limit (or >).
    Lower,
    /// |value| <= limit.
    Magnitude,
}

/// Longest interval searched, days (100 years).
pub const HORIZON_DAYS: f64 = 100.0 * YEAR_DAYS;

/// Days after the last calibration until the one-sided bound at coverage factor `k` reaches
/// the limit: `Some(0.0)` when it already has, `None` when not within [`HORIZON_DAYS`].
pub fn interval_days(d: &Drift, bound: Bound, limit: f64, k: f64) -> Option<f64> {
    let margin = |tau: f64| {
        let (y, u) = d.predict(tau);
        match bound {
            Bound::Upper => limit - (y + k * u),
            Bound::Lower => (y - k * u) - limit,
            Bound::Magnitude => limit - (y.abs() + k * u),
        }
    };
    if margin(0.0) <= 0.0 {
        return Some(0.0);
    }
    // The bound widens with time, so the margin falls eventually; find a bracket, then bisect.
    let mut hi = 1.0;
    while margin(hi) > 0.0 {
        hi *= 2.0;
        if hi > HORIZON_DAYS {
            return if margin(HORIZON_DAYS) > 0.0 {
                None
            } else {
                Some(bisect(&margin, hi / 2.0, HORIZON_DAYS))
            };
        }
    }
    Some(bisect(&margin, hi / 2.0, hi))
}

fn bisect(f: &impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    if f(lo) <= 0.0 {
        lo = 0.0;
    }
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if f(mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(rate_per_year: f64, u: f64) -> Vec<Point> {
        (0..6)
            .map(|i| {
                let t = 20000.0 + 180.0 * i as f64;
                Point {
                    t_days: t,
                    value: 0.01 + rate_per_year * (t - 20000.0) / YEAR_DAYS,
                    u,
                }
            })
            .collect()
    }

    #[test]
    fn exact_line_recovers_rate() {
        let d = drift(&line(0.002, 1e-4)).unwrap();
        assert!((d.rate_per_year - 0.002).abs() < 1e-12);
        assert!(d.u_rate_per_year > 0.0);
    }

    #[test]
    fn one_date_is_undetermined() {
        let p = Point {
            t_days: 20000.2,
            value: 1.0,
            u: 0.1,
        };
        let q = Point {
            t_days: 20000.7,
            ..p
        };
        assert!(drift(&[p]).is_none());
        assert!(drift(&[p, q]).is_none());
    }

    #[test]
    fn interval_reaches_limit() {
        let d = drift(&line(0.002, 1e-4)).unwrap();
        let tau = interval_days(&d, Bound::Magnitude, 0.05, 1.645).unwrap();
        // Without uncertainty the line reaches 0.05 at (0.05 - last) / rate years.
        let last = d.value_at_last;
        let naive = (0.05 - last) / 0.002 * YEAR_DAYS;
        assert!(tau > 0.0 && tau < naive, "{tau} vs {naive}");
        assert_eq!(interval_days(&d, Bound::Upper, 0.0, 1.645), Some(0.0));
    }
}
