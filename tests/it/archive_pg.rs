//! `ratecal archive` on a real PostgreSQL server the test starts itself (a throwaway cluster:
//! `initdb`, `pg_ctl` on a loopback port and a socket in a temporary folder). Without
//! PostgreSQL installed the test says `skipped: postgresql not installed`.

use crate::archive_common;
use crate::pg;
use archive_common::*;
use pg::Cluster;
use std::path::Path;
use std::process::Command;

fn ok(args: &[&str], cwd: &Path) -> String {
    let o = ratecal(args, cwd);
    assert_eq!(code(&o), 0, "{args:?}: {}", text(&o));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

#[test]
fn postgresql_archive_end_to_end() {
    let Some(pg) = Cluster::start() else {
        println!("skipped: postgresql not installed");
        return;
    };
    let url = pg.url();
    let tmp = tempfile::tempdir().unwrap();
    let cwd = tmp.path();
    let names: Vec<String> = (0..6).map(|i| format!("r{i}")).collect();
    for (i, n) in names.iter().enumerate() {
        let started = format!("202{}-05-01T12:00:00Z", i);
        write_run(
            &cwd.join(n),
            Some("PG-1"),
            &started,
            0.01 + 0.002 * i as f64,
            &[],
        );
    }
    write_run(
        &cwd.join("noserial"),
        None,
        "2026-07-01T00:00:00Z",
        0.0,
        &[],
    );

    // Two stations adding at once (files in the database, index in one transaction each).
    let spawn = |runs: &[String]| {
        Command::new(env!("CARGO_BIN_EXE_ratecal"))
            .args(["archive", "add", "--archive", &url])
            .args(runs)
            .current_dir(cwd)
            .env_remove("RATECAL_ARCHIVE")
            .output()
            .unwrap()
    };
    // The schema first (the migrator locks on PostgreSQL, but keep the race about adds).
    ok(&["archive", "check", "--archive", &url], cwd);
    let (a, b) = std::thread::scope(|s| {
        let a = s.spawn(|| spawn(&names[..3]));
        let b = s.spawn(|| spawn(&names[3..]));
        (a.join().unwrap(), b.join().unwrap())
    });
    assert_eq!(code(&a), 0, "{}", text(&a));
    assert_eq!(code(&b), 0, "{}", text(&b));
    ok(
        &["archive", "add", "noserial", "r0", "--archive", &url],
        cwd,
    );
    assert_eq!(list(&url, &["--serial", "PG-1"], cwd).len(), 6);
    let unknown = list(&url, &["--since", "2026-07-01"], cwd);
    assert_eq!(unknown.len(), 1);
    assert_eq!(unknown[0]["serial"], "unknown");

    // Round trip from the database's file store.
    let id = list(&url, &["--serial", "PG-1"], cwd)[2]["id"]
        .as_str()
        .unwrap()
        .to_string();
    ok(&["archive", "export", &id, "back", "--archive", &url], cwd);
    assert_eq!(tree(&cwd.join("r2")), tree(&cwd.join("back")));
    ok(&["verify", "back"], cwd);
    let show = ok(
        &[
            "archive",
            "show",
            &id,
            "--format",
            "json",
            "--archive",
            &url,
        ],
        cwd,
    );
    assert!(show.contains("\"accel.bias.x\""));

    // Trend: 0.002 m/s^2 a year, exactly.
    let t = ok(
        &[
            "archive",
            "trend",
            "PG-1",
            "--format",
            "json",
            "--archive",
            &url,
        ],
        cwd,
    );
    let t: serde_json::Value = serde_json::from_str(&t).unwrap();
    let p = t["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["name"] == "accel.bias.x")
        .unwrap();
    let rate = p["drift"]["rate_per_year"].as_f64().unwrap();
    assert!((rate - 0.002).abs() < 1e-5, "{rate}");

    let check = ok(&["archive", "check", "--archive", &url], cwd);
    assert!(check.contains("consistent"), "{check}");

    // Backup to a folder archive another machine opens without the server.
    ok(&["archive", "backup", "copy", "--archive", &url], cwd);
    assert_eq!(list("copy", &[], cwd), list(&url, &[], cwd));
    ok(&["archive", "check", "--archive", "copy"], cwd);

    // A shared folder for the files instead of the database.
    write_run(
        &cwd.join("r9"),
        Some("PG-2"),
        "2026-08-01T00:00:00Z",
        0.5,
        &[],
    );
    let shared = ["--archive", url.as_str(), "--archive-files", "shared"];
    let mut args = vec!["archive", "add", "r9"];
    args.extend_from_slice(&shared);
    ok(&args, cwd);
    let id = list(&url, &["--serial", "PG-2"], cwd)[0]["id"]
        .as_str()
        .unwrap()
        .to_string();
    let mut args = vec!["archive", "export", id.as_str(), "back9"];
    args.extend_from_slice(&shared);
    ok(&args, cwd);
    assert_eq!(tree(&cwd.join("r9")), tree(&cwd.join("back9")));
}
