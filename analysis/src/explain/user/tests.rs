use super::*;
use ratecal_physics::effects::{Effect, Partials, Signals};
use ratecal_physics::{Mat3, Vec3};

fn sig(k: f64) -> Signals {
    let c = nalgebra::Rotation3::from_euler_angles(0.3 * k, -0.2, 0.7 + k).into_inner();
    let s = Signals {
        f_b: Vec3::new(1.0 + k, -2.0, 9.0),
        w_b: Vec3::new(0.3, -0.7 * k, 1.1),
        dw_b: Vec3::new(-0.5, 0.2, 0.9 * k),
        c_bl: Mat3::from(c),
        earth_b: Vec3::new(1e-5, 2e-5, -3e-5),
        df_b: Vec3::new(0.1, 0.2, 0.3),
        dw_ib: Vec3::new(-0.1, 0.4, 0.2),
        dtemp_c: 2.5 * k,
        g: 9.81,
        t_s: 0.0,
        table: Default::default(),
        outer_b: Vec3::new(0.0, -1.0, 0.0),
        inner_b: Vec3::new(1.0, 0.0, 0.0),
    };
    s.at(100.0 * k)
}

fn one(text: &str) -> &'static UserEffect {
    let v = load(&[("t.effect".into(), text.into())]).unwrap_or_else(|d| panic!("{d:?}"));
    assert_eq!(v.len(), 1);
    v[0]
}

fn codes(text: &str) -> Vec<&'static str> {
    let d = load(&[("t.effect".into(), text.into())]).err().unwrap();
    d.iter().map(|d| d.code).collect()
}

#[test]
fn restated_centripetal_terms_match_the_lever_arm() {
    let fx = one("effect centripetal {
           explanation \"centripetal acceleration at the sensing points\"
           param rxx_mm unit \"mm\" needs \"rotate about Y or Z\"
           param ryy_mm unit \"mm\" needs \"rotate about X or Z\"
           param rzz_mm unit \"mm\" needs \"rotate about X or Y\"
           ax += rxx_mm * 1e-3 * -(w_b.y^2 + w_b.z^2)
           ay += ryy_mm * 1e-3 * -(w_b.x^2 + w_b.z^2)
           az += -rzz_mm / 1000 * (w_b.x^2 + w_b.y^2)
         }");
    let lever = ratecal_physics::effect("lever_arm").unwrap();
    for k in [0.0, 0.4, -1.3] {
        let s = sig(k);
        let mut mine = [Partials::default(); 3];
        fx.regressors(&s, &mut mine);
        let mut theirs = [Partials::default(); 9];
        lever.regressors(&s, &mut theirs);
        // The built-in's dw terms sit off the diagonal: the diagonal is centripetal only.
        for (a, b) in mine.iter().zip([theirs[0], theirs[4], theirs[8]]) {
            assert!((a.accel - b.accel).norm() < 1e-15, "{a:?} {b:?}");
            assert_eq!(a.gyro, Vec3::zeros());
        }
    }
    assert_eq!(fx.sensors(), [ratecal_physics::Sensor::Accel]);
    assert_eq!(
        fx.params()[1].channel,
        Some((ratecal_physics::Sensor::Accel, 1))
    );
    assert_eq!(fx.follows(), "w_b.x, w_b.y, w_b.z");
}

#[test]
fn regressors_are_the_derivatives_of_a_sum_of_terms() {
    let fx = one("effect mix {
           explanation \"x\" follows \"attitude and temperature\"
           param a unit \"1\" needs \"m\"
           param b unit \"1\" needs \"m\"
           gx += (a + 2 * b) * w_b.x / deg - b * f_b.y / g
           gz += a * up_b.z * sin(pi / 6) + b * dtemp_c * t_s
           ax += a * sqrt(abs(north_b.x)) - (-b) * earth_b.z
         }");
    let s = sig(0.8);
    let mut p = [Partials::default(); 2];
    fx.regressors(&s, &mut p);
    let d = ratecal_physics::DEG;
    let (n, u) = (s.c_bl.column(1), s.c_bl.column(2));
    assert!((p[0].gyro.x - s.w_b.x / d).abs() < 1e-12);
    assert!((p[1].gyro.x - (2.0 * s.w_b.x / d - s.f_b.y / s.g)).abs() < 1e-12);
    assert!((p[0].gyro.z - 0.5 * u.z).abs() < 1e-12);
    assert!((p[1].gyro.z - s.dtemp_c * 80.0).abs() < 1e-12);
    assert!((p[0].accel.x - n.x.abs().sqrt()).abs() < 1e-12);
    assert!((p[1].accel.x - s.earth_b.z).abs() < 1e-18);
    // Several channels: the parameter acts on every axis of both sensors.
    assert_eq!(fx.params()[0].channel, None);
    // Forward is the regressors times the values.
    let f = fx.forward(&[2.0, -1.0], &s);
    assert!((f.gyro.x - (2.0 * p[0].gyro.x - p[1].gyro.x)).abs() < 1e-12);
}

#[test]
fn non_finite_regressors_are_zero_and_counted() {
    let fx = one(
        "effect root { explanation \"x\" param a unit \"1\" needs \"m\" gy += a * sqrt(f_b.y) }",
    );
    let mut p = [Partials::default()];
    fx.regressors(&sig(0.0), &mut p);
    assert_eq!(p[0].gyro.y, 0.0);
    assert_eq!(fx.nonfinite(), 1);
}

#[test]
fn contributions_that_are_not_linear_are_refused() {
    let wrap = |c: &str| {
        format!(
            "effect e {{ explanation \"x\" param a unit \"1\" needs \"m\" param b unit \"1\" needs \"m\" {c} }}"
        )
    };
    let cases = [
        ("ax += a * b * f_b.x", "effect::not_linear"),
        ("ax += a^2 + b", "effect::not_linear"),
        ("ax += sin(a) + b", "effect::not_linear"),
        ("ax += f_b.x / a + b", "effect::not_linear"),
        ("ax += 2^a + b", "effect::not_linear"),
        ("ax += a * f_b.x + 0.1 + b", "effect::no_parameter"),
        ("ax += (a + 1) * f_b.x + b", "effect::no_parameter"),
        ("ax += f_b.x ay += a + b", "effect::no_parameter"),
        ("ax += a * f_b.w + b", "effect::unknown_name"),
        ("ax += a * cosh(f_b.x) + b", "effect::unknown_function"),
        ("ax += a * sin(f_b.x, 2) + b", "effect::arity"),
        ("qx += a + b", "effect::unknown_channel"),
        ("ax += a * 1e999 + b", "effect::bad_number"),
        ("ax += a", "effect::unused_parameter"),
    ];
    for (c, code) in cases {
        assert_eq!(codes(&wrap(c)), [code], "{c}");
    }
}

#[test]
fn every_error_of_every_file_is_reported_with_its_file() {
    let d = load(&[
        (
            "a.effect".into(),
            "effect lever_arm { explanation \"x\" param p unit \"1\" ax += p }\neffect e { param g unit \"1\" needs \"m\" gx += g }".into(),
        ),
        ("b.effect".into(), "effect e2 { ax += ".into()),
        (
            "c.effect".into(),
            "effect e3 { explanation \"x\" param q unit \"1\" needs \"m\" az += q }".into(),
        ),
        (
            "d.effect".into(),
            "effect e3 { explanation \"x\" param q unit \"1\" needs \"m\" az += q }".into(),
        ),
    ])
    .err()
    .unwrap();
    let got: Vec<(&str, String)> = d
        .iter()
        .map(|d| (d.code, d.source.as_ref().unwrap().name().to_string()))
        .collect();
    let want = [
        ("effect::duplicate", "a.effect"),
        ("effect::missing", "a.effect"),
        ("effect::name_taken", "a.effect"),
        ("effect::missing", "a.effect"),
        ("effect::syntax", "b.effect"),
        ("effect::duplicate", "d.effect"),
    ];
    let want: Vec<(&str, String)> = want.iter().map(|(c, f)| (*c, f.to_string())).collect();
    assert_eq!(got, want);
    assert!(d.iter().all(|d| d.line_col().is_some() && d.help.is_some()));
}
