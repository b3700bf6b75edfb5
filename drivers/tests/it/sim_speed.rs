//! Throughput of the simulated station: the standard procedure's motion (~80 min) with the
//! IMU at 1 kHz. Run with `cargo test --release -p ratecal-drivers --test it sim_speed:: -- --ignored --nocapture`.

use ratecal_drivers::{Station, TableAxisId, TableCommand, build};
use std::time::{Duration, Instant};

#[tokio::test(start_paused = true)]
#[ignore = "timing; run in release"]
async fn standard_procedure_motion_at_1khz() {
    let text =
        ratecal_drivers::DEFAULT_STATION_YAML.replace("sample_rate: 100 Hz", "sample_rate: 1 kHz");
    let mut s = Station::from_yaml(&text, "fast.yaml").unwrap();
    if std::env::var_os("RATECAL_NOISELESS").is_some() {
        s = s.noiseless();
    }
    let (mut table, mut imu) = build(&s, 1).unwrap();
    let wall = Instant::now();
    let (mut a, mut b) = (Vec::with_capacity(20_000), Vec::new());
    let mut n = 0usize;
    let mut steps: Vec<(TableCommand, f64)> = Vec::new();
    for (p, r) in [
        (0.0, 0.0),
        (0.0, 180.0),
        (90.0, 0.0),
        (-90.0, 0.0),
        (0.0, 90.0),
        (0.0, -90.0),
    ] {
        steps.push((
            TableCommand::MoveTo {
                outer_deg: p,
                inner_deg: r,
            },
            45.0,
        ));
    }
    steps.push((
        TableCommand::MoveTo {
            outer_deg: 0.0,
            inner_deg: 0.0,
        },
        3700.0,
    ));
    for axis in [TableAxisId::Outer, TableAxisId::Inner] {
        for r in [-100.0, -50.0, 0.0, 50.0, 100.0] {
            steps.push((TableCommand::Rate { axis, rate_dps: r }, 40.0));
        }
        steps.push((TableCommand::Stop { axis }, 10.0));
    }
    let mut virt = 0.0;
    for (cmd, dur) in steps {
        table.command(cmd).await.unwrap();
        let mut t = 0.0;
        while t < dur {
            tokio::time::sleep(Duration::from_millis(100)).await;
            t += 0.1;
            imu.read(&mut a).await.unwrap();
            table.read(&mut b).await.unwrap();
            n += a.len();
            a.clear();
            b.clear();
        }
        virt += dur;
    }
    let el = wall.elapsed().as_secs_f64();
    println!(
        "{n} IMU samples, {virt} s simulated in {el:.3} s: {:.0}x real time, {:.0} ns/sample",
        virt / el,
        el / n as f64 * 1e9
    );
}

#[test]
#[ignore = "timing; run in release"]
fn physics_cost_per_call() {
    use ratecal_physics::{AxisMotion, ImuErrors, Signals, TableState};
    let s = Station::default_sim();
    let (geo, site) = (s.geometry(), s.site());
    let model = ImuErrors::default().model(&site);
    let wall = Instant::now();
    let mut acc = 0.0;
    let n = 1_000_000;
    for k in 0..n {
        let st = TableState {
            outer: AxisMotion {
                angle: k as f64 * 1e-4,
                rate: 1.0,
                accel: 0.0,
            },
            inner: AxisMotion::default(),
        };
        let sig = Signals::new(&st.snapshot(&geo, &site), &site, 0.0);
        acc += model.outputs(&sig).0.x;
    }
    println!(
        "{:.0} ns per snapshot + model outputs ({acc})",
        wall.elapsed().as_secs_f64() / n as f64 * 1e9
    );
}
