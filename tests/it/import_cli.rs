//! `ratecal import` end to end (the real binary): mad-lab imucal's Ferraris session (real
//! data no one here wrote) imported with `docs/examples/import/ferraris.yaml` holds exactly
//! the source's samples, agrees with the hand-converted `shared/examples/real-ferraris-session`,
//! and is accepted by analyze, explain, verify and archive add; small generated sessions
//! with one thing wrong are refused (exit 1, nothing written) with a diagnostic naming the
//! file, line and column and a help line.

use crate::support;
use support::*;

use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

fn example_map(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("docs/examples/import")
        .join(name)
}

/// Rows of a CSV file (after its header) as numbers.
fn rows(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    let rows = lines
        .filter(|l| !l.is_empty())
        .map(|l| l.split(',').map(|c| c.parse().unwrap()).collect())
        .collect();
    (header, rows)
}

fn param(results: &serde_json::Value, name: &str) -> f64 {
    results["parameters"][name]["value"]
        .as_f64()
        .unwrap_or_else(|| panic!("{name} in {}", results["parameters"]))
}

#[test]
fn ferraris_session_is_the_hand_converted_example() {
    let (Some(src), Some(example)) = (
        shared_path("real/imucal/example_ferraris_session.csv"),
        shared_path("examples/real-ferraris-session"),
    ) else {
        return;
    };
    let tmp = tempfile::tempdir().unwrap();
    let cwd = tmp.path();
    let map = example_map("ferraris.yaml");
    let o = ratecal(
        &[
            "import",
            src.to_str().unwrap(),
            "--map",
            map.to_str().unwrap(),
            "--out",
            "run",
        ],
        cwd,
    );
    assert_eq!(code(&o), 0, "{}", text(&o));
    for id in ["x_up", "x_down", "y_up", "y_down", "z_up", "z_down"] {
        assert!(text(&o).contains(id), "{}", text(&o));
    }
    let run = cwd.join("run");

    // The same samples as the source, exactly: t = i / 102.4, columns reordered.
    let (h, imp) = rows(&run.join("imu.csv"));
    assert_eq!(h, ["t", "ax", "ay", "az", "gx", "gy", "gz"]);
    let (sh, source) = rows(&src);
    assert_eq!(
        sh,
        [
            "n_samples",
            "gyr_x",
            "gyr_y",
            "gyr_z",
            "acc_x",
            "acc_y",
            "acc_z"
        ]
    );
    assert_eq!(imp.len(), source.len());
    for (i, (a, s)) in imp.iter().zip(&source).enumerate() {
        assert_eq!(a[0], i as f64 / 102.4, "t of sample {i}");
        assert_eq!(&a[1..4], &s[4..7], "accel of sample {i}");
        assert_eq!(&a[4..7], &s[1..4], "gyro of sample {i}");
    }
    // And as the hand conversion, which rounded every value to 7 decimals: within that
    // rounding (5e-8) plus 1e-9 relative.
    let (_, ex) = rows(&example.join("imu.csv"));
    assert_eq!(ex.len(), imp.len());
    for (a, e) in imp.iter().zip(&ex) {
        for k in 0..7 {
            assert!(
                (a[k] - e[k]).abs() <= 5e-8 + 1e-9 * e[k].abs(),
                "{a:?} vs {e:?}"
            );
        }
    }

    // Provenance: the map and the source's SHA-256, the synthesized table.
    let manifest = std::fs::read_to_string(run.join("manifest.yaml")).unwrap();
    let sha = |p: &Path| hex::encode(Sha256::digest(std::fs::read(p).unwrap()));
    assert!(manifest.contains(&sha(&src)), "{manifest}");
    assert!(manifest.contains(&sha(&map)), "{manifest}");
    assert!(manifest.contains("table: synthesized"), "{manifest}");

    // Its faces are `nominal` (the map): analysed, it is calibrated by the six-face
    // solution, which equals the closed form of exact faces computed here from the hand
    // conversion's own windows (rounded by hand: a sample at each edge may differ): the
    // bias is the mean of the six faces' means, column j of K_a their difference over 2 g.
    let o = ratecal(&["analyze", "run", "--out", "imp.json"], cwd);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let a = json(&cwd.join("imp.json"));
    assert_eq!(a["manual"]["method"], "six_face");
    let g = 9.8095;
    let window = |t0: f64, t1: f64| -> [f64; 3] {
        let w: Vec<&Vec<f64>> = ex.iter().filter(|r| r[0] >= t0 && r[0] <= t1).collect();
        std::array::from_fn(|k| w.iter().map(|r| r[1 + k]).sum::<f64>() / w.len() as f64)
    };
    let faces = [
        window(5.27344, 12.41211),
        window(15.82031, 23.05664),
        window(27.48047, 32.20703),
        window(36.52344, 40.54688),
        window(44.16016, 48.58398),
        window(52.5, 58.42773),
    ];
    for (i, ax) in ["x", "y", "z"].iter().enumerate() {
        let bias = faces.iter().map(|f| f[i]).sum::<f64>() / 6.0;
        let scale = (faces[2 * i][i] - faces[2 * i + 1][i]) / (2.0 * g) - 1.0;
        let got_b = param(&a, &format!("accel.bias.{ax}"));
        let got_s = param(&a, &format!("accel.scale.{ax}"));
        assert!(
            (got_b - bias).abs() < 1e-4,
            "accel.bias.{ax}: {got_b} vs {bias}"
        );
        assert!(
            (got_s - 1e6 * scale).abs() < 10.0,
            "accel.scale.{ax}: {got_s} vs {}",
            1e6 * scale
        );
    }

    // explain reads it (0 nothing found, 1 findings); verify and archive add accept it.
    let o = ratecal(&["explain", "run"], cwd);
    assert!(matches!(code(&o), 0 | 1), "{}", text(&o));
    let o = ratecal(&["verify", "run"], cwd);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let o = ratecal(&["archive", "--archive", "arch", "add", "run"], cwd);
    assert_eq!(code(&o), 0, "{}", text(&o));
}

/// A generated session at 100 Hz: 3 s with +z up, 3 s with +x up, 3 s turning about z at
/// 100 deg/s; accelerometers in g, gyros in deg/s (before `edit`).
fn session(edit: impl Fn(usize, &mut [f64; 6])) -> String {
    let mut s = String::from("acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z\n");
    for i in 0..900 {
        let n = ((i * 7919) % 13) as f64 * 1e-4;
        let mut r = match i {
            0..300 => [0.01 + n, -0.02, 1.0 - n, 0.3, -0.2, 0.1 + n],
            300..600 => [1.0 + n, -0.02, 0.01, 0.3, -0.2 + n, 0.1],
            _ => [0.01, -0.02, 1.0 + n, 0.3, -0.2, 100.0 + n],
        };
        edit(i, &mut r);
        let cells: Vec<String> = r.iter().map(|v| v.to_string()).collect();
        s.push_str(&cells.join(","));
        s.push('\n');
    }
    s
}

const MAP: &str = "source: { format: csv }
imu:
  time: { rate_hz: 100 }
  columns: { ax: acc_x, ay: acc_y, az: acc_z, gx: gyr_x, gy: gyr_y, gz: gyr_z }
  units: { accel: g, gyro: deg/s }
segments:
  - { id: z_up, kind: static, samples: [20, 280], up: +z }
  - { id: x_up, kind: static, samples: [320, 580], up: +x }
  - { id: turn, kind: rate, samples: [620, 880], axis: z, rate_dps: 100 }
site: { latitude_deg: 49.57, gravity_mps2: 9.8096 }
";

/// Imports `data` with `map` in a fresh folder: (exit code, output, folder entries after).
fn import(data: &str, map: &str) -> (i32, String, Vec<String>) {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("data.csv"), data).unwrap();
    std::fs::write(tmp.path().join("map.yaml"), map).unwrap();
    let o = ratecal(
        &["import", "data.csv", "--map", "map.yaml", "--out", "run"],
        tmp.path(),
    );
    let mut left: Vec<String> = std::fs::read_dir(tmp.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    left.sort();
    (code(&o), text(&o), left)
}

/// Refused with exit 1, nothing written, the message located and helped.
fn refused(data: &str, map: &str, located: &str, says: &[&str]) {
    let (c, out, left) = import(data, map);
    // miette wraps long lines: compare with the lines joined.
    let out = out
        .lines()
        .map(|l| l.trim_start().trim_start_matches('│').trim())
        .collect::<Vec<_>>()
        .join(" ");
    assert_eq!(c, 1, "{out}");
    assert_eq!(left, ["data.csv", "map.yaml"], "nothing written: {out}");
    assert!(out.contains(located), "located at {located}: {out}");
    assert!(out.contains("help:"), "{out}");
    for s in says {
        assert!(out.contains(s), "`{s}` in {out}");
    }
}

#[test]
fn a_good_session_imports_with_its_rate_segment() {
    let (c, out, left) = import(&session(|_, _| {}), MAP);
    assert_eq!(c, 0, "{out}");
    assert!(left.contains(&"run".to_string()), "{left:?}");
    // Raw offsets of a consumer IMU (0.5 g on one axis) are plausible.
    let (c, out, _) = import(&session(|_, r| r[1] += 0.5), MAP);
    assert_eq!(c, 0, "{out}");
}

#[test]
fn accelerometers_in_the_wrong_unit_are_refused_at_units_accel() {
    let m = MAP.replace("accel: g", "accel: m/s^2");
    refused(
        &session(|_, _| {}),
        &m,
        "map.yaml:5:19",
        &[
            "look like g, not m/s^2: set units.accel",
            "z_up",
            "data.csv lines 22-281",
        ],
    );
    let m = MAP.replace("accel: g", "accel: mg");
    refused(
        &session(|_, _| {}),
        &m,
        "map.yaml:5:19",
        &["look like g, not mg"],
    );
    let data = session(|_, r| {
        for v in &mut r[..3] {
            *v *= 9.80665;
        }
    });
    refused(&data, MAP, "map.yaml:5:19", &["look like m/s^2, not g"]);
}

#[test]
fn gyros_that_do_not_fit_their_unit_are_refused() {
    // Gyro columns in rad/s declared deg/s: the rate segment reads 1.75 for 100.
    let data = session(|_, r| {
        for v in &mut r[3..] {
            *v = v.to_radians();
        }
    });
    refused(
        &data,
        MAP,
        "map.yaml:9:5",
        &["look like rad/s, not deg/s", "turn"],
    );
    // Unsigned counts without their zero: a gyro at rest reading thousands.
    let data = session(|_, r| r[3] += 32768.0);
    refused(
        &data,
        MAP,
        "map.yaml:5:28",
        &["not a plausible bias", "zero.gyro"],
    );
}

#[test]
fn bad_cells_and_clocks_are_located_in_the_source() {
    let mut data = session(|_, _| {});
    data = data.replacen("0.3,-0.2", "0.3,abc", 1);
    refused(&data, MAP, "data.csv:2:", &["`abc` is not a number"]);
    let data = session(|i, r| {
        if i == 5 {
            r[2] = f64::NAN;
        }
    });
    refused(&data, MAP, "data.csv:7:", &["not a finite number"]);
    // A time column that goes backwards, and one that repeats.
    let timed = |bad: usize, dt: f64| {
        let mut s = String::from("t,ax,ay,az,gx,gy,gz\n");
        for i in 0..300 {
            let t = if i == bad {
                (i as f64 - dt) * 0.01
            } else {
                i as f64 * 0.01
            };
            s.push_str(&format!("{t},0,0,1,0,0,0\n"));
        }
        s
    };
    let map = "source: { format: csv }
imu:
  time: { column: t, unit: s }
  columns: { ax: ax, ay: ay, az: az, gx: gx, gy: gy, gz: gz }
  units: { accel: g, gyro: deg/s }
site: { latitude_deg: 49.57, gravity_mps2: 9.8096 }
";
    refused(
        &timed(100, 2.0),
        map,
        "data.csv:102:1",
        &["time goes backwards"],
    );
    refused(&timed(100, 1.0), map, "data.csv:102:1", &["time repeats"]);
    // Microseconds declared as milliseconds: 100 Hz becomes 0.1 Hz, refused after the
    // first 64 samples, at the 64th (issue 38).
    let us: String = timed(usize::MAX, 0.0)
        .lines()
        .enumerate()
        .map(|(i, l)| match i {
            0 => format!("{l}\n"),
            _ => format!("{}{}\n", (i - 1) * 10_000, &l[l.find(',').unwrap()..]),
        })
        .collect();
    let ms = map.replace("unit: s", "unit: ms");
    refused(
        &us,
        &ms,
        "data.csv:65:1",
        &["0.1000 Hz over the first 64 samples", "imu.time's unit"],
    );
}

#[test]
fn segments_outside_the_data_overlapping_or_contradicted_are_refused() {
    let m = MAP.replace("samples: [620, 880]", "samples: [620, 980]");
    refused(
        &session(|_, _| {}),
        &m,
        "map.yaml:9:",
        &["outside the data", "samples 0..900"],
    );
    let m = MAP.replace("samples: [320, 580]", "samples: [250, 580]");
    refused(
        &session(|_, _| {}),
        &m,
        "map.yaml:8:",
        &["overlapping or out of order"],
    );
    let m = MAP.replace("up: +x", "up: -y");
    refused(
        &session(|_, _| {}),
        &m,
        "map.yaml:8:",
        &["`up: -y` is", "gravity says +x is up"],
    );
}

#[test]
fn map_mistakes_are_located_in_the_map() {
    let m = MAP.replace("units: {", "unit: {");
    refused(&session(|_, _| {}), &m, "map.yaml:5:", &["unknown field"]);
    let m = MAP.replace("gyro: deg/s", "gyro: g");
    refused(
        &session(|_, _| {}),
        &m,
        "map.yaml:5:",
        &["is a unit of acceleration"],
    );
    // A header name that names two columns is not guessed at (issue 38).
    let data = session(|_, _| {}).replacen("gyr_z", "acc_y", 1);
    refused(
        &data,
        MAP,
        "map.yaml:4:",
        &[
            "column `acc_y` names 2 columns",
            "1, 5)",
            "index instead (e.g. `1`)",
        ],
    );
    // A row with a cell no header column names is refused at that cell (issue 38); a
    // trailing delimiter is not a cell.
    let mut lines: Vec<String> = session(|_, _| {}).lines().map(String::from).collect();
    lines[11].push_str(",7.5");
    refused(
        &(lines.join("\n") + "\n"),
        MAP,
        "data.csv:12:",
        &["this row has 7 cells; the header names 6 columns"],
    );
    let trailing: String = session(|_, _| {})
        .lines()
        .map(|l| format!("{l},\n"))
        .collect();
    assert_eq!(import(&trailing, MAP).0, 0);
    let m = MAP.replace("az: acc_z", "az: acc_zz");
    refused(
        &session(|_, _| {}),
        &m,
        "map.yaml:4:",
        &["no column `acc_zz`", "acc_z"],
    );
    // A nominal face says how well it is known; a turn's axis is a body axis.
    let m = MAP.replace("up: +z }", "up: +z, attitude: nominal }");
    refused(
        &session(|_, _| {}),
        &m,
        "map.yaml:7:",
        &[
            "`attitude: nominal` needs `tolerance_deg`",
            "tolerance_deg: 0.5",
        ],
    );
    let m = MAP.replace("up: +z }", "up: +z, attitude: feedback }");
    refused(
        &session(|_, _| {}),
        &m,
        "map.yaml:7:",
        &["without the table's feedback"],
    );
    let m = MAP.replace(
        "kind: rate, samples: [620, 880], axis: z, rate_dps: 100",
        "kind: turn, samples: [620, 880], axis: outer, angle_deg: 360",
    );
    refused(
        &session(|_, _| {}),
        &m,
        "map.yaml:9:",
        &["`outer` is not a body axis"],
    );
}

#[test]
fn turns_and_attitudes_are_written_to_the_manifest() {
    let m = MAP
        .replace(
            "up: +z }",
            "up: +z, attitude: nominal, tolerance_deg: 0.5 }",
        )
        .replace("up: +x }", "attitude: unknown }")
        .replace(
            "kind: rate, samples: [620, 880], axis: z, rate_dps: 100",
            "kind: turn, samples: [620, 880], axis: -z, angle_deg: -360",
        );
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("s.csv"), session(|_, _| {})).unwrap();
    std::fs::write(tmp.path().join("map.yaml"), m).unwrap();
    let o = ratecal(
        &["import", "s.csv", "--map", "map.yaml", "--out", "run"],
        tmp.path(),
    );
    assert_eq!(code(&o), 0, "{}", text(&o));
    let text = std::fs::read_to_string(tmp.path().join("run/manifest.yaml")).unwrap();
    let man: serde_json::Value = serde_saphyr::from_str(&text).unwrap();
    let s = &man["segments"];
    assert_eq!(s[0]["attitude"], "nominal");
    assert_eq!(s[0]["tolerance_deg"], 0.5);
    assert_eq!(s[1]["attitude"], "unknown");
    assert!(s[1]["up"].is_null(), "{text}");
    assert_eq!(s[2]["kind"], "turn");
    assert_eq!(s[2]["axis"], "-z");
    assert_eq!(s[2]["angle_deg"], -360.0);
    // No segment of a recording without a table is held by feedback.
    assert!(!text.contains("attitude: feedback"), "{text}");
}

/// A killed import's staging folder (`.OUT.import-PID`, its process gone) is removed by the
/// next import into OUT; a live process's, and another output's, are left (issue 38).
#[test]
fn a_killed_imports_staging_folder_is_removed_by_the_next() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("data.csv"), session(|_, _| {})).unwrap();
    std::fs::write(tmp.path().join("map.yaml"), MAP).unwrap();
    // Above the kernel's largest pid: never a running process.
    let dead = tmp.path().join(".run.import-4294967");
    let live = tmp.path().join(".run.import-1");
    let other = tmp.path().join(".other.import-4294967");
    for d in [&dead, &live, &other] {
        std::fs::create_dir_all(d).unwrap();
        std::fs::write(d.join("imu.csv"), "t,ax\n").unwrap();
    }
    let o = ratecal(
        &["import", "data.csv", "--map", "map.yaml", "--out", "run"],
        tmp.path(),
    );
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert!(!dead.exists(), "the dead import's staging folder is gone");
    assert!(live.exists() && other.exists());
}
