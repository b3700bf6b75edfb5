//! The real consumer IMU's six-position session (`../shared/examples/real-ferraris-session`,
//! no truth): explain names the accelerometer misalignment the seed model leaves out, and
//! its values agree with an independent full 3x3 fit of the same data (segment means
//! against the closed-form gravity references, solved here by SVD).

use crate::shared;
use nalgebra::{DMatrix, DVector};
use ratecal_analysis::explain::{self, NominalModel, Options, Parameter};
use ratecal_recording as recording;

/// `K` (3x3) of `a = K f + b` from the six segments' mean outputs and references
/// `f = g [sin th, cos th sin ph, cos th cos ph]` (th, ph: mean outer and inner feedback),
/// each row with its standard uncertainties from the scatter about the fit (six equations,
/// four unknowns: two degrees of freedom).
fn full_fit(rec: &recording::Recording) -> [[(f64, f64); 3]; 3] {
    let g = rec.manifest.station.site.gravity_mps2;
    let mean = |x: &[f64], t: &[f64], t0: f64, t1: f64| {
        let v: Vec<f64> = t
            .iter()
            .zip(x)
            .filter(|(t, _)| **t >= t0 && **t <= t1)
            .map(|p| *p.1)
            .collect();
        v.iter().sum::<f64>() / v.len() as f64
    };
    let segs = &rec.manifest.segments;
    let mut a = DMatrix::zeros(segs.len(), 4);
    let mut y: Vec<DVector<f64>> = vec![DVector::zeros(segs.len()); 3];
    for (k, s) in segs.iter().enumerate() {
        let th = mean(&rec.table.outer, &rec.table.t, s.t_start, s.t_end).to_radians();
        let ph = mean(&rec.table.inner, &rec.table.t, s.t_start, s.t_end).to_radians();
        let f = [th.sin(), th.cos() * ph.sin(), th.cos() * ph.cos()].map(|v| g * v);
        for j in 0..3 {
            a[(k, j)] = f[j];
            y[j][k] = mean(&rec.imu.accel[j], &rec.imu.t, s.t_start, s.t_end);
        }
        a[(k, 3)] = 1.0;
    }
    let svd = a.clone().svd(true, true);
    let cov = (a.transpose() * &a)
        .try_inverse()
        .expect("six attitudes determine K");
    let dof = (segs.len() - 4) as f64;
    let mut kmat = [[(0.0, 0.0); 3]; 3];
    for i in 0..3 {
        let x = svd.solve(&y[i], 1e-12).unwrap();
        let s2 = (&a * &x - &y[i]).norm_squared() / dof;
        for j in 0..3 {
            kmat[i][j] = (x[j], (s2 * cov[(j, j)]).sqrt());
        }
    }
    kmat
}

#[test]
fn explain_names_the_misalignment_a_full_fit_agrees_with() {
    let Some(dir) = shared::shared_example("real-ferraris-session") else {
        return;
    };
    let rec = recording::read(&dir).unwrap();
    let x = explain::explain(&rec, &NominalModel::seed(), &Options::default());
    let found: Vec<&str> = x.findings.iter().map(|f| f.effect.as_str()).collect();
    assert_eq!(found, ["accel_misalignment"], "rejected {:?}", x.rejected);
    let k = full_fit(&rec);
    let names = ["x", "y", "z"];
    let f = &x.findings[0];
    for i in 0..3 {
        for j in (0..3).filter(|&j| j != i) {
            let name = format!("{}{}_mrad", names[i], names[j]);
            let Parameter::Estimate { value, u, .. } = &f.parameters[&name] else {
                panic!("{name} not determined");
            };
            let (full, uf) = (k[i][j].0 * 1e3, k[i][j].1 * 1e3);
            eprintln!("{name}: explain {value:.3} ± {u:.3}, full 3x3 fit {full:.3} ± {uf:.3}");
            // Within their joint uncertainty, and (the six means' scatter being large) within
            // half a milliradian: a twentieth of the misalignments found.
            let both = (u * u + uf * uf).sqrt();
            assert!(
                (value - full).abs() < (3.0 * both).min(0.5),
                "{name}: {value} ± {u} vs {full} ± {uf}"
            );
        }
    }
}
