//! `ratecal explain` on a run folder, as the README's worked example does it: the lever
//! arm found, its parameters printed as a lab writes them, one before/after figure per
//! finding beside explain.json (sealed with it) and in `--plots DIR`, and in the report.

use crate::support;
use support::{code, json, procedures, ratecal, text};

/// `name = value ± u unit` from explain's text: value and u as written.
fn param<'a>(out: &'a str, name: &str) -> (&'a str, &'a str) {
    let key = format!(" {name} = ");
    let rest = out
        .lines()
        .find_map(|l| l.split_once(&key).map(|(_, rest)| rest))
        .unwrap_or_else(|| panic!("no {name} in\n{out}"));
    let (value, rest) = rest.split_once(" ± ").unwrap();
    (value, rest.split(' ').next().unwrap())
}

fn decimals(s: &str) -> usize {
    s.split_once('.').map_or(0, |(_, f)| f.len())
}

#[test]
fn explain_finds_the_lever_arm_and_draws_it_before_and_after() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let station = format!(
        "{}/drivers/stations/with-lever-arm.yaml",
        env!("CARGO_MANIFEST_DIR")
    );
    let std = procedures("imu-2d-standard");
    let o = ratecal(
        &[
            "run",
            &std,
            "--dry-run",
            "--station",
            &station,
            "--out",
            "lever",
        ],
        dir,
    );
    assert_eq!(code(&o), 0, "{}", text(&o));
    // Acceptance values with their expanded uncertainty, U to two significant digits.
    let run_out = String::from_utf8_lossy(&o.stdout);
    assert!(run_out.contains("acceptance (value ± expanded uncertainty U, k as stated):"));
    let (v, u) = param(&run_out, "gyro.residual.std");
    assert!(
        v.starts_with("0.00") && u.starts_with("0.0000"),
        "{run_out}"
    );
    assert_eq!(decimals(v), decimals(u), "{run_out}");
    // Every conformity line states its k as a certificate does (`k = 2`), and a reading
    // without U says so at four digits, with no k for a U that is not there.
    let drift = (run_out.lines())
        .find(|l| l.contains("environment.temperature_drift ="))
        .unwrap_or_else(|| panic!("{run_out}"));
    assert!(
        drift.contains("= 0.02 degC/h (limit <= 0.5 degC/h, U not stated)"),
        "{drift}"
    );
    assert!(!drift.contains("k ="), "{drift}");
    let residual = (run_out.lines())
        .find(|l| l.contains("gyro.residual.std ="))
        .unwrap();
    assert!(residual.contains(", k = 2)"), "{residual}");
    // A check made at several points names the point and its segment.
    let point = (run_out.lines())
        .find(|l| l.contains("gyro.error ="))
        .unwrap_or_else(|| panic!("{run_out}"));
    assert!(
        point.contains("): at 75 deg/s about the outer axis, segment verify/outer/+75"),
        "{point}"
    );

    let o = ratecal(&["explain", "lever", "--plots", "figs"], dir);
    assert_eq!(code(&o), 1, "{}", text(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    // The station holds rzz = 25 mm; u to two significant digits, the value at its place.
    let (v, u) = param(&out, "rzz_mm");
    let (value, unc): (f64, f64) = (v.parse().unwrap(), u.parse().unwrap());
    assert!((value - 25.0).abs() < 0.05, "{out}");
    assert_eq!(u.trim_start_matches(['0', '.']).len(), 2, "{out}");
    assert_eq!(decimals(v), decimals(u), "{out}");
    assert!(unc > 0.0 && unc < 0.05, "{out}");

    let x = json(&dir.join("lever/explain.json"));
    let findings = x["findings"].as_array().unwrap();
    // The Earth's rate, held at the site's latitude, is taken first when significant.
    let lever = findings
        .iter()
        .find(|f| f["effect"] == "lever_arm")
        .expect("lever_arm found");
    // Every segment and channel: 23 segments of the standard, 6 channels.
    let rows = lever["residuals"].as_array().unwrap();
    assert_eq!(rows.len(), 23 * 6);
    for f in findings {
        let name = format!("explain-{}.svg", f["effect"].as_str().unwrap());
        let beside = std::fs::read_to_string(dir.join("lever").join(&name)).unwrap();
        let asked = std::fs::read_to_string(dir.join("figs").join(&name)).unwrap();
        assert_eq!(beside, asked, "{name}");
        assert!(
            text(&o).contains(&format!("figure: figs/{name}")),
            "{}",
            text(&o)
        );
    }
    let svg = std::fs::read_to_string(dir.join("figs/explain-lever_arm.svg")).unwrap();
    assert!(svg.starts_with("<svg xmlns=\"http://www.w3.org/2000/svg\""));
    for ch in ["ax", "ay", "az"] {
        assert!(svg.contains(&format!("lever_arm: {ch} residual RMS per segment")));
    }
    assert!(
        !svg.contains("lever_arm: gx"),
        "the gyros are not where it shows"
    );
    assert!(svg.contains("data-name=\"after, held out\""));

    // explain.json and the figures joined the seal in one addition.
    let seal = json(&dir.join("lever/seal.json"));
    let added = seal["added"].as_array().unwrap();
    let files = &added.last().unwrap()["files"];
    assert!(files.get("explain.json").is_some(), "{seal}");
    assert!(files.get("explain-lever_arm.svg").is_some(), "{seal}");
    let o = ratecal(&["verify", "lever"], dir);
    assert_eq!(code(&o), 0, "{}", text(&o));

    // The report of the folder shows the figure in its explain section.
    let o = ratecal(
        &["report", "lever", "--format", "html", "--out", "r.html"],
        dir,
    );
    assert_eq!(code(&o), 0, "{}", text(&o));
    let html = std::fs::read_to_string(dir.join("r.html")).unwrap();
    assert!(html.contains("Residuals before and after: lever_arm"));
}
