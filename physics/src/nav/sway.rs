//! The swaying coefficient `c(A, T)` of Kozlov & Kapralov's equation (6).

use std::f64::consts::PI;

/// `c(A, T) = T^2 / (4 pi^2 A J1(A))` in s^2, amplitude `a_rad` in radians, period `t_s` in s:
/// over a period of `th0 + A sin(2 pi t / T)`, `<th'' sin th> = -cos(th0) / c`.
pub fn sway_coefficient(a_rad: f64, t_s: f64) -> f64 {
    t_s * t_s / (4.0 * PI * PI * a_rad * libm::j1(a_rad))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_papers_value_at_90_deg_and_5_s() {
        // J1(pi/2) = 0.566824088905874 (crates.md); physics.md: c(pi/2, 5 s) = 0.711 s^2.
        assert!((libm::j1(PI / 2.0) - 0.566824088905874).abs() < 1e-14);
        let c = sway_coefficient(PI / 2.0, 5.0);
        assert!((c - 0.711).abs() < 5e-4, "{c}");
        assert!((sway_coefficient(PI / 2.0, 10.0) - 4.0 * c).abs() < 1e-12);
    }

    #[test]
    fn matches_the_period_average_it_stands_for() {
        // <th'' sin th> over one period, by quadrature, against -cos(th0) / c.
        let (a, t, th0) = (1.2_f64, 7.0_f64, 0.4_f64);
        let w = 2.0 * PI / t;
        let n = 20_000;
        let mut sum = 0.0;
        for k in 0..n {
            let s = w * t * (k as f64 + 0.5) / n as f64;
            let th = th0 + a * s.sin();
            let acc = -a * w * w * s.sin();
            sum += acc * th.sin();
        }
        let mean = sum / n as f64;
        assert!((mean + th0.cos() / sway_coefficient(a, t)).abs() < 1e-9);
    }
}
