//! With noise off, the simulated station's outputs equal the closed forms of
//! spec/physics.md, written out here independently of the physics crate.

use ratecal_drivers::{ImuSample, Station, TableAxisId, TableCommand, TableSample, build};
use std::time::Duration;

const OMEGA_E: f64 = 7.2921150e-5;
const D: f64 = std::f64::consts::PI / 180.0;

fn station(edit: &[(&str, &str)]) -> Station {
    let mut text = ratecal_drivers::DEFAULT_STATION_YAML.to_string();
    for (from, to) in edit {
        assert!(text.contains(from), "{from}");
        text = text.replacen(from, to, 1);
    }
    Station::from_yaml(&text, "test.yaml").unwrap().noiseless()
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

/// `C_LB` of the seed geometry at pitch `th`, roll `phi` (rad): `R_y(-th) R_x(phi)`.
fn c_lb(th: f64, phi: f64) -> [[f64; 3]; 3] {
    let ry = [
        [th.cos(), 0.0, -th.sin()],
        [0.0, 1.0, 0.0],
        [th.sin(), 0.0, th.cos()],
    ];
    let rx = [
        [1.0, 0.0, 0.0],
        [0.0, phi.cos(), -phi.sin()],
        [0.0, phi.sin(), phi.cos()],
    ];
    let mut m = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            m[i][j] = (0..3).map(|k| ry[i][k] * rx[k][j]).sum();
        }
    }
    m
}

/// Earth rate in body axes, deg/s.
fn earth_b(lat_deg: f64, th: f64, phi: f64) -> [f64; 3] {
    let lat = lat_deg * D;
    let w_l = [0.0, OMEGA_E * lat.cos(), OMEGA_E * lat.sin()];
    let c = c_lb(th, phi);
    [0, 1, 2].map(|j| (0..3).map(|i| c[i][j] * w_l[i]).sum::<f64>() / D)
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

#[tokio::test(start_paused = true)]
async fn six_static_attitudes_match_gravity_and_earth_rate() {
    for lat in ["55.70", "-33.9"] {
        let s = station(&[("latitude_deg: 55.70", &format!("latitude_deg: {lat}"))]);
        let tr = truth(&s);
        for (pitch, roll) in [
            (0.0, 0.0),
            (0.0, 180.0),
            (90.0, 0.0),
            (90.0, 180.0),
            (0.0, 90.0),
            (0.0, 270.0),
        ] {
            let cmd = TableCommand::MoveTo {
                outer_deg: pitch,
                inner_deg: roll,
            };
            let (imu, _) = run(&s, &[(1.0, cmd)], 20.0).await;
            let (th, phi) = (pitch * D, roll * D);
            let f = [th.sin(), th.cos() * phi.sin(), th.cos() * phi.cos()].map(|x| x * tr.g);
            let w = earth_b(tr.lat, th, phi);
            let tail: Vec<_> = imu.iter().filter(|x| x.t >= 15.0).collect();
            assert_eq!(tail.len(), 501);
            for x in tail {
                for i in 0..3 {
                    let a = (1.0 + tr.sa[i]) * f[i] + tr.ba[i];
                    let g = (1.0 + tr.sg[i]) * w[i] + tr.bg[i];
                    assert!(
                        (x.accel[i] - a).abs() < 1e-9,
                        "lat {lat} ({pitch}, {roll}) a{i}: {} vs {a}",
                        x.accel[i]
                    );
                    assert!(
                        (x.gyro[i] - g).abs() < 1e-11,
                        "lat {lat} ({pitch}, {roll}) g{i}: {} vs {g}",
                        x.gyro[i]
                    );
                }
            }
        }
    }
}

/// IMU samples paired with the table sample of the same instant (50 Hz of the 100 Hz).
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

#[tokio::test(start_paused = true)]
async fn constant_rates_give_k_times_w_ib_plus_bias() {
    let s = station(&[]);
    let tr = truth(&s);
    for (axis, rate) in [
        (TableAxisId::Outer, 100.0),
        (TableAxisId::Outer, -50.0),
        (TableAxisId::Inner, 100.0),
    ] {
        let (imu, table) = run(
            &s,
            &[(
                1.0,
                TableCommand::Rate {
                    axis,
                    rate_dps: rate,
                },
            )],
            12.0,
        )
        .await;
        for (x, y) in paired(&imu, &table, 5.0) {
            assert!((y.outer_rate_dps + y.inner_rate_dps - rate).abs() < 1e-9);
            let (th, phi) = (y.outer_deg * D, y.inner_deg * D);
            let e = earth_b(tr.lat, th, phi);
            // Outer axis = -Y at roll 0; inner axis = X.
            let w_b = match axis {
                TableAxisId::Outer => [0.0, -rate, 0.0],
                TableAxisId::Inner => [rate, 0.0, 0.0],
            };
            for i in 0..3 {
                let g = (1.0 + tr.sg[i]) * (w_b[i] + e[i]) + tr.bg[i];
                assert!(
                    (x.gyro[i] - g).abs() < 1e-9,
                    "{axis:?} {rate} g{i} at {}: {} vs {g}",
                    x.t,
                    x.gyro[i]
                );
            }
        }
    }
}

#[tokio::test(start_paused = true)]
async fn lever_arm_adds_centripetal_terms() {
    let s = station(&[(
        "effects: {}",
        "effects: { lever_arm: { ryy_mm: 40, rzz_mm: 50 } }",
    )]);
    let tr = truth(&s);
    let rate = 200.0;
    let cmd = TableCommand::Rate {
        axis: TableAxisId::Inner,
        rate_dps: rate,
    };
    let (imu, table) = run(&s, &[(1.0, cmd)], 10.0).await;
    let w2 = (rate * D) * (rate * D);
    for (x, y) in paired(&imu, &table, 5.0) {
        let phi = y.inner_deg * D;
        // Spinning about X at level: a point at r along Y or Z feels -w^2 r towards the axis.
        let sy = tr.g * phi.sin() - w2 * 0.040;
        let sz = tr.g * phi.cos() - w2 * 0.050;
        let ay = (1.0 + tr.sa[1]) * sy + tr.ba[1];
        let az = (1.0 + tr.sa[2]) * sz + tr.ba[2];
        assert!((x.accel[1] - ay).abs() < 1e-9, "ay {} vs {ay}", x.accel[1]);
        assert!((x.accel[2] - az).abs() < 1e-9, "az {} vs {az}", x.accel[2]);
    }
}

#[tokio::test(start_paused = true)]
async fn time_offset_delays_the_outputs_by_tau() {
    let plain = station(&[]);
    let late = station(&[("effects: {}", "effects: { time_offset: { tau_ms: 30 } }")]);
    let cmd = TableCommand::Oscillate {
        axis: TableAxisId::Inner,
        center_deg: 0.0,
        amplitude_deg: 30.0,
        period_s: 4.0,
    };
    let (a, _) = run(&plain, &[(1.0, cmd.clone())], 20.0).await;
    let (b, _) = run(&late, &[(1.0, cmd)], 20.0).await;
    let mut moving = 0;
    for k in 300..a.len() {
        // 30 ms = 3 samples at 100 Hz.
        for i in 0..3 {
            assert!((b[k].gyro[i] - a[k - 3].gyro[i]).abs() < 1e-9);
            assert!((b[k].accel[i] - a[k - 3].accel[i]).abs() < 1e-9);
        }
        moving += usize::from((a[k].gyro[0] - a[k - 3].gyro[0]).abs() > 1.0);
    }
    assert!(moving > 1000, "the oscillation makes the offset visible");
}

#[tokio::test(start_paused = true)]
async fn remount_changes_the_mount_from_then_on() {
    let s = station(&[]);
    let tr = truth(&s);
    let (mut table, mut imu) = build(&s, 1).unwrap();
    table
        .command(TableCommand::MoveTo {
            outer_deg: 90.0,
            inner_deg: 0.0,
        })
        .await
        .unwrap();
    tokio::time::sleep(Duration::from_secs(10)).await;
    // Body X along platform Y: C_PB columns are the body axes in P.
    imu.remount([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
        .await
        .unwrap();
    tokio::time::sleep(Duration::from_secs(10)).await;
    let mut xs = Vec::new();
    imu.read(&mut xs).await.unwrap();
    assert_eq!(xs.len(), 2001);
    let before = xs.iter().find(|x| x.t == 9.0).unwrap();
    let after = xs.iter().find(|x| x.t >= 15.0).unwrap();
    // Pitch 90: platform X is up, so the old body X reads +g and the new body Y reads -g.
    assert!((before.accel[0] - ((1.0 + tr.sa[0]) * tr.g + tr.ba[0])).abs() < 1e-9);
    assert!((after.accel[1] - ((1.0 + tr.sa[1]) * -tr.g + tr.ba[1])).abs() < 1e-9);
    assert!((after.accel[0] - tr.ba[0]).abs() < 1e-9);
}
