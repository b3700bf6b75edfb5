//! Overlapping Allan deviation of the gyros over a static block: angle random walk at
//! tau = 1 s and bias instability (minimum of the curve / 0.664).

use super::{AXES, Out};
use crate::results::{AllanCurve, Parameter};

/// Overlapping Allan deviation of `y` sampled every `dt`, at octave cluster sizes
/// `m = 1, 2, 4, ...` up to a quarter of the series: `(tau, adev, clusters)`.
pub fn overlapping_adev(y: &[f64], dt: f64) -> Vec<(f64, f64, usize)> {
    adev_of_angle(&integrated(y.to_vec(), dt), dt)
}

/// The integrated angle `theta` of a rate series (`theta[0] = 0`), in the series' own
/// memory.
fn integrated(mut y: Vec<f64>, dt: f64) -> Vec<f64> {
    y.push(0.0);
    y.rotate_right(1);
    let mut acc = 0.0;
    for v in &mut y[1..] {
        acc += *v * dt;
        *v = acc;
    }
    y
}

/// The curve from the integrated angle `theta` (`theta[0] = 0`).
fn adev_of_angle(theta: &[f64], dt: f64) -> Vec<(f64, f64, usize)> {
    let n = theta.len() - 1;
    let mut out = Vec::new();
    let mut m = 1;
    while 4 * m <= n {
        let tau = m as f64 * dt;
        let terms = n + 1 - 2 * m;
        let mut s = 0.0;
        for k in 0..terms {
            let d = theta[k + 2 * m] - 2.0 * theta[k + m] + theta[k];
            s += d * d;
        }
        out.push((tau, (s / (2.0 * tau * tau * terms as f64)).sqrt(), n / m));
        m *= 2;
    }
    out
}

/// The three gyro curves of a block from its kept samples per axis (treated as
/// contiguous), sampled every `dt`: the costly part of the Allan analysis, free of `Out`
/// so that it can run while the fits do. Each series is integrated in place, so a long
/// 1 kHz block holds its three series and nothing more.
pub(crate) type Curves = Vec<Vec<(f64, f64, usize)>>;

pub(crate) fn curves(series: [Vec<f64>; 3], dt: f64) -> Curves {
    series
        .into_iter()
        .map(|y| adev_of_angle(&integrated(y, dt), dt))
        .collect()
}

/// Allan analysis of the block's gyros from its `curves`: angle random walk at tau = 1 s,
/// bias instability.
pub(crate) fn analyse(id: &str, curves: &Curves, out: &mut Out) -> Option<AllanCurve> {
    let mut taus = Vec::new();
    let mut adev: [Vec<f64>; 3] = Default::default();
    for (ax, curve) in curves.iter().enumerate() {
        if curve.len() < 2 {
            return None;
        }
        taus = curve.iter().map(|c| c.0).collect();
        adev[ax] = curve.iter().map(|c| c.1).collect();
        let name = AXES[ax];
        // Relative uncertainty of an Allan deviation with K clusters: about 1/sqrt(2(K-1)).
        let rel = |k: usize| 1.0 / (2.0 * (k.max(2) - 1) as f64).sqrt();
        match curve.windows(2).find(|w| w[0].0 <= 1.0 && w[1].0 >= 1.0) {
            Some(w) => {
                let f = (1.0f64.ln() - w[0].0.ln()) / (w[1].0.ln() - w[0].0.ln());
                let a1 = (w[0].1.ln() + f * (w[1].1.ln() - w[0].1.ln())).exp();
                // deg/s at tau = 1 s is deg/sqrt(s); x 60 gives deg/sqrt(h).
                out.params.insert(
                    format!("gyro.arw.{name}"),
                    Parameter::estimate(a1 * 60.0, a1 * 60.0 * rel(w[0].2), "deg/sqrt(h)"),
                );
            }
            None => out.unobservable(
                &format!("gyro.arw.{name}"),
                "the static block does not span tau = 1 s",
            ),
        }
        let (i, min) = curve
            .iter()
            .enumerate()
            .min_by(|a, b| a.1.1.total_cmp(&b.1.1))
            .map(|(i, c)| (i, c.1))?;
        let bi = min / 0.664 * 3600.0;
        // A curve still falling at its longest tau has not reached its floor: the minimum
        // bounds the bias instability from above and is no estimate of it.
        let falling = i + 1 == curve.len();
        let p = match falling {
            false => Parameter::estimate(bi, bi * rel(curve[i].2), "deg/h"),
            true => Parameter::UpperBound {
                upper_bound: bi,
                unit: "deg/h".into(),
                why: format!(
                    "the Allan deviation of {id} still falls at its longest tau ({:.0} s)",
                    curve[i].0
                ),
            },
        };
        out.params
            .insert(format!("gyro.bias_instability.{name}"), p);
        if falling && ax == 0 {
            out.warnings.push(format!(
                "Allan deviation of {} still falls at its longest tau ({:.0} s): the bias instability is only bounded from above (no value is given)",
                id,
                curve[i].0
            ));
        }
    }
    Some(AllanCurve {
        segment: id.to_string(),
        tau_s: taus,
        adev_dps: adev,
    })
}

#[cfg(test)]
mod tests {
    use super::{Out, Parameter, analyse, overlapping_adev};

    /// A curve with its floor inside gives a value with an uncertainty; one still falling at
    /// its longest tau gives only the bound, no value beside its own bound.
    #[test]
    fn a_curve_still_falling_bounds_the_instability_and_gives_no_value() {
        let curve = |floor: bool| -> Vec<(f64, f64, usize)> {
            let taus = [0.5, 1.0, 2.0, 4.0, 8.0];
            let at = |t: f64| {
                if floor && t > 3.0 {
                    1e-3 * t / 4.0
                } else {
                    1e-3 / t.sqrt()
                }
            };
            taus.iter()
                .map(|&t| (t, at(t), (64.0 / t) as usize))
                .collect()
        };
        for floor in [true, false] {
            let mut out = Out::default();
            analyse("gyro_bias", &vec![curve(floor); 3], &mut out).unwrap();
            let p = &out.params["gyro.bias_instability.x"];
            match (floor, p) {
                (true, Parameter::Estimate { value, .. }) => {
                    assert!(
                        (value - 1e-3 / 2f64.sqrt() / 0.664 * 3600.0).abs() < 1e-9,
                        "{value}"
                    )
                }
                (false, Parameter::UpperBound { upper_bound, .. }) => {
                    let b = 1e-3 / 8f64.sqrt() / 0.664 * 3600.0;
                    assert!((upper_bound - b).abs() < 1e-9, "{upper_bound}");
                    assert!(out.warnings[0].contains("bounded from above"));
                }
                (floor, p) => panic!("floor {floor}: {p:?}"),
            }
            assert_eq!(out.warnings.is_empty(), floor);
        }
    }

    #[test]
    fn white_noise_falls_as_one_over_sqrt_tau() {
        // A deterministic +-1 alternating sequence is "white" enough at m = 1 and averages
        // to zero at every even cluster size: closed forms for both.
        let y: Vec<f64> = (0..4096)
            .map(|i| if i % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        let c = overlapping_adev(&y, 1.0);
        // m = 1: differences of consecutive samples are +-2, adev^2 = 4/2 = 2.
        assert!((c[0].1 - 2f64.sqrt()).abs() < 1e-12);
        assert!(c[1].1 < 1e-12);
    }
}
