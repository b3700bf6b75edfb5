//! `ratecal import` with static-interval detection on two public real sessions no one here
//! wrote: imu_tk's Xsens MTi (two whitespace text files named `.mat`, unsigned counts) and
//! an MPU-6050 (raw registers after a metadata header). The detected intervals are checked
//! against the sources through values the importer never sees: the Xsens factory
//! calibration (`shared/real/imu_tk/README.md`) and the MPU-6050's documented start-up rest.

use crate::support;
use support::*;

use std::path::Path;

/// Whitespace- or comma-separated numbers, after `skip` lines.
fn numbers(path: &Path, skip: usize) -> Vec<Vec<f64>> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .skip(skip)
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            l.split(|c: char| c == ',' || c.is_whitespace())
                .filter(|c| !c.is_empty())
                .map(|c| c.parse().unwrap())
                .collect()
        })
        .collect()
}

/// Every detected static interval: (t_start, t_end, oblique) from the manifest's static
/// segments (`Some` when no body axis is near vertical: the manifest has no `up`); each is
/// `attitude: unknown` (hand-held), and a free `turn` lies between each two.
fn intervals(run: &Path) -> Vec<(f64, f64, Option<String>)> {
    let text = std::fs::read_to_string(run.join("manifest.yaml")).unwrap();
    let m: serde_json::Value = serde_saphyr::from_str(&text).unwrap();
    let mut v: Vec<(f64, f64, Option<String>)> = Vec::new();
    let segs = m["segments"].as_array().unwrap();
    for (i, s) in segs.iter().enumerate() {
        if s["kind"] == "turn" {
            // Between two poses, from the end of one to the start of the next.
            assert_eq!(s["t_start"], segs[i - 1]["t_end"]);
            assert_eq!(s["t_end"], segs[i + 1]["t_start"]);
            continue;
        }
        assert_eq!(s["kind"], "static");
        assert_eq!(s["attitude"], "unknown");
        v.push((
            s["t_start"].as_f64().unwrap(),
            s["t_end"].as_f64().unwrap(),
            s["up"].is_null().then(|| "oblique".to_string()),
        ));
    }
    v.sort_by(|a, b| a.0.total_cmp(&b.0));
    v
}

#[test]
fn imu_tk_xsens_poses_are_found_and_static_by_the_factory_calibration() {
    let Some([acc, gyr]) = xsens_session() else {
        return;
    };
    let tmp = tempfile::tempdir().unwrap();
    let o = ratecal(
        &[
            "import",
            acc.to_str().unwrap(),
            gyr.to_str().unwrap(),
            "--map",
            &import_map("imu_tk-xsens.yaml"),
            "--out",
            "run",
        ],
        tmp.path(),
    );
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert!(
        text(&o).contains("detected from the signal"),
        "{}",
        text(&o)
    );
    let run = tmp.path().join("run");
    let found = intervals(&run);
    // About 50 s at rest, then about 37 poses (the source's README).
    assert!(
        (35..=42).contains(&found.len()),
        "{} intervals",
        found.len()
    );
    assert!(found[0].0 < 0.1 && found[0].1 > 45.0, "{:?}", found[0]);

    // The time column is the source's, exactly; the gyro file's columns follow the accel's.
    let (a, g) = (numbers(&acc, 0), numbers(&gyr, 0));
    let imu = numbers(&run.join("imu.csv"), 1);
    assert_eq!(imu.len(), a.len());
    for i in [0, 1000, a.len() - 1] {
        assert_eq!(imu[i][0], a[i][0]);
        assert!(
            (imu[i][4] - (g[i][1] - 32768.0) / 4767.0 * 180.0 / std::f64::consts::PI).abs() < 1e-9
        );
    }

    // Each interval, averaged from the source's raw counts and calibrated with the factory
    // values, reads gravity (the README: 9.803 +- 0.013 m/s^2 over the static poses): a
    // window that took in part of a hand turn would not.
    let offset = [33123.0, 33276.0, 32360.0];
    let k = [415.0, 413.0, 415.0];
    let m = [[1.00, 0.00, -0.01], [0.01, 1.00, 0.01], [0.02, 0.01, 1.00]];
    for (t0, t1, up) in &found {
        let rows: Vec<&Vec<f64>> = a.iter().filter(|r| r[0] >= *t0 && r[0] <= *t1).collect();
        let raw: [f64; 3] = std::array::from_fn(|j| {
            rows.iter().map(|r| r[j + 1]).sum::<f64>() / rows.len() as f64 - offset[j]
        });
        // x = inv(K M) raw: solve K M x = raw (M is close to I: three Jacobi sweeps suffice).
        let mut x = [0.0; 3];
        for _ in 0..20 {
            x = std::array::from_fn(|i| {
                let off: f64 = (0..3).filter(|&j| j != i).map(|j| m[i][j] * x[j]).sum();
                (raw[i] / k[i] - off) / m[i][i]
            });
        }
        let norm = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
        assert!(
            (norm - 9.803).abs() < 0.05,
            "interval {t0}..{t1}: |a| = {norm}"
        );
        // Oblique (`up: oblique`) exactly when no axis of gravity, from the raw counts with
        // the map's nominal zero and scale (not the factory calibration: its offsets of up
        // to 900 counts tilt the nominal vector by several degrees), is within 10 deg of
        // vertical (0.5 deg of margin for the edges of a window).
        let nominal: [f64; 3] = std::array::from_fn(|j| {
            rows.iter().map(|r| r[j + 1] - 32768.0).sum::<f64>() / rows.len() as f64
        });
        let n = nominal.iter().map(|c| c * c).sum::<f64>().sqrt();
        let cos_near = nominal.iter().map(|c| c.abs()).fold(0.0, f64::max) / n;
        let deg = cos_near.clamp(-1.0, 1.0).acos().to_degrees();
        match up {
            Some(_) => assert!(
                deg > 9.5,
                "{t0}..{t1} oblique, but {deg:.1} deg from an axis"
            ),
            None => assert!(
                deg < 10.5,
                "{t0}..{t1} a face, but {deg:.1} deg from an axis"
            ),
        }
    }

    // The session's many oblique poses are static segments of unknown attitude, like the
    // rest; `analyze` calibrates from all of them (gravity's magnitude) and the turns.
    let oblique: Vec<usize> = (0..found.len()).filter(|&i| found[i].2.is_some()).collect();
    assert!(oblique.len() >= 20, "{} oblique", oblique.len());
    assert!(found.len() - oblique.len() >= 6);
    let o = ratecal(&["analyze", "run", "--out", "results.json"], tmp.path());
    assert!(matches!(code(&o), 0 | 3), "{}", text(&o));
    let r = json(&tmp.path().join("results.json"));
    for s in r["segments"].as_array().unwrap() {
        let used = s["used_for"].as_array().unwrap();
        let want = if s["kind"] == "static" {
            "accel"
        } else {
            "gyro_full"
        };
        assert!(used.iter().any(|u| u == want), "{}: {used:?}", s["id"]);
    }
}

#[test]
fn mpu6050_start_up_rest_and_poses_are_found() {
    let Some(src) = shared_path("real/mpu6050/example_data_calibration.csv") else {
        return;
    };
    let tmp = tempfile::tempdir().unwrap();
    let o = ratecal(
        &[
            "import",
            src.to_str().unwrap(),
            "--map",
            &import_map("mpu6050.yaml"),
            "--out",
            "run",
        ],
        tmp.path(),
    );
    assert_eq!(code(&o), 0, "{}", text(&o));
    let run = tmp.path().join("run");
    let found = intervals(&run);
    // The logger's own header: "Initialization time,36.5" (s at rest, z up).
    assert!(
        found[0].0 == 0.0 && (35.0..38.0).contains(&found[0].1),
        "{:?}",
        found[0]
    );
    assert!(found.len() >= 6, "{found:?}");
    // Every interval reads one g within the part's tolerances, from the raw registers.
    let raw = numbers(&src, 5);
    for (t0, t1, _) in &found {
        let (i0, i1) = ((t0 * 100.0).round() as usize, (t1 * 100.0).round() as usize);
        let mean: [f64; 3] = std::array::from_fn(|j| {
            raw[i0..=i1].iter().map(|r| r[j]).sum::<f64>() / (i1 - i0 + 1) as f64 / 16384.0
        });
        let g = (mean[0] * mean[0] + mean[1] * mean[1] + mean[2] * mean[2]).sqrt();
        assert!((0.88..1.12).contains(&g), "{t0}..{t1}: {g} g");
    }
    // Samples exactly the registers scaled: 16384 counts per g.
    let imu = numbers(&run.join("imu.csv"), 1);
    assert_eq!(imu.len(), raw.len());
    assert_eq!(imu[7][3], raw[7][2] * (9.80665 / 16384.0));
}

/// A gyro unit slip that no rest shows (`deg/h` for the Ferraris session's deg/s: its
/// biases at rest become 0.0003 deg/s, a plausible rest) is caught by the hand turns: the
/// map declares -360 deg about each axis, the gyros would turn a tenth of a degree.
/// Refused at the unit, the right unit named, nothing written.
#[test]
fn a_gyro_unit_slip_is_caught_by_the_declared_turns() {
    let Some(src) = shared_path("real/imucal/example_ferraris_session.csv") else {
        return;
    };
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let map = std::fs::read_to_string(root.join("docs/examples/import/ferraris.yaml")).unwrap();
    assert!(map.contains("gyro: deg/s }"));
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(
        tmp.path().join("m.yaml"),
        map.replace("gyro: deg/s }", "gyro: deg/h }"),
    )
    .unwrap();
    let o = ratecal(
        &[
            "import",
            src.to_str().unwrap(),
            "--map",
            "m.yaml",
            "--out",
            "run",
        ],
        tmp.path(),
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("turn segment `x_rot`"), "{err}");
    assert!(err.contains("look like deg/s, not deg/h"), "{err}");
    assert!(err.contains("m.yaml:23:"), "{err}");
    assert!(!tmp.path().join("run").exists());
}
