//! The simulated station behaves like a real one: limited moves, determinism, faults.

use ratecal_drivers::{
    ImuDriver, ImuSample, Station, TableAxisId, TableCommand, TableDriver, TableSample, build,
};
use std::time::Duration;

fn station(edit: &[(&str, &str)]) -> Station {
    let mut text = ratecal_drivers::DEFAULT_STATION_YAML.to_string();
    for (from, to) in edit {
        assert!(text.contains(from), "{from}");
        text = text.replacen(from, to, 1);
    }
    Station::from_yaml(&text, "test.yaml").unwrap()
}

async fn sleep(s: f64) {
    tokio::time::sleep(Duration::from_secs_f64(s)).await;
}

async fn drain(
    table: &mut Box<dyn TableDriver>,
    imu: &mut Box<dyn ImuDriver>,
) -> (Vec<TableSample>, Vec<ImuSample>) {
    let (mut t, mut i) = (Vec::new(), Vec::new());
    table.read(&mut t).await.unwrap();
    imu.read(&mut i).await.unwrap();
    (t, i)
}

#[tokio::test(start_paused = true)]
async fn moves_respect_rate_and_acceleration_limits() {
    let s = station(&[]).noiseless();
    let (mut table, mut imu) = build(&s, 3).unwrap();
    table
        .command(TableCommand::MoveTo {
            outer_deg: 170.0,
            inner_deg: -350.0,
        })
        .await
        .unwrap();
    sleep(10.0).await;
    let (fb, _) = drain(&mut table, &mut imu).await;
    let (vmax, amax) = (s.table.max_rate.0, s.table.max_accel_dps2);
    let peak_rate = fb
        .iter()
        .map(|x| x.inner_rate_dps.abs())
        .fold(0.0, f64::max);
    // 350 deg at 200 deg/s^2 would peak at 265 deg/s: the move is acceleration-limited.
    assert!(peak_rate > 180.0 && peak_rate <= 265.0, "{peak_rate}");
    for w in fb.windows(2) {
        let acc = (w[1].outer_rate_dps - w[0].outer_rate_dps) / (w[1].t - w[0].t);
        assert!(acc.abs() <= amax, "{acc} at {}", w[0].t);
        assert!(w[0].outer_rate_dps.abs() <= vmax);
    }
    let last = fb.last().unwrap();
    assert!((last.outer_deg - 170.0).abs() < 1e-9 && (last.inner_deg + 350.0).abs() < 1e-9);

    let big = TableCommand::Rate {
        axis: TableAxisId::Outer,
        rate_dps: 900.0,
    };
    let err = table.command(big).await.unwrap_err();
    assert_eq!(err.kind(), ratecal_drivers::DriverErrorKind::InvalidCommand);
}

#[tokio::test(start_paused = true)]
async fn settling_leaves_something_to_wait_for() {
    let s = station(&[]).noiseless();
    let (mut table, mut imu) = build(&s, 3).unwrap();
    table
        .command(TableCommand::MoveTo {
            outer_deg: 90.0,
            inner_deg: 0.0,
        })
        .await
        .unwrap();
    sleep(5.0).await;
    let (fb, _) = drain(&mut table, &mut imu).await;
    // The move takes about 2 sqrt(90 / 200) = 1.34 s; then the servo overshoots and settles.
    let err_at = |t: f64| {
        fb.iter()
            .find(|x| x.t >= t)
            .map(|x| (x.outer_deg - 90.0).abs())
            .unwrap()
    };
    let overshoot = fb
        .iter()
        .filter(|x| x.t > 1.34)
        .map(|x| (x.outer_deg - 90.0).abs())
        .fold(0.0, f64::max);
    assert!(overshoot > 5.0 / 3600.0, "overshoot {overshoot} deg");
    assert!(err_at(3.0) < 0.1 / 3600.0);
}

async fn record(seed: u64, chunk: f64) -> (Vec<TableSample>, Vec<ImuSample>) {
    let s = station(&[]);
    let (mut table, mut imu) = build(&s, seed).unwrap();
    let (mut t, mut i) = (Vec::new(), Vec::new());
    table
        .command(TableCommand::MoveTo {
            outer_deg: 45.0,
            inner_deg: 10.0,
        })
        .await
        .unwrap();
    let mut now = 0.0;
    while now < 30.0 {
        sleep(chunk).await;
        now += chunk;
        if (now - 10.0).abs() < chunk / 2.0 {
            table
                .command(TableCommand::Rate {
                    axis: TableAxisId::Inner,
                    rate_dps: 30.0,
                })
                .await
                .unwrap();
        }
        table.read(&mut t).await.unwrap();
        imu.read(&mut i).await.unwrap();
    }
    (t, i)
}

#[tokio::test(start_paused = true)]
async fn same_seed_same_samples_however_often_read() {
    let a = record(11, 0.1).await;
    let b = record(11, 0.5).await;
    let c = record(12, 0.1).await;
    assert_eq!(a.1.len(), 3001);
    assert_eq!(a, b);
    assert_ne!(a.1, c.1);
}

#[tokio::test(start_paused = true)]
async fn imu_dropout_gives_nan_then_recovers() {
    for (mode, check) in [("nan", 0), ("stuck", 1), ("missing", 2)] {
        let fault =
            format!("faults: [ {{ imu_dropout: {{ at: 5 s, duration: 2 s, mode: {mode} }} }} ]");
        let s = station(&[("faults: []", &fault)]);
        let (mut table, mut imu) = build(&s, 1).unwrap();
        sleep(10.0).await;
        let (_, xs) = drain(&mut table, &mut imu).await;
        let inside: Vec<_> = xs.iter().filter(|x| x.t >= 5.0 && x.t < 7.0).collect();
        let outside = xs.iter().filter(|x| x.t < 5.0 || x.t >= 7.0);
        assert!(
            outside
                .clone()
                .all(|x| x.accel.iter().all(|v| v.is_finite()))
        );
        match check {
            0 => assert!(inside.len() == 200 && inside.iter().all(|x| x.gyro[0].is_nan())),
            1 => assert!(inside.len() == 200 && inside.iter().all(|x| x.accel == inside[0].accel)),
            _ => assert!(inside.is_empty() && xs.len() == 801),
        }
    }
}

#[tokio::test(start_paused = true)]
async fn table_faults_stop_following_until_safe_stop() {
    let fault = "faults: [ { table: { at: 2 s, axis: outer, mode: stuck } } ]";
    let s = station(&[("faults: []", fault)]).noiseless();
    let (mut table, mut imu) = build(&s, 1).unwrap();
    sleep(3.0).await;
    table
        .command(TableCommand::MoveTo {
            outer_deg: 30.0,
            inner_deg: 30.0,
        })
        .await
        .unwrap();
    sleep(5.0).await;
    let (fb, _) = drain(&mut table, &mut imu).await;
    let last = fb.last().unwrap();
    assert_eq!(last.outer_deg, 0.0, "the stuck axis ignored the move");
    assert!((last.inner_deg - 30.0).abs() < 1e-9);

    let fault = "faults: [ { table: { at: 2 s, axis: inner, mode: runaway, rate: 40 deg/s } } ]";
    let s = station(&[("faults: []", fault)]).noiseless();
    let (mut table, mut imu) = build(&s, 1).unwrap();
    sleep(5.0).await;
    table
        .command(TableCommand::Stop {
            axis: TableAxisId::Inner,
        })
        .await
        .unwrap();
    sleep(2.0).await;
    let (fb, _) = drain(&mut table, &mut imu).await;
    assert!(
        (fb.last().unwrap().inner_rate_dps - 40.0).abs() < 1e-6,
        "a runaway axis ignores stop"
    );
    table.command(TableCommand::SafeStop).await.unwrap();
    sleep(3.0).await;
    let (fb, _) = drain(&mut table, &mut imu).await;
    assert_eq!(
        fb.last().unwrap().inner_rate_dps,
        0.0,
        "the emergency stop still works"
    );
}

#[tokio::test(start_paused = true)]
async fn temperature_excursion_shows_in_ambient() {
    let fault = "faults: [ { temperature_excursion: { at: 100 s, delta: 3 degC, ramp: 10 s, duration: 50 s } } ]";
    let s = station(&[("faults: []", fault)]).noiseless();
    let (mut table, mut imu) = build(&s, 1).unwrap();
    sleep(200.0).await;
    let (fb, xs) = drain(&mut table, &mut imu).await;
    let amb = |t: f64| fb.iter().find(|x| x.t >= t).unwrap().ambient_c.unwrap();
    let drift = 0.02 / 3600.0;
    assert!((amb(50.0) - (20.0 + drift * 50.0)).abs() < 1e-9);
    assert!((amb(130.0) - (23.0 + drift * 130.0)).abs() < 1e-9);
    assert!((amb(190.0) - (20.0 + drift * 190.0)).abs() < 1e-9);
    // IMU internal temperature: ambient plus a 4 degC warm-up over 10 min.
    let x = xs.iter().find(|x| x.t >= 130.0).unwrap();
    let want = 23.0 + drift * 130.0 + 4.0 * (1.0 - (-130.0f64 / 600.0).exp());
    assert!((x.temp_c.unwrap() - want).abs() < 1e-9);
}

#[tokio::test(start_paused = true)]
async fn noise_has_the_configured_size() {
    let s = station(&[]);
    let (mut table, mut imu) = build(&s, 5).unwrap();
    sleep(600.0).await;
    let (_, xs) = drain(&mut table, &mut imu).await;
    let std = |f: &dyn Fn(&ImuSample) -> f64| {
        let d: Vec<f64> = xs.windows(2).map(|w| f(&w[1]) - f(&w[0])).collect();
        (d.iter().map(|v| v * v).sum::<f64>() / d.len() as f64 / 2.0).sqrt()
    };
    // Per-sample sigma = density * sqrt(100 Hz); differencing cancels the slow terms.
    let sa = std(&|x| x.accel[2]);
    let sg = std(&|x| x.gyro[0]);
    assert!((sa / (2e-6 * 9.80665 * 10.0) - 1.0).abs() < 0.05, "{sa}");
    assert!((sg / 0.003 - 1.0).abs() < 0.05, "{sg}");
}

/// The Gauss-Markov sigma has one name (`gyro_bias_markov_sigma`, not the Allan floor's
/// "bias instability"); station files written with the former name read the same.
#[test]
fn the_markov_sigma_reads_under_its_former_name_too() {
    let now = station(&[]);
    let old = station(&[("gyro_bias_markov_sigma:", "gyro_bias_instability:")]);
    assert!(now.imu.gyro_bias_markov_sigma.0 > 0.0);
    assert_eq!(
        now.imu.gyro_bias_markov_sigma.0,
        old.imu.gyro_bias_markov_sigma.0
    );
}
