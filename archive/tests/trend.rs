//! Trend on simulated calibrations of one serial with a known drift, in a real SQLite
//! archive in a temporary folder: the drift comes back within its uncertainty, and the
//! recalibration interval follows from the acceptance limit.

use ratecal_archive::trend::TrendOptions;
use ratecal_archive::{Archive, Folder, IndexFacts, LimitRow, Location, ParamRow, iso_date};

const TRUE_RATE: f64 = 0.004; // m/s^2 per year
const U: f64 = 0.001;

/// Deterministic standard-normal draws (a fixed LCG and Box-Muller): the same every run.
fn normals(n: usize) -> Vec<f64> {
    let mut x: u64 = 0x2545_f491_4f6c_dd1d;
    let mut uni = || {
        x = x
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((x >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    };
    (0..n)
        .map(|_| {
            let (a, b) = (uni(), uni());
            (-2.0 * a.ln()).sqrt() * (std::f64::consts::TAU * b).cos()
        })
        .collect()
}

/// A calibration of serial `serial` on day `day` (days since 1970) with `bias`.
pub fn calibration(serial: &str, i: usize, day: f64, bias: f64, dry_run: bool) -> Folder {
    Folder {
        dir: Default::default(),
        files: Vec::new(),
        facts: IndexFacts {
            id: format!("{:016x}", 0xc0ffee_u64 * 1000 + i as u64),
            name: format!("cal-{i}"),
            serial: serial.into(),
            model: "SIM-TAC-100".into(),
            procedure: "imu-2d-standard".into(),
            version: "1.0.0".into(),
            station: "sim".into(),
            started: format!("{}T09:00:00Z", iso_date(day)),
            status: "completed".into(),
            dry_run,
            verdict: "pass".into(),
            imu: "{}".into(),
            parameters: vec![
                ParamRow {
                    name: "accel.bias.x".into(),
                    value: bias,
                    u: U,
                    unit: "m/s^2".into(),
                },
                ParamRow {
                    name: "gyro.scale.z".into(),
                    value: 120.0,
                    u: 5.0,
                    unit: "ppm".into(),
                },
            ],
            limits: vec![LimitRow {
                quantity: "abs(accel.bias.x)".into(),
                op: "<=".into(),
                limit: 0.05,
                unit: "m/s^2".into(),
            }],
            ..IndexFacts::default()
        },
    }
}

fn opts(params: &[&str]) -> TrendOptions {
    TrendOptions {
        params: params.iter().map(|s| s.to_string()).collect(),
        include_dry_runs: false,
        confidence: 0.95,
    }
}

#[tokio::test]
async fn known_drift_is_recovered_within_its_uncertainty() {
    let tmp = tempfile::tempdir().unwrap();
    let a = Archive::open(&Location::Folder(tmp.path().join("a")))
        .await
        .unwrap();
    let t0 = 19_000.0;
    let noise = normals(12);
    let mut cals: Vec<Folder> = (0..12)
        .map(|i| {
            let day = t0 + 91.0 * i as f64;
            let bias = 0.01 + TRUE_RATE * (day - t0) / 365.25 + U * noise[i];
            calibration("1234", i, day, bias, false)
        })
        .collect();
    // A dry run far off the line: left out of the trend.
    cals.push(calibration("1234", 99, t0 + 500.0, 1.0, true));
    a.insert_many(&cals).await.unwrap();

    let t = a.trend("1234", &opts(&["accel.bias.x"])).await.unwrap();
    assert_eq!(t.calibrations, 12);
    let p = &t.parameters[0];
    assert_eq!(p.points.len(), 12);
    let d = p.drift.expect("determined");
    assert!(d.u_rate_per_year > 0.0 && d.u_rate_per_year < TRUE_RATE);
    assert!(
        (d.rate_per_year - TRUE_RATE).abs() < 2.0 * d.u_rate_per_year,
        "{} ± {} vs {TRUE_RATE}",
        d.rate_per_year,
        d.u_rate_per_year
    );
    // |bias| reaches 0.05 about (0.05 - 0.0499) / 0.004 years after the last calibration
    // at the line; the 95 % bound reaches it sooner.
    let days = p.recalibration_days.expect("interval");
    let naive = (0.05 - d.value_at_last) / d.rate_per_year * 365.25;
    assert!(days > 0.0 && days < naive, "{days} vs {naive}");
    assert!(p.recalibrate_by.is_some());
    // No limit on the scale factor: drift, but no interval.
    let all = a.trend("1234", &opts(&[])).await.unwrap();
    let g = all
        .parameters
        .iter()
        .find(|p| p.name == "gyro.scale.z")
        .unwrap();
    assert!(g.limit.is_none() && g.recalibration_days.is_none());
    assert!(t.svg().contains("class=\"drift\""));
    assert!(t.text().contains("recalibrate within"));
    // The recommended interval is the earliest parameter's date, and names it.
    let (by, line) = all.recommended_interval().expect("a recommendation");
    assert_eq!(Some(by.clone()), p.recalibrate_by);
    assert!(
        line.starts_with(&format!(
            "recommended recalibration: {by} (from the drift of accel.bias.x"
        )),
        "{line}"
    );

    // The same limit written in mg on a plain `accel.bias.x <= L` (how the language
    // states a check on a calibrated parameter: its magnitude): the same interval.
    let b = Archive::open(&Location::Folder(tmp.path().join("b")))
        .await
        .unwrap();
    let in_mg: Vec<Folder> = cals
        .iter()
        .cloned()
        .map(|mut f| {
            f.facts.id = format!("mg{}", f.facts.id);
            f.facts.limits = vec![LimitRow {
                quantity: "accel.bias.x".into(),
                op: "<=".into(),
                limit: 0.05 / 9.80665 * 1000.0,
                unit: "mg".into(),
            }];
            f
        })
        .collect();
    b.insert_many(&in_mg).await.unwrap();
    let m = b.trend("1234", &opts(&["accel.bias.x"])).await.unwrap();
    let mg_days = m.parameters[0].recalibration_days.expect("interval in mg");
    assert!((mg_days - days).abs() < 1e-6 * days, "{mg_days} vs {days}");
}

#[tokio::test]
async fn one_date_leaves_the_drift_undetermined() {
    let tmp = tempfile::tempdir().unwrap();
    let a = Archive::open(&Location::Folder(tmp.path().join("a")))
        .await
        .unwrap();
    a.insert_many(&[
        calibration("77", 1, 20_000.1, 0.01, false),
        calibration("77", 2, 20_000.6, 0.011, false),
    ])
    .await
    .unwrap();
    let t = a.trend("77", &opts(&["accel.bias.x"])).await.unwrap();
    let p = &t.parameters[0];
    assert_eq!(p.drift_status, "undetermined");
    assert!(p.drift.is_none() && p.recalibration_days.is_none());
    let none = a.trend("no-such-serial", &opts(&[])).await.unwrap();
    assert_eq!(none.calibrations, 0);
    assert!(none.parameters.is_empty());
}

/// `within +-L` bounds both sides: a bias drifting downwards reaches -L, and the interval
/// is the mirror image's (the same data negated, against `<= L`), to the day.
#[tokio::test]
async fn a_within_limit_is_reached_from_below() {
    let tmp = tempfile::tempdir().unwrap();
    let t0 = 19_000.0;
    let noise = normals(8);
    let series = |sign: f64, prefix: &str, q: &str, op: &str| -> Vec<Folder> {
        (0..8)
            .map(|i| {
                let day = t0 + 91.0 * i as f64;
                let bias = sign * (0.01 + TRUE_RATE * (day - t0) / 365.25 + U * noise[i]);
                let mut f = calibration("55", i, day, bias, false);
                f.facts.id = format!("{prefix}{}", f.facts.id);
                f.facts.limits = vec![LimitRow {
                    quantity: q.into(),
                    op: op.into(),
                    limit: 0.05,
                    unit: "m/s^2".into(),
                }];
                f
            })
            .collect()
    };
    let down = Archive::open(&Location::Folder(tmp.path().join("down")))
        .await
        .unwrap();
    down.insert_many(&series(-1.0, "d", "accel.bias.x", "within"))
        .await
        .unwrap();
    let t = down.trend("55", &opts(&["accel.bias.x"])).await.unwrap();
    let p = &t.parameters[0];
    assert!(p.drift.expect("determined").rate_per_year < 0.0);
    let days = p
        .recalibration_days
        .expect("an interval from the lower side");
    assert_eq!(
        p.limit.as_ref().unwrap().text,
        "accel.bias.x within +-0.05 m/s^2"
    );
    let (_, line) = t.recommended_interval().expect("a recommendation");
    assert!(
        line.contains("reaches accel.bias.x within +-0.05 m/s^2"),
        "{line}"
    );

    let up = Archive::open(&Location::Folder(tmp.path().join("up")))
        .await
        .unwrap();
    up.insert_many(&series(1.0, "u", "accel.bias.x", "<="))
        .await
        .unwrap();
    let m = up.trend("55", &opts(&["accel.bias.x"])).await.unwrap();
    let mirror = m.parameters[0].recalibration_days.expect("mirror interval");
    assert!((mirror - days).abs() < 1e-6 * days, "{mirror} vs {days}");
}
