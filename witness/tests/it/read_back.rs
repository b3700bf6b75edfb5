//! A witness recording read through the project's reader (`ratecal_recording::read`) holds
//! the numbers the witness computed; the plan has the shared examples' shape; the noise is
//! seeded and of the stated size.

use std::path::Path;

use ratecal_recording::SegmentKind;
use ratecal_witness::{Hidden, Plan, Scenario, write};

fn short(name: &str, seed: u64) -> Scenario {
    let mut s = Scenario::standard(name, seed);
    s.plan = Plan::standard(30.0);
    s
}

/// Every IMU row equals the closed form at its stamp (to the file's rounding), every table
/// row the timeline; the segments are the standard procedure's, in its ids, kinds and keys.
#[test]
fn a_quiet_recording_reads_back_as_computed() {
    let dir = tempfile::tempdir().unwrap();
    let s = short("read-back", 3)
        .quiet()
        .with(Hidden::ClockRate { ppm: 40.0 })
        .with(Hidden::LeverArm {
            r_mm: [[10.0, 0.0, -5.0], [0.0, 20.0, 0.0], [3.0, 0.0, 30.0]],
        });
    let truth = write(dir.path(), &s).unwrap();
    let rec = ratecal_recording::read(dir.path()).unwrap();
    let tl = s.timeline();

    let m = &rec.manifest;
    assert_eq!(m.station.site.latitude_deg, 40.0);
    assert_eq!(m.station.site.gravity_mps2, 9.8016);
    let ids: Vec<&str> = m.segments.iter().map(|g| g.id.as_str()).collect();
    let mut want = vec![];
    for n in 1..=6 {
        want.push(format!("accel_static/{n}"));
    }
    want.push("gyro_bias".into());
    for axis in ["outer", "inner"] {
        for r in ["-100", "-50", "+0", "+50", "+100"] {
            want.push(format!("gyro_scale/{axis}/{r}"));
        }
    }
    assert_eq!(ids, want);
    for (g, spec) in m.segments.iter().zip(&tl.segments) {
        assert!((g.t_start - spec.t_start).abs() < 1e-4 && (g.t_end - spec.t_end).abs() < 1e-4);
        match spec.rate {
            Some((axis, rate)) => {
                assert_eq!(g.kind, SegmentKind::Rate);
                assert_eq!(g.rate_dps, Some(rate));
                assert_eq!(g.axis.as_deref(), Some(axis.name()));
            }
            None => assert_eq!(g.kind, SegmentKind::Static),
        }
    }

    let imu = &rec.imu;
    assert!((imu.t[1] - imu.t[0] - 0.01).abs() < 1e-9);
    assert!((imu.t[imu.t.len() - 1] - truth.duration_s).abs() <= 0.01);
    let temp = imu.temp.as_ref().unwrap();
    for k in (0..imu.t.len()).step_by(7) {
        let inst = s.instant(&tl, imu.t[k]);
        let (a, w) = s.outputs(&inst);
        for i in 0..3 {
            assert!((imu.accel[i][k] - a[i]).abs() <= 5.1e-7, "row {k} a{i}");
            assert!((imu.gyro[i][k] - w[i]).abs() <= 5.1e-8, "row {k} g{i}");
        }
        assert!((temp[k] - inst.temp_c).abs() <= 5.1e-4);
    }
    let table = &rec.table;
    assert!((table.t[1] - 0.02).abs() < 1e-12);
    for k in (0..table.t.len()).step_by(3) {
        let [o, i] = tl.state(table.t[k]);
        assert!((table.outer[k] - o[0]).abs() <= 5.1e-7);
        assert!((table.inner[k] - i[0]).abs() <= 5.1e-7);
        assert!((table.outer_rate[k] - o[1]).abs() <= 5.1e-6);
        assert!((table.inner_rate[k] - i[1]).abs() <= 5.1e-6);
    }

    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("truth.json")).unwrap())
            .unwrap();
    assert_eq!(json["hidden"][0]["id"], "clock_rate");
    assert_eq!(json["hidden"][1]["parameters"]["rzx_mm"], 3.0);
    assert_eq!(json["nominal"]["gyro_scale_ppm"][2], 1100.0);
}

fn file(dir: &Path, name: &str) -> String {
    std::fs::read_to_string(dir.join(name)).unwrap()
}

/// The same seed writes the same files; another seed other noise, of the stated size.
#[test]
fn noise_is_seeded_and_of_the_stated_size() {
    let dirs: Vec<_> = (0..3).map(|_| tempfile::tempdir().unwrap()).collect();
    for (d, seed) in dirs.iter().zip([5, 5, 6]) {
        write(d.path(), &short("noise", seed)).unwrap();
    }
    let (a, b, c) = (dirs[0].path(), dirs[1].path(), dirs[2].path());
    assert_eq!(file(a, "imu.csv"), file(b, "imu.csv"));
    assert_eq!(file(a, "table.csv"), file(b, "table.csv"));
    assert_ne!(file(a, "imu.csv"), file(c, "imu.csv"));

    let s = short("noise", 5);
    let tl = s.timeline();
    let rec = ratecal_recording::read(a).unwrap();
    let seg = tl.segments.iter().find(|g| g.id == "gyro_bias").unwrap();
    let (mut da, mut dg, mut n) = (0.0, 0.0, 0.0);
    for (k, &t) in rec.imu.t.iter().enumerate() {
        if t < seg.t_start || t > seg.t_end {
            continue;
        }
        let (a, w) = s.outputs(&s.instant(&tl, t));
        da += (rec.imu.accel[0][k] - a[0]).powi(2);
        dg += (rec.imu.gyro[2][k] - w[2]).powi(2);
        n += 1.0;
    }
    let (sa, sg) = ((da / n).sqrt(), (dg / n).sqrt());
    assert!((sa / 0.003 - 1.0).abs() < 0.05, "accel noise {sa}");
    // The gyro's residual also holds the wandering bias (about 1e-5 deg/s per sqrt(s)).
    assert!((sg / 0.005 - 1.0).abs() < 0.1, "gyro noise {sg}");
}
