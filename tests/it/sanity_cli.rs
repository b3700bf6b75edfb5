//! Sanity checks and the one verdict, end to end: recordings that are wrong in ways a new
//! user makes them (accelerometers in g, gyros in rad/s, a sign-flipped gyro axis, a mount
//! that is not the manifest's, time going backwards, two clocks) are refused or not passed,
//! with the failing check named; the shared examples and a dry run pass every check; a run or
//! analysis with nothing to judge is `not_judged` (exit 0, never PASS); the terminal, the
//! results and the report give the same warnings.
//!
//! Each broken recording is a dry run of MINI (two attitudes, one rate point about the
//! outer axis, sensed by the Y gyro) with one thing changed, so that only that thing can
//! make it fail.

use crate::support;
use support::*;

use serde_json::Value;
use std::path::Path;

/// A copy of the run folder `src` as `dst` with each IMU row's cells (`t, ax, ay, az, gx,
/// gy, gz, ...`) passed through `f`, and the manifest passed through `m`.
fn altered(src: &Path, dst: &Path, f: impl Fn(&mut [f64]), m: impl Fn(String) -> String) {
    std::fs::create_dir_all(dst).unwrap();
    std::fs::copy(src.join("table.csv"), dst.join("table.csv")).unwrap();
    let manifest = std::fs::read_to_string(src.join("manifest.yaml")).unwrap();
    std::fs::write(dst.join("manifest.yaml"), m(manifest)).unwrap();
    let imu = std::fs::read_to_string(src.join("imu.csv")).unwrap();
    let mut lines = imu.lines();
    let mut out = format!("{}\n", lines.next().unwrap());
    for line in lines {
        let mut row: Vec<f64> = line.split(',').map(|c| c.parse().unwrap()).collect();
        f(&mut row);
        let cells: Vec<String> = row.iter().map(|x| x.to_string()).collect();
        out += &cells.join(",");
        out.push('\n');
    }
    std::fs::write(dst.join("imu.csv"), out).unwrap();
}

/// A dry run of MINI in `dir/r` (exit 0: it has no acceptance check).
fn mini(dir: &Path) -> std::path::PathBuf {
    let o = mini_run(dir, "r", &[]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    dir.join("r")
}

/// `ratecal analyze DIR` (no procedure): exit code, results.json, standard error.
fn analyze(dir: &Path, cwd: &Path, extra: &[&str]) -> (i32, Value, String) {
    let mut args = vec!["analyze", dir.to_str().unwrap()];
    args.extend_from_slice(extra);
    let o = ratecal(&args, cwd);
    let v = serde_json::from_slice(&o.stdout).unwrap_or(Value::Null);
    (code(&o), v, String::from_utf8_lossy(&o.stderr).into_owned())
}

/// The sanity entry named `check`.
fn entry<'a>(results: &'a Value, check: &str) -> &'a Value {
    results["sanity"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["check"] == check)
        .unwrap_or_else(|| panic!("no sanity entry {check} in {}", results["sanity"]))
}

/// Not a pass, with `check` at `fail` and named by the verdict's reason and the terminal.
fn not_fit(code: i32, v: &Value, err: &str, check: &str) {
    assert_eq!(code, 3, "{err}");
    assert_eq!(v["verdict"], "incomplete", "{err}");
    assert_eq!(entry(v, check)["status"], "fail", "{}", v["sanity"]);
    let reason = v["verdict_reason"].as_str().unwrap();
    assert!(
        reason.contains("not fit for judgment") && reason.contains(check),
        "{reason}"
    );
    assert!(err.contains(&format!("[FAIL] {check}:")), "{err}");
    assert!(
        err.contains("verdict: INCOMPLETE (the recording is not fit"),
        "{err}"
    );
}

const NAMES: [&str; 8] = [
    "time_increasing",
    "clocks_overlap",
    "sampling",
    "gravity_magnitude_at_rest",
    "gravity_direction_at_rest",
    "gyro_at_rest",
    "gyro_follows_table",
    "fitted_values_plausible",
];

/// Every check listed once, in order, none failing.
fn no_check_fails(v: &Value, what: &str) {
    let s = v["sanity"].as_array().unwrap();
    let names: Vec<&str> = s.iter().map(|c| c["check"].as_str().unwrap()).collect();
    assert_eq!(names, NAMES, "{what}");
    for c in s {
        assert_ne!(c["status"], "fail", "{what}: {c}");
    }
}

#[test]
fn accelerometers_in_g_are_not_fit_for_judgment() {
    let tmp = tempfile::tempdir().unwrap();
    let run = mini(tmp.path());
    let g = tmp.path().join("g");
    altered(
        &run,
        &g,
        |r| r[1..4].iter_mut().for_each(|a| *a /= 9.80665),
        |m| m,
    );
    let (c, v, err) = analyze(&g, tmp.path(), &[]);
    not_fit(c, &v, &err, "gravity_magnitude_at_rest");
    // The fit itself turns the units error into a scale factor of about -90 %.
    assert_eq!(entry(&v, "fitted_values_plausible")["status"], "fail");
    let scale = v["parameters"]["accel.scale.z"]["value"].as_f64().unwrap();
    assert!(scale < -800_000.0, "{scale}");
}

/// The issue's own case: the real consumer session with its accelerometer columns in g,
/// analysed with the consumer procedure, was a PASS at -896,800 ppm.
#[test]
fn the_real_session_in_g_is_not_passed() {
    let Some(ex) = support::shared_example("real-ferraris-session") else {
        return;
    };
    let tmp = tempfile::tempdir().unwrap();
    let g = tmp.path().join("g");
    altered(
        &ex,
        &g,
        |r| r[1..4].iter_mut().for_each(|a| *a /= 9.80665),
        |m| m,
    );
    let consumer = procedures("imu-2d-consumer");
    let (c, v, err) = analyze(&g, tmp.path(), &["--procedure", &consumer]);
    not_fit(c, &v, &err, "gravity_magnitude_at_rest");
    assert!(!err.contains("verdict: PASS"), "{err}");
}

#[test]
fn gyros_in_rad_per_s_are_not_fit_for_judgment() {
    let tmp = tempfile::tempdir().unwrap();
    let run = mini(tmp.path());
    let rad = tmp.path().join("rad");
    altered(
        &run,
        &rad,
        |r| r[4..7].iter_mut().for_each(|w| *w = w.to_radians()),
        |m| m,
    );
    let (c, v, err) = analyze(&rad, tmp.path(), &[]);
    not_fit(c, &v, &err, "gyro_follows_table");
    // The rotating axis's gain on its reference is pi/180.
    let detail = entry(&v, "gyro_follows_table")["detail"].as_str().unwrap();
    assert!(detail.contains("gy 0.017"), "{detail}");
    // At rest a gyro in rad/s is only quieter: that check still passes.
    assert_eq!(entry(&v, "gyro_at_rest")["status"], "pass");
}

#[test]
fn a_sign_flipped_gyro_axis_is_not_fit_for_judgment() {
    let tmp = tempfile::tempdir().unwrap();
    let run = mini(tmp.path());
    let flipped = tmp.path().join("flipped");
    altered(&run, &flipped, |r| r[5] = -r[5], |m| m);
    let (c, v, err) = analyze(&flipped, tmp.path(), &[]);
    not_fit(c, &v, &err, "gyro_follows_table");
    let detail = entry(&v, "gyro_follows_table")["detail"].as_str().unwrap();
    assert!(detail.contains("gy -1.0"), "{detail}");
    // The accelerometers are untouched.
    assert_eq!(entry(&v, "gravity_direction_at_rest")["status"], "pass");
}

/// The manifest says the IMU is turned 90 deg about Z on the platform; it is not.
#[test]
fn a_mount_that_is_not_the_manifests_is_not_fit_for_judgment() {
    let tmp = tempfile::tempdir().unwrap();
    let run = mini(tmp.path());
    let mount = tmp.path().join("mount");
    altered(
        &run,
        &mount,
        |_| {},
        |m| {
            // The run's manifest holds the identity mount: its block is replaced.
            let at = m.find("\n  mount:\n").expect("a mount block") + 1;
            let len = m[at..]
                .lines()
                .skip(1)
                .take_while(|l| l.starts_with("    "))
                .map(|l| l.len() + 1)
                .sum::<usize>()
                + "  mount:\n".len();
            let turned = "  mount:\n    rotation: [[0, -1, 0], [1, 0, 0], [0, 0, 1]]\n";
            format!("{}{turned}{}", &m[..at], &m[at + len..])
        },
    );
    let manifest = std::fs::read_to_string(mount.join("manifest.yaml")).unwrap();
    let (c, v, err) = analyze(&mount, tmp.path(), &[]);
    not_fit(c, &v, &err, "gyro_follows_table");
    assert_eq!(
        entry(&v, "gravity_direction_at_rest")["status"],
        "fail",
        "{manifest}"
    );
}

#[test]
fn time_going_backwards_is_refused_with_a_located_diagnostic() {
    let tmp = tempfile::tempdir().unwrap();
    let run = mini(tmp.path());
    let back = tmp.path().join("back");
    altered(&run, &back, |_| {}, |m| m);
    let imu = std::fs::read_to_string(back.join("imu.csv")).unwrap();
    let mut lines: Vec<&str> = imu.lines().collect();
    lines.swap(100, 101);
    std::fs::write(back.join("imu.csv"), lines.join("\n") + "\n").unwrap();
    let (c, v, err) = analyze(&back, tmp.path(), &[]);
    assert_eq!(c, 1, "{err}");
    assert!(v.is_null(), "no results on standard output");
    assert!(err.contains("sanity::time_increasing"), "{err}");
    assert!(err.contains("imu.csv:102:1"), "{err}");
    assert!(err.contains("help:"), "{err}");
}

#[test]
fn clocks_without_overlap_are_refused_with_a_located_diagnostic() {
    let tmp = tempfile::tempdir().unwrap();
    let run = mini(tmp.path());
    let shifted = tmp.path().join("shifted");
    altered(&run, &shifted, |r| r[0] += 1.0e6, |m| m);
    let (c, _, err) = analyze(&shifted, tmp.path(), &[]);
    assert_eq!(c, 1, "{err}");
    assert!(err.contains("sanity::clocks_overlap"), "{err}");
    assert!(err.contains("table.csv:2:1"), "{err}");
    assert!(err.contains("help:"), "{err}");
}

/// Recordings from another implementation of the spec (tactical, simulated) and a real
/// consumer IMU on a hand-held "table" pass every check that applies to them.
#[test]
fn the_shared_examples_pass_every_check() {
    let tmp = tempfile::tempdir().unwrap();
    for name in [
        "standard-with-lever-arm",
        "open-null",
        "open-gyro-g2",
        "open-accel-bias-step",
        "real-ferraris-session",
        "sway-independent",
    ] {
        let Some(ex) = support::shared_example(name) else {
            continue;
        };
        let (c, v, err) = analyze(&ex, tmp.path(), &[]);
        assert_eq!(c, 0, "{name}: {err}");
        no_check_fails(&v, name);
        // Nothing about them is out of the ordinary: the stamps are regular.
        let sampling = entry(&v, "sampling")["detail"].as_str().unwrap();
        assert!(sampling.contains("imu.csv nominal"), "{name}: {sampling}");
        assert!(!err.contains("[FAIL]"), "{name}: {err}");
    }
}

/// No procedure, nothing to judge: `not_judged`, exit 0, said why, never PASS; a dry run
/// passes every sanity check.
#[test]
fn analyze_without_a_procedure_is_not_judged() {
    let tmp = tempfile::tempdir().unwrap();
    let run = mini(tmp.path());
    let results = json(&run.join("results.json"));
    no_check_fails(&results, "dry run");
    assert!(
        results["sanity"]
            .as_array()
            .unwrap()
            .iter()
            .all(|c| c["status"] == "pass"),
        "{}",
        results["sanity"]
    );
    let (c, v, err) = analyze(&run, tmp.path(), &[]);
    assert_eq!(c, 0, "{err}");
    assert_eq!(v["verdict"], "not_judged");
    assert!(
        v["verdict_reason"]
            .as_str()
            .unwrap()
            .contains("without a procedure")
    );
    assert!(
        err.contains("verdict: NOT JUDGED (analysed without a procedure"),
        "{err}"
    );
    assert!(!err.contains("PASS"), "{err}");
}

/// station-check declares no acceptance check: its run is `not_judged` (exit 0) in the
/// terminal, results.json and both reports, which say what the run was for.
#[test]
fn a_station_check_run_is_not_judged() {
    let tmp = tempfile::tempdir().unwrap();
    let sc = procedures("station-check");
    let o = ratecal(&["run", &sc, "--dry-run", "--out", "sc"], tmp.path());
    assert_eq!(code(&o), 0, "{}", text(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        out.contains(
            "verdict: NOT JUDGED (procedure station-check 1.0.0 declares no acceptance check"
        ),
        "{out}"
    );
    assert!(!out.contains("PASS"), "{out}");
    let dir = tmp.path().join("sc");
    let results = json(&dir.join("results.json"));
    assert_eq!(results["verdict"], "not_judged");
    no_check_fails(&results, "station-check");
    let md = std::fs::read_to_string(dir.join("report.md")).unwrap();
    assert!(md.contains("Overall verdict: **NOT JUDGED**"), "{md}");
    assert!(
        md.contains("The run was for: Station check: links, feedback and motion."),
        "{md}"
    );
    let html = std::fs::read_to_string(dir.join("report.html")).unwrap();
    for (name, text) in [("report.md", &md), ("report.html", &html)] {
        assert!(!text.contains("PASS"), "{name} renders a PASS");
        assert!(!text.contains("meet the standard"), "{name}");
    }
}

/// One count of warnings: the run's terminal summary, results.json and both reports list
/// the same ones (a journal warning of the run among them); no "No findings." is printed
/// beside them.
#[test]
fn the_terminal_results_and_report_agree_on_the_warnings() {
    let tmp = tempfile::tempdir().unwrap();
    let o = mini_too_fast_run(tmp.path(), "r");
    assert_eq!(code(&o), 0, "{}", text(&o));
    let dir = tmp.path().join("r");
    let warnings: Vec<String> = json(&dir.join("results.json"))["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| w.as_str().unwrap().to_string())
        .collect();
    assert!(!warnings.is_empty());
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        out.contains(&format!("\nwarnings: {}\n", warnings.len())),
        "{out}"
    );
    let listed = out.lines().filter(|l| l.starts_with("  warning: ")).count();
    assert_eq!(listed, warnings.len(), "{out}");
    let md = std::fs::read_to_string(dir.join("report.md")).unwrap();
    let section = md.split("### Warnings").nth(1).expect("a Warnings section");
    let section = section.split("\n## ").next().unwrap();
    let items = section.lines().filter(|l| l.starts_with("- ")).count();
    assert_eq!(items, warnings.len(), "{section}");
    let html = std::fs::read_to_string(dir.join("report.html")).unwrap();
    let list = html.split("<ul class=\"warnings\">").nth(1).unwrap();
    let list = list.split("</ul>").next().unwrap();
    assert_eq!(list.matches("<li>").count(), warnings.len(), "{list}");
    for w in &warnings {
        assert!(out.contains(w.as_str()) && md.contains(w.as_str()), "{w}");
    }
    assert!(!html.contains("No findings."), "{html}");
}
