//! `ratecal explain RUN RUN...` on fleets written by `ratecal-witness` (a second,
//! independent implementation of the spec): physics shared by every unit but too weak for
//! any one recording is found in the pool, physics of one unit is `unit`, a warm-up after
//! some power-ons is `occasional`, a unit far off the fleet is an outlier, and a fleet with
//! nothing shared pools nothing.

use crate::support;
use ratecal_witness::{Hidden, Scenario, write};
use serde_json::Value;
use std::path::{Path, PathBuf};
use support::{code, ratecal, text};

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// The fleet's shared K2 on every axis, ug/g^2: under two standard uncertainties of one
/// short recording (explain's threshold is above four).
const K2: f64 = 16.0;

/// A short standard-shaped recording of unit `serial` ([`Scenario::fleet_unit`]).
fn unit(serial: &str, n: u64, seed: u64) -> Scenario {
    Scenario::fleet_unit(serial, n, seed, 60.0)
}

fn k2(k: f64) -> Hidden {
    Hidden::AccelSecondOrder {
        k2_ug_per_g2: [k, k, k],
    }
}

/// Writes each scenario into its own folder under `dir`; the folders.
fn write_all(dir: &Path, fleet: Vec<Scenario>) -> Vec<PathBuf> {
    fleet
        .into_iter()
        .enumerate()
        .map(|(i, s)| {
            let p = dir.join(format!("{i:02}-{}", s.name));
            write(&p, &s).unwrap();
            p
        })
        .collect()
}

/// `explain RUN... --format json [EXTRA...]`: exit code and the JSON.
fn explain(runs: &[PathBuf], extra: &[&str]) -> (i32, Value) {
    let mut args = vec!["explain".to_string()];
    args.extend(runs.iter().map(|p| p.display().to_string()));
    args.extend(["--format".into(), "json".into()]);
    args.extend(extra.iter().map(|a| a.to_string()));
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let o = ratecal(&args, Path::new(ROOT));
    let v = serde_json::from_slice(&o.stdout).unwrap_or_else(|e| panic!("{e}: {}", text(&o)));
    (code(&o), v)
}

fn entries<'a>(v: &'a Value, effect: &str) -> Vec<&'a Value> {
    v["across"]["effects"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|e| e["effect"] == effect)
        .collect()
}

fn f(v: &Value, k: &str) -> f64 {
    v[k].as_f64().unwrap_or_else(|| panic!("{k} in {v}"))
}

#[test]
fn the_pool_finds_a_weak_shared_k2_a_units_lever_arm_a_warm_up_and_an_outlier() {
    let tmp = tempfile::tempdir().unwrap();
    let mut fleet: Vec<Scenario> = (1..=8)
        .map(|n| unit(&format!("SN{n:03}"), n, 100 + n).with(k2(K2)))
        .collect();
    // One unit recorded three times, each time with the same lever arm.
    let lever = [[30.0, 0.0, 0.0], [30.0, 0.0, 0.0], [30.0, 0.0, 0.0]];
    for seed in [201, 202, 203] {
        fleet.push(
            unit("SN100", 100, seed)
                .with(k2(K2))
                .with(Hidden::LeverArm { r_mm: lever }),
        );
    }
    // One unit whose K2 is five times the fleet's.
    fleet.push(unit("SN200", 200, 300).with(k2(5.0 * K2)));
    // One unit recorded three times, twice right after power-on (a gyro warm-up).
    for (seed, warm) in [(401, true), (402, true), (403, false)] {
        let s = unit("SN300", 300, seed).with(k2(K2));
        fleet.push(match warm {
            true => s.with(Hidden::GyroWarmUp {
                amplitude_dps: [0.03, -0.02, 0.025],
                tau_s: 100.0,
            }),
            false => s,
        });
    }
    let runs = write_all(tmp.path(), fleet);
    // The model's twin and the forest plots are written by the same query.
    let (plots, twin) = (tmp.path().join("plots"), tmp.path().join("model-twin.yaml"));
    let extra = [
        "--plots",
        plots.to_str().unwrap(),
        "--twin",
        STATION,
        "--write-twin",
        twin.to_str().unwrap(),
    ];
    let (c, v) = explain(&runs, &extra);
    assert_eq!(c, 1, "a recording or the pool has a finding");
    model_twin_holds_the_pooled_k2(&v, &twin);
    forest_plots_name_every_recording(&v, &plots.join("explain-across.html"));
    let a = &v["across"];
    assert_eq!(a["recordings"].as_array().unwrap().len(), 15);
    // Hardly any recording of the fleet finds K2 alone (else this would not test pooling).
    let found_k2 = |r: &Value| {
        r["findings"]
            .as_array()
            .unwrap()
            .iter()
            .any(|f| f == "accel_second_order")
    };
    let recs = a["recordings"].as_array().unwrap();
    let alone = (recs.iter())
        .filter(|r| r["serial"] != "SN200" && found_k2(r))
        .count();
    println!("K2 found alone in {alone} of 14 recordings");
    assert!(alone <= 2, "{a:#}");
    // The pooled K2: within 3u of the truth on every axis, `pooled_only` or `model`, the
    // five-fold unit left out.
    let k2s = entries(&v, "accel_second_order");
    assert_eq!(k2s.len(), 3, "{a:#}");
    for e in &k2s {
        let (x, u) = (f(e, "pooled"), f(e, "u"));
        println!("K2 {}: {x:.2} ± {u:.2} ({})", e["parameter"], e["verdict"]);
        assert!((x - K2).abs() < 3.0 * u, "{e:#}");
        assert!(u < K2 / 3.0, "the pool determines it: {e:#}");
        assert!(
            e["verdict"] == "pooled_only" || e["verdict"] == "model",
            "{e:#}"
        );
        let left: Vec<&str> = e["left_out"]
            .as_array()
            .unwrap()
            .iter()
            .map(|r| r.as_str().unwrap())
            .collect();
        assert_eq!(left.len(), 1, "{e:#}");
        assert!(left[0].ends_with("-SN200"), "{left:?}");
        assert_eq!(e["per_recording"].as_array().unwrap().len(), 15);
    }
    // The five-fold unit is among the outliers, on K2.
    let outliers = a["outliers"].as_array().unwrap();
    assert!(
        outliers
            .iter()
            .any(|o| o["serial"] == "SN200" && o["effect"] == "accel_second_order"),
        "{outliers:#?}"
    );
    // The lever arm is the unit's: its x coordinates, in every recording of SN100 and no
    // other serial.
    let lever = entries(&v, "lever_arm");
    let rxx = lever
        .iter()
        .find(|e| e["parameter"] == "rxx_mm")
        .unwrap_or_else(|| panic!("{a:#}"));
    assert_eq!(rxx["verdict"], "unit", "{rxx:#}");
    assert!(
        lever
            .iter()
            .all(|e| e["verdict"] != "model" && e["verdict"] != "pooled_only"),
        "{lever:#?}"
    );
    // The warm-up is occasional: some recordings of one unit, not all.
    let decay = entries(&v, "form_gyro_decay");
    assert!(!decay.is_empty(), "{a:#}");
    assert!(
        decay.iter().any(|e| e["verdict"] == "occasional"),
        "{decay:#?}"
    );
    assert!(
        decay
            .iter()
            .all(|e| e["verdict"] == "occasional" || e["verdict"] == "none"),
        "{decay:#?}"
    );
    // The text output leads with what recurs.
    let mut args = vec!["explain".to_string()];
    args.extend(runs.iter().map(|p| p.display().to_string()));
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let o = ratecal(&args, Path::new(ROOT));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        out.starts_with("Across 15 recordings of 11 units:"),
        "{out}"
    );
    let k2_at = out
        .find("accel_second_order.")
        .unwrap_or_else(|| panic!("{out}"));
    assert!(k2_at < out.find("Each recording:").unwrap(), "{out}");
}

/// The station file the model's twin is written into.
const STATION: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/drivers/stations/default.yaml");

/// The model's twin written by the query: the pooled K2 (not the five-fold unit's) within
/// 3u of the truth, u the pooled u with the spread; a station file `check` runs on.
fn model_twin_holds_the_pooled_k2(v: &Value, path: &Path) {
    let t = &v["twin"];
    assert_eq!(t["written"], path.display().to_string(), "{t:#}");
    assert_eq!(t["model"], "ratecal-witness", "{t:#}");
    let yaml = std::fs::read_to_string(path).unwrap();
    assert!(
        yaml.starts_with("# The twin of model ratecal-witness"),
        "{yaml}"
    );
    let st = ratecal_drivers::station::Station::from_yaml(&yaml, "model-twin.yaml")
        .unwrap_or_else(|e| panic!("{e:?}\n{yaml}"));
    let k2 = ratecal_physics::effect("accel_second_order").unwrap();
    let written = st.imu.effects.values(k2);
    for (axis, k) in ["x", "y", "z"].iter().enumerate() {
        let e = entries(v, "accel_second_order")
            .into_iter()
            .find(|e| e["parameter"] == *k)
            .unwrap_or_else(|| panic!("{v:#}"));
        let change = (t["changes"].as_array().unwrap().iter())
            .find(|c| c["effect"] == "accel_second_order" && c["parameter"] == *k)
            .unwrap_or_else(|| panic!("{t:#}"));
        let (w, u) = (written[axis], f(change, "u"));
        println!("model twin K2 {k}: {w} ± {u} (pooled {})", f(e, "pooled"));
        // The uncertainty written is the pooled u with the spread between units.
        assert!(
            (u - f(e, "u").hypot(f(e, "spread"))).abs() < 1e-9,
            "{change:#}"
        );
        // The value is the pool's (to the rounding of two digits of u) ...
        assert!((w - f(e, "pooled")).abs() <= 0.05 * u, "{w} {e:#}");
        // ... within 3u of the truth, far from the five-fold unit's.
        assert!((w - K2).abs() < 3.0 * u, "{w} ± {u}");
        assert!(w < 2.5 * K2, "{w}");
    }
    // Only what the fleet shares: not the lever arm of one unit (the station has none).
    assert!(!yaml.contains("lever_arm"), "{yaml}");
    let o = ratecal(
        &[
            "check",
            "procedures/imu-2d-standard",
            "--station",
            path.to_str().unwrap(),
        ],
        Path::new(ROOT),
    );
    assert_eq!(code(&o), 0, "{}", text(&o));
}

/// The forest plots' page: a plot per pooled entry, every recording named by run and
/// serial in each, the pooled K2 written.
fn forest_plots_name_every_recording(v: &Value, page: &Path) {
    let html = std::fs::read_to_string(page).unwrap_or_else(|e| panic!("{}: {e}", page.display()));
    let effects = v["across"]["effects"].as_array().unwrap();
    assert_eq!(html.matches("<svg").count(), effects.len());
    for e in effects {
        let id = format!(
            "<section id=\"{}.{}\">",
            e["effect"].as_str().unwrap(),
            e["parameter"].as_str().unwrap()
        );
        let section = html
            .split(&id)
            .nth(1)
            .unwrap_or_else(|| panic!("{id}"))
            .split("</section>")
            .next()
            .unwrap();
        for r in e["per_recording"].as_array().unwrap() {
            let (run, sn) = (r["run"].as_str().unwrap(), r["serial"].as_str().unwrap());
            assert!(
                section.contains(&format!("data-run=\"{run}\" data-serial=\"{sn}\"")),
                "{id}: {run}"
            );
        }
        if e["effect"] == "accel_second_order" {
            // The five-fold unit: an outlier, left out.
            assert!(section.contains("outlier (left out)"), "{section}");
            let u = f(e, "u");
            let d = (1 - u.log10().floor() as i32).max(0) as usize;
            let pooled = format!("{:.d$} ± {u:.d$}", f(e, "pooled"));
            assert!(section.contains(&pooled), "{pooled}: {section}");
        }
    }
}

#[test]
fn a_fleet_with_nothing_shared_pools_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let fleet: Vec<Scenario> = (1..=8)
        .map(|n| unit(&format!("NULL{n:02}"), n, 500 + n))
        .collect();
    let runs = write_all(tmp.path(), fleet);
    let (c, v) = explain(&runs, &[]);
    assert!(c == 0 || c == 1, "{v:#}");
    let a = &v["across"];
    let pooled: Vec<&Value> = a["effects"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|e| e["verdict"] == "model" || e["verdict"] == "pooled_only")
        .filter(|e| e["effect"] != "earth_rate")
        .collect();
    assert!(pooled.is_empty(), "nothing shared, yet pooled: {pooled:#?}");
    // Every pooled parameter is listed with its recordings: what is in `effects` has one
    // value per recording that determines it.
    for e in a["effects"].as_array().unwrap() {
        assert!(!e["per_recording"].as_array().unwrap().is_empty(), "{e:#}");
    }
}

#[test]
fn err_one_recording_options_with_several_are_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let runs = write_all(tmp.path(), vec![unit("A", 1, 1), unit("B", 2, 2)]);
    let (a, b) = (runs[0].to_str().unwrap(), runs[1].to_str().unwrap());
    let dir = tmp.path().to_str().unwrap();
    refused(
        &["explain", a, b, "--draft-effects", dir],
        "explain::one_recording_only",
    );
    refused(
        &["explain", a, b, "--twin", STATION],
        "explain::one_recording_only",
    );
    let missing = tmp.path().join("nothing-here");
    let o = ratecal(&["explain", a, missing.to_str().unwrap()], Path::new(ROOT));
    assert_eq!(code(&o), 2, "{}", text(&o));
}

/// The command exits 2 (an error, docs/explain.md) with the diagnostic `code` and its help
/// line, and writes no model's twin.
fn refused(args: &[&str], diagnostic: &str) {
    let o = ratecal(args, Path::new(ROOT));
    assert_eq!(code(&o), 2, "{args:?}: {}", text(&o));
    assert!(text(&o).contains(diagnostic), "{args:?}: {}", text(&o));
    assert!(text(&o).contains("help:"), "{args:?}: {}", text(&o));
    if let Some(i) = args.iter().position(|a| *a == "--write-twin") {
        let out = Path::new(args[i + 1]);
        assert!(!out.exists() || out.ends_with("manifest.yaml"), "{args:?}");
    }
}

#[test]
fn err_a_models_twin_of_a_serial_of_several_models_or_without_a_station_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let runs = write_all(tmp.path(), vec![unit("A", 1, 1), unit("B", 2, 2)]);
    let (a, b) = (runs[0].to_str().unwrap(), runs[1].to_str().unwrap());
    let out = tmp.path().join("twin.yaml");
    let out = out.to_str().unwrap();
    let archive = tmp.path().join("archive");
    let archive = archive.to_str().unwrap();
    // One unit's history is no model's.
    refused(
        &[
            "explain",
            "--archive",
            archive,
            "--serial",
            "A",
            "--twin",
            STATION,
            "--write-twin",
            out,
        ],
        "explain::model_twin_of_a_serial",
    );
    // No station file to write into: refused with one recording and with several.
    refused(
        &["explain", a, b, "--write-twin", out],
        "explain::write_twin_needs_twin",
    );
    refused(
        &["explain", a, "--write-twin", out],
        "explain::write_twin_needs_twin",
    );
    // The output may not replace a run's input.
    let manifest = runs[0].join("manifest.yaml");
    let before = std::fs::read(&manifest).unwrap();
    refused(
        &[
            "explain",
            a,
            b,
            "--twin",
            STATION,
            "--write-twin",
            manifest.to_str().unwrap(),
        ],
        "run_folder::output_is_input",
    );
    assert_eq!(std::fs::read(&manifest).unwrap(), before);
    // Recordings of two models.
    let text_b = std::fs::read_to_string(runs[1].join("manifest.yaml")).unwrap();
    let other = text_b.replace("model: \"ratecal-witness\"", "model: \"OTHER-9\"");
    assert_ne!(other, text_b);
    std::fs::write(runs[1].join("manifest.yaml"), other).unwrap();
    refused(
        &["explain", a, b, "--twin", STATION, "--write-twin", out],
        "explain::model_twin_of_several_models",
    );
    // ... and folders of another model than --model's.
    refused(
        &[
            "explain",
            a,
            "--archive",
            archive,
            "--model",
            "OTHER-9",
            "--twin",
            STATION,
            "--write-twin",
            out,
        ],
        "explain::model_twin_of_several_models",
    );
}
