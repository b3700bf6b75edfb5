//! `ratecal import` with the table's own feedback file, on a recording we did not make:
//! `shared/examples/standard-with-lever-arm` rewritten in a lab's format (renamed columns,
//! semicolons, milliseconds, accelerations in g, rates and angles in radians), imported
//! with a map and `table: { file: ... }`, and analysed: the results equal the original's
//! within a small fraction of their uncertainty, and the manifest says `table: feedback`.
//! Feedback in the wrong unit, going backwards, or missing, is refused (exit 1).

use crate::support;
use support::*;

use std::fmt::Write as _;
use std::path::Path;

/// The lab's files beside the map; returns the map text.
fn lab_files(example: &Path, dir: &Path) -> String {
    let csv = |name: &str| -> Vec<Vec<f64>> {
        std::fs::read_to_string(example.join(name))
            .unwrap()
            .lines()
            .skip(1)
            .map(|l| l.split(',').map(|c| c.parse().unwrap()).collect())
            .collect()
    };
    let d2r = std::f64::consts::PI / 180.0;
    let mut imu = String::from("zeit_ms;acc_x_g;acc_y_g;acc_z_g;rot_x;rot_y;rot_z\n");
    for r in csv("imu.csv") {
        let v = [
            r[0] * 1000.0,
            r[1] / 9.80665,
            r[2] / 9.80665,
            r[3] / 9.80665,
            r[4] * d2r,
            r[5] * d2r,
            r[6] * d2r,
        ];
        let row: Vec<String> = v.iter().map(|x| format!("{x:?}")).collect();
        writeln!(imu, "{}", row.join(";")).unwrap();
    }
    std::fs::write(dir.join("daq.csv"), imu).unwrap();
    let mut table = String::from("t_ms;phi_out;phi_in;rate_out;rate_in\n");
    for r in csv("table.csv") {
        let v = [
            r[0] * 1000.0,
            r[1] * d2r,
            r[2] * d2r,
            r[3] * d2r,
            r[4] * d2r,
        ];
        let row: Vec<String> = v.iter().map(|x| format!("{x:?}")).collect();
        writeln!(table, "{}", row.join(";")).unwrap();
    }
    std::fs::write(dir.join("feedback.csv"), table).unwrap();

    // The example's segments, as a lab would write them from its notebook.
    let text = std::fs::read_to_string(example.join("manifest.yaml")).unwrap();
    let m: serde_json::Value = serde_saphyr::from_str(&text).unwrap();
    let mut segs = String::new();
    for s in m["segments"].as_array().unwrap() {
        let rate = match (&s["axis"], &s["rate_dps"]) {
            (serde_json::Value::String(a), r) if r.is_number() => {
                format!(", axis: {a}, rate_dps: {r}")
            }
            _ => String::new(),
        };
        writeln!(
            segs,
            "  - {{ id: \"{}\", kind: {}, time: [{}, {}]{rate} }}",
            s["id"].as_str().unwrap(),
            s["kind"].as_str().unwrap(),
            s["t_start"],
            s["t_end"]
        )
        .unwrap();
    }
    let site = &m["station"]["site"];
    format!(
        "source: {{ format: csv, delimiter: \";\" }}
imu:
  time: {{ column: zeit_ms, unit: ms }}
  columns: {{ ax: acc_x_g, ay: acc_y_g, az: acc_z_g, gx: rot_x, gy: rot_y, gz: rot_z }}
  units: {{ accel: g, gyro: rad/s }}
segments:
{segs}table:
  file: feedback.csv
  source: {{ format: csv, delimiter: \";\" }}
  time: {{ column: t_ms, unit: ms }}
  offset_s: 0
  columns: {{ outer: phi_out, inner: phi_in, outer_rate: rate_out, inner_rate: rate_in }}
  units: {{ angle: rad, rate: rad/s }}
  outer_axis: [0, -1, 0]
  inner_axis: [1, 0, 0]
site: {{ latitude_deg: {}, gravity_mps2: {} }}
",
        site["latitude_deg"], site["gravity_mps2"]
    )
}

fn import(dir: &Path, map: &str, out: &str) -> std::process::Output {
    std::fs::write(dir.join("map.yaml"), map).unwrap();
    ratecal(
        &["import", "daq.csv", "--map", "map.yaml", "--out", out],
        dir,
    )
}

#[test]
fn a_lab_format_with_feedback_analyses_as_the_original() {
    let Some(example) = shared_example("standard-with-lever-arm") else {
        return;
    };
    let tmp = tempfile::tempdir().unwrap();
    let map = lab_files(&example, tmp.path());
    let o = import(tmp.path(), &map, "run");
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert!(text(&o).contains("feedback samples from feedback.csv"));
    let manifest = std::fs::read_to_string(tmp.path().join("run/manifest.yaml")).unwrap();
    let m: serde_json::Value = serde_saphyr::from_str(&manifest).unwrap();
    assert_eq!(m["provenance"]["table"], "feedback");
    let sha =
        ratecal_recording::sha256_hex(&std::fs::read(tmp.path().join("feedback.csv")).unwrap());
    assert_eq!(m["provenance"]["table_file"]["sha256"], sha.as_str());
    assert_eq!(m["segments"].as_array().unwrap().len(), 17);

    // The feedback stream is the original's, sample for sample.
    let (orig, imp) = (
        ratecal_recording::read(&example).unwrap(),
        ratecal_recording::read(&tmp.path().join("run")).unwrap(),
    );
    assert_eq!(orig.table.t.len(), imp.table.t.len());
    for i in (0..orig.table.t.len()).step_by(997) {
        assert!((orig.table.t[i] - imp.table.t[i]).abs() < 1e-9);
        assert!((orig.table.outer[i] - imp.table.outer[i]).abs() < 1e-9);
        assert!((orig.table.inner_rate[i] - imp.table.inner_rate[i]).abs() < 1e-9);
    }

    let analyze = |run: &Path, out: &str| -> serde_json::Value {
        let o = ratecal(
            &["analyze", run.to_str().unwrap(), "--out", out],
            tmp.path(),
        );
        assert!(matches!(code(&o), 0 | 1), "{}", text(&o));
        json(&tmp.path().join(out))
    };
    let (a, b) = (
        analyze(&example, "orig.json"),
        analyze(&tmp.path().join("run"), "imp.json"),
    );
    assert_eq!(a["verdict"], b["verdict"]);
    // Each parameter within 1% of its uncertainty: the segments' windows differ only by
    // the table samples on their edges (the map's [t0, t1) keeps the IMU's samples).
    let (pa, pb) = (
        a["parameters"].as_object().unwrap(),
        b["parameters"].as_object().unwrap(),
    );
    assert_eq!(pa.len(), pb.len());
    let mut n = 0;
    for (k, p) in pa {
        let q = &pb[k];
        if p.get("observable") == Some(&serde_json::Value::Bool(false)) {
            // Not observable from this procedure (gyro.scale.z): the same in both.
            assert_eq!(p, q, "{k}");
            continue;
        }
        if let Some(x) = p["upper_bound"].as_f64() {
            // A bound only (an Allan curve still falling): the same bound in both.
            let y = q["upper_bound"].as_f64().unwrap();
            assert!((x - y).abs() <= 0.01 * x.abs(), "{k}: {x} vs {y}");
            continue;
        }
        let (x, y, u) = (
            p["value"].as_f64().unwrap(),
            q["value"].as_f64().unwrap(),
            p["u"].as_f64().unwrap(),
        );
        assert!((x - y).abs() < 0.01 * u, "{k}: {x} vs {y} (u {u})");
        n += 1;
    }
    assert!(n >= 12, "{n} parameters");
    for k in ["accel.scale.z", "gyro.scale.x", "accel.bias.x"] {
        assert!(pa.contains_key(k), "{k}");
    }
}

/// Exit 1, nothing written, and the message holds each of `want`.
fn refused(dir: &Path, map: &str, want: &[&str]) {
    let o = import(dir, map, "refused");
    let t = text(&o).replace('│', " ");
    let t = t.split_whitespace().collect::<Vec<_>>().join(" ");
    assert_eq!(code(&o), 1, "{t}");
    assert!(!dir.join("refused").exists(), "{t}");
    for w in want {
        assert!(t.contains(w), "no `{w}` in:\n{t}");
    }
}

#[test]
fn feedback_in_the_wrong_unit_backwards_or_missing_is_refused() {
    let Some(example) = shared_example("standard-with-lever-arm") else {
        return;
    };
    let tmp = tempfile::tempdir().unwrap();
    let map = lab_files(&example, tmp.path());
    // Radians declared as degrees: the angle turns 57 times slower than the rate reads.
    refused(
        tmp.path(),
        &map.replace(
            "units: { angle: rad, rate: rad/s }",
            "units: { angle: deg, rate: rad/s }",
        ),
        &[
            "the outer angle turns at",
            "look like rad, not deg: set table.units.angle",
            "map.yaml:",
        ],
    );
    // Rates declared as deg/s: the rate column does not read the declared rate.
    refused(
        tmp.path(),
        &map.replace(
            "units: { angle: rad, rate: rad/s }",
            "units: { angle: rad, rate: deg/s }",
        ),
        &["look like rad/s, not deg/s: set table.units.rate"],
    );
    // A clock that does not meet the IMU's.
    refused(
        tmp.path(),
        &map.replace("offset_s: 0", "offset_s: 5000"),
        &["has no table feedback sample", "offset_s"],
    );
    refused(
        tmp.path(),
        &map.replace("file: feedback.csv", "file: nowhere.csv"),
        &["no table feedback file", "map.yaml:"],
    );
    // Time going backwards in the feedback: located in its file.
    let fb = std::fs::read_to_string(tmp.path().join("feedback.csv")).unwrap();
    let mut lines: Vec<&str> = fb.lines().collect();
    lines.swap(100, 101);
    std::fs::write(tmp.path().join("back.csv"), lines.join("\n")).unwrap();
    refused(
        tmp.path(),
        &map.replace("file: feedback.csv", "file: back.csv"),
        &["back.csv:102:1", "table time goes backwards"],
    );
}
