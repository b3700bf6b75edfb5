//! `ratecal explain --archive A --model M | --serial SN`: the same fleet explained from a
//! SQLite archive and from a PostgreSQL server the test starts (skipped, saying so, when
//! PostgreSQL is not installed) gives the pool the folders give; a second query reads every
//! explanation back from the archive (it explains none again, and on SQLite it needs no
//! stored file: the store is removed before it).

use crate::pg::Cluster;
use crate::support;
use ratecal_archive::{Archive, Location};
use ratecal_witness::{Hidden, Plan, Scenario, write};
use serde_json::Value;
use std::path::{Path, PathBuf};
use support::{code, ratecal, text};

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// Five recordings of four units sharing a K2, short (a 60 s gyro-bias block).
fn fleet(dir: &Path) -> Vec<PathBuf> {
    let units = [
        ("AR-1", 11),
        ("AR-1", 12),
        ("AR-2", 13),
        ("AR-3", 14),
        ("AR-4", 15),
    ];
    units
        .iter()
        .map(|&(serial, seed)| {
            let mut s = Scenario::standard(serial, seed).with(Hidden::AccelSecondOrder {
                k2_ug_per_g2: [60.0, 60.0, 60.0],
            });
            s.plan = Plan::standard(60.0);
            let p = dir.join(format!("{serial}-{seed}"));
            write(&p, &s).unwrap();
            p
        })
        .collect()
}

/// Adds the folders to the archive at `loc` (the library's add: witness recordings are not
/// sealed run folders, which `ratecal archive add` verifies first).
fn archive(loc: &str, runs: &[PathBuf]) {
    let rt = tokio::runtime::Runtime::new().unwrap();
    rt.block_on(async {
        let a = Archive::open(&Location::parse(loc, None)).await.unwrap();
        for r in runs {
            a.add(r).await.unwrap();
        }
        a.close().await;
    });
}

/// `explain ARGS --format json`: the JSON and standard error.
fn explain(args: &[&str]) -> (Value, String) {
    let mut all = vec!["explain"];
    all.extend_from_slice(args);
    all.extend(["--format", "json"]);
    let o = ratecal(&all, Path::new(ROOT));
    assert_eq!(code(&o), 1, "{}", text(&o));
    let v = serde_json::from_slice(&o.stdout).unwrap_or_else(|e| panic!("{e}: {}", text(&o)));
    (v, String::from_utf8_lossy(&o.stderr).into_owned())
}

/// The pool without the runs' names: (effect, parameter, verdict, pooled, u) and the
/// per-recording values sorted (the archive lists its runs in its own order).
type Pool = Vec<(String, String, String, f64, f64, Vec<f64>)>;

fn pool(v: &Value) -> Pool {
    v["across"]["effects"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| {
            (
                e["effect"].as_str().unwrap().to_string(),
                e["parameter"].as_str().unwrap().to_string(),
                e["verdict"].as_str().unwrap().to_string(),
                e["pooled"].as_f64().unwrap(),
                e["u"].as_f64().unwrap(),
                {
                    let mut v: Vec<f64> = (e["per_recording"].as_array().unwrap().iter())
                        .map(|r| r["value"].as_f64().unwrap())
                        .collect();
                    v.sort_by(f64::total_cmp);
                    v
                },
            )
        })
        .collect()
}

/// Two pools agree: the same parameters and verdicts, the values to 1e-9 relative (the
/// sums run in another order).
fn same(a: &Pool, b: &Pool) {
    let close = |x: f64, y: f64| (x - y).abs() <= 1e-9 * x.abs().max(y.abs()).max(1e-300);
    assert_eq!(a.len(), b.len(), "{a:?}\n{b:?}");
    for (x, y) in a.iter().zip(b) {
        assert_eq!((&x.0, &x.1, &x.2), (&y.0, &y.1, &y.2), "{a:?}\n{b:?}");
        assert!(close(x.3, y.3) && close(x.4, y.4), "{x:?} {y:?}");
        assert!(
            x.5.iter().zip(&y.5).all(|(p, q)| close(*p, *q)),
            "{x:?} {y:?}"
        );
    }
}

/// Cold then warm queries on archive `loc` agree with the folders' pool (`folders`); the
/// warm one explains nothing again. `between` runs between the two.
fn cold_and_warm(loc: &str, folders: &Value, between: impl FnOnce()) -> Value {
    let (cold, err) = explain(&["--archive", loc, "--model", "ratecal-witness"]);
    assert!(
        err.contains("5 archived run(s): 0 explanation(s) kept in the archive, 5 to explain"),
        "{err}"
    );
    assert_eq!(cold["across"]["recordings"].as_array().unwrap().len(), 5);
    same(&pool(&cold), &pool(folders));
    between();
    let (warm, err) = explain(&["--archive", loc, "--model", "ratecal-witness"]);
    assert!(
        err.contains("5 explanation(s) kept in the archive, 0 to explain"),
        "{err}"
    );
    same(&pool(&warm), &pool(&cold));
    assert_eq!(warm["across"]["recordings"], cold["across"]["recordings"]);
    // One unit's history: its two recordings, read back too.
    let (unit, err) = explain(&["--archive", loc, "--serial", "AR-1"]);
    assert!(
        err.contains("2 archived run(s): 2 explanation(s) kept"),
        "{err}"
    );
    let serials: Vec<&str> = (unit["across"]["recordings"].as_array().unwrap().iter())
        .map(|r| r["serial"].as_str().unwrap())
        .collect();
    assert_eq!(serials, ["AR-1", "AR-1"]);
    cold
}

#[test]
fn the_archive_pools_as_the_folders_do_and_keeps_each_explanation() {
    let tmp = tempfile::tempdir().unwrap();
    let runs = fleet(&tmp.path().join("runs"));
    let names: Vec<&str> = runs.iter().map(|p| p.to_str().unwrap()).collect();
    let (folders, _) = explain(&names);
    // K2 at 60 ug/g^2 over five recordings: the pool finds it.
    assert!(
        pool(&folders)
            .iter()
            .any(|e| e.0 == "accel_second_order" && e.2 != "none"),
        "{:#}",
        folders["across"]
    );
    let sqlite = tmp.path().join("archive");
    archive(sqlite.to_str().unwrap(), &runs);
    let store = sqlite.join("files");
    assert!(store.is_dir());
    let from_sqlite = cold_and_warm(sqlite.to_str().unwrap(), &folders, || {
        std::fs::remove_dir_all(&store).unwrap();
    });
    model_twin_from_the_archive(sqlite.to_str().unwrap(), tmp.path(), &from_sqlite);
    let Some(pg) = Cluster::start() else {
        println!("skipped: postgresql not installed");
        return;
    };
    let url = pg.url();
    archive(&url, &runs);
    let from_pg = cold_and_warm(&url, &folders, || {});
    // The same runs (content addresses), the same pool.
    same(&pool(&from_pg), &pool(&from_sqlite));
}

/// `--model M --twin STATION --write-twin OUT` from the archive (every explanation kept:
/// pooling only) writes every `model`/`pooled_only` entry of the pool `pool_v`, and
/// nothing else, into a station file that parses.
fn model_twin_from_the_archive(loc: &str, tmp: &Path, pool_v: &Value) {
    let out = tmp.join("model-twin.yaml");
    let station = format!("{ROOT}/drivers/stations/default.yaml");
    let (v, err) = explain(&[
        "--archive",
        loc,
        "--model",
        "ratecal-witness",
        "--twin",
        &station,
        "--write-twin",
        out.to_str().unwrap(),
    ]);
    assert!(err.contains("0 to explain"), "{err}");
    let shared: Vec<(&str, &str, f64)> = (pool_v["across"]["effects"].as_array().unwrap().iter())
        .filter(|e| e["verdict"] == "model" || e["verdict"] == "pooled_only")
        .map(|e| {
            let p = e["pooled"].as_f64().unwrap();
            (
                e["effect"].as_str().unwrap(),
                e["parameter"].as_str().unwrap(),
                p,
            )
        })
        .collect();
    assert!(!shared.is_empty(), "{:#}", pool_v["across"]);
    let changes = v["twin"]["changes"].as_array().unwrap();
    assert_eq!(changes.len(), shared.len(), "{:#}", v["twin"]);
    for (c, (effect, parameter, pooled)) in changes.iter().zip(&shared) {
        assert_eq!(
            (c["effect"].as_str(), c["parameter"].as_str()),
            (Some(*effect), Some(*parameter))
        );
        assert!((c["to"].as_f64().unwrap() - pooled).abs() < 1e-9, "{c:#}");
    }
    let yaml = std::fs::read_to_string(&out).unwrap();
    let st = ratecal_drivers::station::Station::from_yaml(&yaml, "model-twin.yaml")
        .unwrap_or_else(|e| panic!("{e:?}\n{yaml}"));
    let k2 = ratecal_physics::effect("accel_second_order").unwrap();
    assert!(
        st.imu
            .effects
            .values(k2)
            .iter()
            .all(|k| (*k - 60.0).abs() < 30.0),
        "{yaml}"
    );
}

#[test]
fn err_no_archived_run_matches() {
    let tmp = tempfile::tempdir().unwrap();
    let runs = fleet(&tmp.path().join("runs"));
    let a = tmp.path().join("archive");
    archive(a.to_str().unwrap(), &runs[..1]);
    let o = ratecal(
        &[
            "explain",
            "--archive",
            a.to_str().unwrap(),
            "--serial",
            "NOPE",
        ],
        Path::new(ROOT),
    );
    assert_eq!(code(&o), 2, "{}", text(&o));
    assert!(text(&o).contains("explain::no_runs"), "{}", text(&o));
    let o = ratecal(
        &[
            "explain",
            runs[0].to_str().unwrap(),
            "--since",
            "2026-01-01",
        ],
        Path::new(ROOT),
    );
    assert_eq!(code(&o), 2, "{}", text(&o));
    assert!(text(&o).contains("explain::no_selection"), "{}", text(&o));
}
