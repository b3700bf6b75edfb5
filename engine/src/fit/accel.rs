//! Accelerometer models from the static attitudes: the seed's per-axis `a = K (a_ref + b)`
//! and the full 3x3 sensitivity matrix with biases.

use super::lsq::Normal;
use super::prep::SegData;
use super::stats::Inflation;
use super::{AXES, Out, residual_stats};
use crate::results::Parameter;
use ratecal_physics::{Mat3, Vec3};

/// Fits the seed model per axis over every retained static sample (each sample weighs the same).
pub(crate) fn fit_seed(segs: &[&SegData], out: &mut Out) {
    let mut k = Mat3::identity();
    let mut b = Vec3::zeros();
    for ax in 0..3 {
        let mut ne = Normal::new(2);
        for s in segs {
            for i in 0..s.t.len() {
                if s.keep_a[i] {
                    ne.add(&[s.f_ref[ax][i], 1.0], s.accel[ax][i]);
                }
            }
        }
        let name = AXES[ax];
        let sol = if ne.weak_columns(1e-3).contains(&0) {
            None
        } else {
            ne.solve(&[0, 1])
        };
        let Some(sol) = sol else {
            out.unobservable(
                &format!("accel.scale.{name}"),
                "no static attitude put gravity along this axis",
            );
            out.unobservable(
                &format!("accel.bias.{name}"),
                "no static attitude put gravity along this axis",
            );
            continue;
        };
        let mut infl = Inflation::default();
        for s in segs {
            let r: Vec<f64> = (0..s.t.len())
                .map(|i| s.accel[ax][i] - sol.x[0] * s.f_ref[ax][i] - sol.x[1])
                .collect();
            infl.add(&r, &s.keep_a);
        }
        let f = infl.factor();
        k[(ax, ax)] = sol.x[0];
        b[ax] = sol.x[1];
        out.params.insert(
            format!("accel.scale.{name}"),
            Parameter::estimate((sol.x[0] - 1.0) * 1e6, sol.u(0, f) * 1e6, "ppm"),
        );
        out.params.insert(
            format!("accel.bias.{name}"),
            Parameter::estimate(sol.x[1], sol.u(1, f), "m/s^2"),
        );
    }
    finish(segs, k, b, out);
}

/// Fits the full model: per output axis, a row of `K_a` and a bias.
pub(crate) fn fit_full(segs: &[&SegData], out: &mut Out) {
    let mut k = Mat3::identity();
    let mut b = Vec3::zeros();
    for ax in 0..3 {
        let mut ne = Normal::new(4);
        for s in segs {
            for i in 0..s.t.len() {
                if s.keep_a[i] {
                    ne.add(
                        &[s.f_ref[0][i], s.f_ref[1][i], s.f_ref[2][i], 1.0],
                        s.accel[ax][i],
                    );
                }
            }
        }
        let weak = ne.weak_columns(1e-3);
        let cols: Vec<usize> = (0..4).filter(|c| !weak.contains(c)).collect();
        let name = AXES[ax];
        let Some(sol) = ne.solve(&cols) else {
            for j in 0..3 {
                out.unobservable(
                    &k_name("accel", ax, j),
                    "the static attitudes do not separate this term",
                );
            }
            out.unobservable(
                &format!("accel.bias.{name}"),
                "the static attitudes do not separate this term",
            );
            continue;
        };
        let mut infl = Inflation::default();
        for s in segs {
            let r: Vec<f64> = (0..s.t.len())
                .map(|i| {
                    let mut p = 0.0;
                    for (c, &col) in cols.iter().enumerate() {
                        p += sol.x[c] * if col == 3 { 1.0 } else { s.f_ref[col][i] };
                    }
                    s.accel[ax][i] - p
                })
                .collect();
            infl.add(&r, &s.keep_a);
        }
        let f = infl.factor();
        for j in 0..4 {
            let Some(c) = cols.iter().position(|&x| x == j) else {
                if j < 3 {
                    out.unobservable(
                        &k_name("accel", ax, j),
                        "no static attitude put gravity along this input axis",
                    );
                } else {
                    out.unobservable(
                        &format!("accel.bias.{name}"),
                        "not separable from the sensitivity terms",
                    );
                }
                continue;
            };
            let (v, u) = (sol.x[c], sol.u(c, f));
            if j == 3 {
                b[ax] = v;
                out.params.insert(
                    format!("accel.bias.{name}"),
                    Parameter::estimate(v, u, "m/s^2"),
                );
            } else {
                k[(ax, j)] = v;
                out.params
                    .insert(k_name("accel", ax, j), k_param(ax, j, v, u));
            }
        }
    }
    finish(segs, k, b, out);
}

/// Parameter name of `K[i][j]`: the scale on the diagonal, misalignment off it.
pub(crate) fn k_name(sensor: &str, i: usize, j: usize) -> String {
    if i == j {
        format!("{sensor}.scale.{}", AXES[i])
    } else {
        format!("{sensor}.misalignment.{}{}", AXES[i], AXES[j])
    }
}

/// `K[i][j]` as reported: `(K - 1)` ppm on the diagonal, `K * 1000` mrad off it.
pub(crate) fn k_param(i: usize, j: usize, v: f64, u: f64) -> Parameter {
    if i == j {
        Parameter::estimate((v - 1.0) * 1e6, u * 1e6, "ppm")
    } else {
        Parameter::estimate(v * 1e3, u * 1e3, "mrad")
    }
}

/// Residuals per segment and the pooled residual standard deviation.
fn finish(segs: &[&SegData], k: Mat3, b: Vec3, out: &mut Out) {
    let worst = model_residuals(segs, Sensor::Accel, &k, &b, out);
    out.quantities.insert("accel.residual.std".into(), worst);
    out.accel_model = Some((k, b));
}

/// Which sensor a fitted model describes.
#[derive(Clone, Copy)]
pub(super) enum Sensor {
    /// Accelerometers: outputs `accel`, references `f_ref`, mask `keep_a`.
    Accel,
    /// Gyros: outputs `gyro`, references `w_ref`, mask `keep_g`.
    Gyro,
}

/// Pushes the residuals of `out = K ref + b` per segment and axis, and returns the worst
/// axis's pooled residual standard deviation with its standard uncertainty.
pub(super) fn model_residuals(
    segs: &[&SegData],
    sensor: Sensor,
    k: &Mat3,
    b: &Vec3,
    out: &mut Out,
) -> (f64, f64) {
    let mut worst = (0.0f64, 0.0f64);
    for ax in 0..3 {
        let (mut ss, mut n) = (0.0, 0usize);
        for s in segs {
            let (y, rf, keep, name, unit) = match sensor {
                Sensor::Accel => (&s.accel, &s.f_ref, &s.keep_a, "accel", "m/s^2"),
                Sensor::Gyro => (&s.gyro, &s.w_ref, &s.keep_g, "gyro", "deg/s"),
            };
            let r: Vec<f64> = (0..s.t.len())
                .map(|i| y[ax][i] - b[ax] - (0..3).map(|j| k[(ax, j)] * rf[j][i]).sum::<f64>())
                .collect();
            out.residuals
                .push(residual_stats(s, name, ax, &r, keep, unit));
            for i in 0..r.len() {
                if keep[i] {
                    ss += r[i] * r[i];
                    n += 1;
                }
            }
        }
        if n > 1 {
            let sd = (ss / (n - 1) as f64).sqrt();
            if sd > worst.0 {
                worst = (sd, sd / (2.0 * (n - 1) as f64).sqrt());
            }
        }
    }
    worst
}
