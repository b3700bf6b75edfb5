//! With noise off, the simulated station applies the IEEE model-equation terms of the
//! registry (second order, scale asymmetry, scale thermal, clock rate, encoder
//! eccentricity) as their closed forms, written out here independently of the physics
//! crate.

// Channel loops index the truth's arrays and the samples' at once.
#![allow(clippy::needless_range_loop)]

use ratecal_drivers::{ImuSample, Station, TableAxisId, TableCommand, TableSample, build};
use std::time::Duration;

const OMEGA_E: f64 = 7.2921150e-5;
const D: f64 = std::f64::consts::PI / 180.0;
const ARCSEC: f64 = D / 3600.0;

fn station(edit: &[(&str, &str)]) -> Station {
    let mut text = ratecal_drivers::DEFAULT_STATION_YAML.to_string();
    for (from, to) in edit {
        assert!(text.contains(from), "{from}");
        text = text.replacen(from, to, 1);
    }
    Station::from_yaml(&text, "test.yaml").unwrap().noiseless()
}

fn imu_effects(block: &str) -> Station {
    station(&[("effects: {}", &format!("effects: {{ {block} }}"))])
}

async fn run(
    s: &Station,
    cmds: &[(f64, TableCommand)],
    until: f64,
) -> (Vec<ImuSample>, Vec<TableSample>) {
    let (mut table, mut imu) = build(s, 1).unwrap();
    let (mut a, mut b) = (Vec::new(), Vec::new());
    let mut now = 0.0;
    for (at, cmd) in cmds {
        tokio::time::sleep(Duration::from_secs_f64(at - now)).await;
        now = *at;
        table.command(cmd.clone()).await.unwrap();
    }
    tokio::time::sleep(Duration::from_secs_f64(until - now)).await;
    imu.read(&mut a).await.unwrap();
    table.read(&mut b).await.unwrap();
    (a, b)
}

/// Specific force (m/s^2) of the seed geometry at rest at pitch `th`, roll `phi` (rad).
fn gravity_b(g: f64, th: f64, phi: f64) -> [f64; 3] {
    [th.sin(), th.cos() * phi.sin(), th.cos() * phi.cos()].map(|x| x * g)
}

/// Earth rate in body axes (deg/s) at pitch `th`, roll `phi`: `C_LB^T Omega_L` with
/// `C_LB = R_y(-th) R_x(phi)`.
fn earth_b(lat_deg: f64, th: f64, phi: f64) -> [f64; 3] {
    let lat = lat_deg * D;
    let (n, u) = (OMEGA_E * lat.cos(), OMEGA_E * lat.sin());
    // Rows of C_LB^T applied to [0, n, u].
    let (st, ct, sp, cp) = (th.sin(), th.cos(), phi.sin(), phi.cos());
    [u * st, n * cp + u * ct * sp, -n * sp + u * ct * cp].map(|x| x / D)
}

struct Truth {
    g: f64,
    lat: f64,
    ba: [f64; 3],
    sa: [f64; 3],
    bg: [f64; 3],
    sg: [f64; 3],
}

fn truth(s: &Station) -> Truth {
    Truth {
        g: s.site.gravity_mps2,
        lat: s.site.latitude_deg,
        ba: s.imu.accel_bias.map(|q| q.0),
        sa: s.imu.accel_scale.map(|q| q.0),
        bg: s.imu.gyro_bias.map(|q| q.0),
        sg: s.imu.gyro_scale.map(|q| q.0),
    }
}

fn near(got: f64, want: f64, tol: f64, what: &str) {
    assert!((got - want).abs() < tol, "{what}: {got} vs {want}");
}

const ATTITUDES: [(f64, f64); 6] = [
    (0.0, 0.0),
    (0.0, 180.0),
    (90.0, 0.0),
    (-90.0, 0.0),
    (30.0, 45.0),
    (-60.0, 120.0),
];

/// The last 5 s of 20 s at rest at each attitude: `(pitch, roll, samples)`.
async fn at_rest(s: &Station) -> Vec<(f64, f64, Vec<ImuSample>)> {
    let mut out = Vec::new();
    for (pitch, roll) in ATTITUDES {
        let cmd = TableCommand::MoveTo {
            outer_deg: pitch,
            inner_deg: roll,
        };
        let (imu, _) = run(s, &[(1.0, cmd)], 20.0).await;
        let tail = imu.into_iter().filter(|x| x.t >= 15.0).collect();
        out.push((pitch * D, roll * D, tail));
    }
    out
}

#[tokio::test(start_paused = true)]
async fn second_order_adds_k2_f_squared_over_g() {
    let k2 = [150.0, -80.0, 40.0]; // ug/g^2
    let s = imu_effects("accel_second_order: { x: 150, y: -80, z: 40 }");
    let tr = truth(&s);
    for (th, phi, xs) in at_rest(&s).await {
        let f = gravity_b(tr.g, th, phi);
        for x in &xs {
            for i in 0..3 {
                // ug = 1e-6 of the station's g: K2 g (f / g)^2.
                let a = (1.0 + tr.sa[i]) * f[i] + k2[i] * 1e-6 * f[i] * f[i] / tr.g + tr.ba[i];
                near(x.accel[i], a, 1e-9, &format!("a{i} at ({th}, {phi})"));
            }
        }
    }
}

#[tokio::test(start_paused = true)]
async fn accel_asymmetry_changes_the_scale_with_the_sign() {
    let k = [300.0, -200.0, 100.0]; // ppm
    let s = imu_effects("accel_scale_asymmetry: { x: 300, y: -200, z: 100 }");
    let tr = truth(&s);
    for (th, phi, xs) in at_rest(&s).await {
        let f = gravity_b(tr.g, th, phi);
        for x in &xs {
            for i in 0..3 {
                let scale = tr.sa[i] + if f[i] >= 0.0 { k[i] } else { -k[i] } * 1e-6;
                let a = (1.0 + scale) * f[i] + tr.ba[i];
                near(x.accel[i], a, 1e-9, &format!("a{i} at ({th}, {phi})"));
            }
        }
    }
}

/// IMU samples paired with the table sample of the same instant, from `from` s on.
fn paired<'a>(
    imu: &'a [ImuSample],
    table: &'a [TableSample],
    from: f64,
) -> Vec<(&'a ImuSample, &'a TableSample)> {
    let out: Vec<_> = imu
        .iter()
        .filter(|x| x.t >= from)
        .filter_map(|x| {
            table
                .iter()
                .find(|y| (y.t - x.t).abs() < 1e-9)
                .map(|y| (x, y))
        })
        .collect();
    assert!(out.len() > 100);
    out
}

fn spin(axis: TableAxisId, rate_dps: f64) -> [(f64, TableCommand); 1] {
    [(1.0, TableCommand::Rate { axis, rate_dps })]
}

#[tokio::test(start_paused = true)]
async fn gyro_asymmetry_and_thermal_scale_follow_the_rate() {
    // 10 degC below the IMU's ~20 degC: the thermal scale is visible.
    let s = station(&[
        (
            "effects: {}",
            "effects: { gyro_scale_asymmetry: { x: 250, y: -150 }, gyro_scale_thermal: { x: 40, y: -30 } }",
        ),
        ("reference: 20 degC", "reference: 10 degC"),
    ]);
    let tr = truth(&s);
    let (asym, thermal) = ([250.0, -150.0, 0.0], [40.0, -30.0, 0.0]);
    for (axis, rate) in [
        (TableAxisId::Inner, 100.0),
        (TableAxisId::Inner, -100.0),
        (TableAxisId::Outer, 60.0),
        (TableAxisId::Outer, -60.0),
    ] {
        let (imu, table) = run(&s, &spin(axis, rate), 12.0).await;
        for (x, y) in paired(&imu, &table, 5.0) {
            let (th, phi) = (y.outer_deg * D, y.inner_deg * D);
            let e = earth_b(tr.lat, th, phi);
            let w_b = match axis {
                TableAxisId::Outer => [0.0, -rate, 0.0],
                TableAxisId::Inner => [rate, 0.0, 0.0],
            };
            let dt = x.temp_c.unwrap() - 10.0;
            assert!(dt > 9.0);
            for i in 0..3 {
                let w = w_b[i] + e[i];
                let scale = tr.sg[i] + (asym[i] * w.signum() + thermal[i] * dt) * 1e-6;
                let g = (1.0 + scale) * w + tr.bg[i];
                near(
                    x.gyro[i],
                    g,
                    1e-9,
                    &format!("{axis:?} {rate} g{i} at {}", x.t),
                );
            }
        }
    }
}

#[tokio::test(start_paused = true)]
async fn accel_thermal_scale_follows_the_temperature() {
    let s = station(&[
        (
            "effects: {}",
            "effects: { accel_scale_thermal: { x: 50, y: -20, z: 35 } }",
        ),
        ("reference: 20 degC", "reference: 10 degC"),
    ]);
    let tr = truth(&s);
    let c = [50.0, -20.0, 35.0];
    for (th, phi, xs) in at_rest(&s).await {
        let f = gravity_b(tr.g, th, phi);
        for x in &xs {
            let dt = x.temp_c.unwrap() - 10.0;
            for i in 0..3 {
                let a = (1.0 + tr.sa[i] + c[i] * dt * 1e-6) * f[i] + tr.ba[i];
                near(x.accel[i], a, 1e-9, &format!("a{i} at ({th}, {phi})"));
            }
        }
    }
}

#[tokio::test(start_paused = true)]
async fn clock_rate_re_times_the_motion_exactly() {
    // 1000 ppm fast: the sample stamped t saw the table at t / 1.001 (50 ms late at 50 s).
    let eps = 1000e-6;
    let s = imu_effects("clock_rate: { ppm: 1000 }");
    let tr = truth(&s);
    let rate = 100.0;
    let (imu, table) = run(&s, &spin(TableAxisId::Inner, rate), 60.0).await;
    let mut checked = 0;
    for x in imu.iter().filter(|x| x.t >= 20.0) {
        let te = x.t / (1.0 + eps);
        // Turning steadily: the roll at te from the table sample before it.
        let y = table.iter().rev().find(|y| y.t <= te).unwrap();
        assert!((y.inner_rate_dps - rate).abs() < 1e-9);
        let phi = (y.inner_deg + rate * (te - y.t)) * D;
        let f = gravity_b(tr.g, 0.0, phi);
        for i in 1..3 {
            let a = (1.0 + tr.sa[i]) * f[i] + tr.ba[i];
            near(x.accel[i], a, 1e-9, &format!("a{i} at {}", x.t));
        }
        // The first-order lag t eps is off by t eps^2 (2.5 mdeg of roll at 50 s): the
        // outputs tell the exact re-timing from it.
        let phi1 = (y.inner_deg + rate * (x.t * (1.0 - eps) - y.t)) * D;
        if x.t > 40.0 {
            let a1 = (1.0 + tr.sa[1]) * gravity_b(tr.g, 0.0, phi1)[1] + tr.ba[1];
            assert!((x.accel[1] - a1).abs() > 1e-6 || phi.cos().abs() < 0.1);
        }
        checked += 1;
    }
    assert!(checked > 3000);
}

/// The true angle `th` with `th + s sin th + c cos th = enc` (rad), by Newton's method.
fn true_angle(enc: f64, s: f64, c: f64) -> f64 {
    let mut th = enc;
    for _ in 0..8 {
        let f = th + s * th.sin() + c * th.cos() - enc;
        th -= f / (1.0 + s * th.cos() - c * th.sin());
    }
    th
}

#[tokio::test(start_paused = true)]
async fn encoder_eccentricity_turns_the_imu_by_the_true_angle() {
    // e sin(theta + phi) = s sin(theta) + c cos(theta), arcsec.
    let (os, oc, is, ic) = (40.0, -25.0, 30.0, 50.0);
    let block = format!(
        "feedback_rate: 50 Hz\n  effects: {{ table_encoder_eccentricity: {{ outer_sin_arcsec: {os}, outer_cos_arcsec: {oc}, inner_sin_arcsec: {is}, inner_cos_arcsec: {ic} }} }}"
    );
    let s = station(&[("feedback_rate: 50 Hz", &block)]);
    let tr = truth(&s);
    let (os, oc, is, ic) = (os * ARCSEC, oc * ARCSEC, is * ARCSEC, ic * ARCSEC);
    // At rest: the table reports the commanded (encoder) angles; the IMU reads gravity at
    // the true ones.
    for (pitch, roll) in ATTITUDES {
        let cmd = TableCommand::MoveTo {
            outer_deg: pitch,
            inner_deg: roll,
        };
        let (imu, table) = run(&s, &[(1.0, cmd)], 20.0).await;
        let y = table.last().unwrap();
        near(y.outer_deg, pitch, 1e-9, "reported pitch");
        near(y.inner_deg, roll, 1e-9, "reported roll");
        let th = true_angle(pitch * D, os, oc);
        let phi = true_angle(roll * D, is, ic);
        let f = gravity_b(tr.g, th, phi);
        let w = earth_b(tr.lat, th, phi);
        let mut apart = 0.0_f64;
        for x in imu.iter().filter(|x| x.t >= 15.0) {
            for i in 0..3 {
                let a = (1.0 + tr.sa[i]) * f[i] + tr.ba[i];
                near(x.accel[i], a, 1e-9, &format!("a{i} at ({pitch}, {roll})"));
                let g = (1.0 + tr.sg[i]) * w[i] + tr.bg[i];
                near(x.gyro[i], g, 1e-11, &format!("g{i} at ({pitch}, {roll})"));
                let at_enc = gravity_b(tr.g, pitch * D, roll * D)[i];
                apart = apart.max(((1.0 + tr.sa[i]) * at_enc + tr.ba[i] - x.accel[i]).abs());
            }
        }
        assert!(
            apart > 1e-4,
            "the error shows at ({pitch}, {roll}): {apart}"
        );
    }
    // Turning about the inner axis: the encoder's rate is steady, the true one is not.
    let rate = 100.0;
    let (imu, table) = run(&s, &spin(TableAxisId::Inner, rate), 12.0).await;
    let mut spread = (f64::MAX, f64::MIN);
    for (x, y) in paired(&imu, &table, 5.0) {
        near(y.inner_rate_dps, rate, 1e-9, "reported rate");
        let phi = true_angle(y.inner_deg * D, is, ic);
        // d(phi + eps(phi))/dt = rate_enc: the true rate divides by 1 + eps'(phi).
        let w_true = rate / (1.0 + is * phi.cos() - ic * phi.sin());
        let th = true_angle(y.outer_deg * D, os, oc);
        let f = gravity_b(tr.g, th, phi);
        let e = earth_b(tr.lat, th, phi);
        let w = [w_true + e[0], e[1], e[2]];
        for i in 0..3 {
            let g = (1.0 + tr.sg[i]) * w[i] + tr.bg[i];
            near(x.gyro[i], g, 1e-9, &format!("g{i} at {}", x.t));
        }
        for i in 1..3 {
            let a = (1.0 + tr.sa[i]) * f[i] + tr.ba[i];
            near(x.accel[i], a, 1e-9, &format!("a{i} at {}", x.t));
        }
        spread = (spread.0.min(w_true), spread.1.max(w_true));
    }
    // 58 arcsec of eccentricity: the true rate swings by +-2.8e-4 of 100 deg/s.
    assert!(spread.1 - spread.0 > 0.05, "{spread:?}");
}
