//! Issue 37 items 4 to 7, the real binary on real run folders and a real archive: the
//! authorised signers of `LAB.yaml`, one archive entry per calibration whatever the order of
//! `approve` and `archive add`, what an assessor looks for in every format (the user's text
//! escaped in Markdown and HTML), and an imported recording certified like a run.

use crate::certificate_cli::{
    approve, certificate, certified_station, flat, json_of, lab_in, mini, numbered, pdf_pages,
    unwrapped, with,
};
use crate::support::{self, code, ratecal, text};
use std::path::Path;
use std::process::Output;

/// `ratecal certificate RUN --lab LAB --archive archive ...` in `dir`.
fn certificate_with(dir: &Path, run: &str, lab: &str, extra: &[&str]) -> Output {
    let mut args = vec!["certificate", run, "--lab", lab, "--archive", "archive"];
    args.extend_from_slice(extra);
    ratecal(&args, dir)
}

/// The approval's key fingerprint in `run`'s seal.
fn fingerprint(dir: &Path, run: &str) -> String {
    let seal = support::json(&dir.join(run).join("seal.json"));
    seal["approval"]["key_fingerprint"]
        .as_str()
        .unwrap()
        .to_string()
}

// -- item 4: signers -----------------------------------------------------------------------

#[test]
fn a_certificate_is_issued_only_for_an_approval_key_the_lab_lists() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let station = certified_station("2099-12-31");
    mini(dir, "run", &station, true);
    let listed = lab_in(dir);
    // The same laboratory without `signers`: an approved run is refused, with help.
    let text_of = std::fs::read_to_string(&listed).unwrap();
    let bare = &text_of[..text_of.find("signers:").unwrap()];
    std::fs::write(dir.join("bare.yaml"), bare).unwrap();
    let o = certificate_with(dir, "run", "bare.yaml", &["--format", "json"]);
    assert_eq!(code(&o), 1, "{}", text(&o));
    let t = unwrapped(&o);
    assert!(t.contains("lists no authorised signers"), "{t}");
    assert!(t.contains(&fingerprint(dir, "run")), "{t}");
    assert!(t.contains("help") && t.contains("signers:"), "{t}");
    // An unapproved run still gets its DRAFT without signers.
    mini(dir, "draft", &station, false);
    let o = certificate_with(dir, "draft", "bare.yaml", &["--format", "json"]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert_eq!(json_of(&o)["draft"], true);

    // A key made a minute ago, not listed: refused, naming its fingerprint; nothing taken.
    std::fs::write(dir.join("p.rcal"), support::MINI).unwrap();
    let o = ratecal(
        &["run", "p.rcal", "--station", "s.yaml", "--out", "other"],
        dir,
    );
    assert!(matches!(code(&o), 0 | 3), "{}", text(&o));
    let o = ratecal(&["key", "new", "rogue"], dir);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let o = ratecal(
        &[
            "approve",
            "other",
            "--signer",
            "Someone",
            "--role",
            "Head of Lab",
            "--key",
            "rogue/lab.key",
        ],
        dir,
    );
    assert_eq!(code(&o), 0, "approve needs no lab file: {}", text(&o));
    let o = ratecal(&["archive", "add", "other", "--archive", "archive"], dir);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let o = certificate(dir, "other", &["--out", "rogue.pdf"]);
    assert_eq!(code(&o), 1, "{}", text(&o));
    let t = unwrapped(&o);
    let rogue = fingerprint(dir, "other");
    assert_ne!(rogue, fingerprint(dir, "run"));
    assert!(t.contains(&rogue), "the refusal names the key: {t}");
    assert!(t.contains("not the key of a signer"), "{t}");
    assert!(!dir.join("rogue.pdf").exists());
    // A signer's key file that cannot be read: refused at its key.
    std::fs::write(
        dir.join("missing.yaml"),
        text_of.replace("keys/lab.pub", "nowhere/lab.pub"),
    )
    .unwrap();
    let o = certificate_with(dir, "run", "missing.yaml", &["--format", "json"]);
    assert_eq!(code(&o), 1, "{}", text(&o));
    assert!(text(&o).contains("nowhere/lab.pub"), "{}", text(&o));
    // The listed key: issued, the first number (the refusals burned none).
    let o = certificate(dir, "run", &["--format", "json"]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert_eq!(json_of(&o)["number"], numbered(1).as_str());
}

/// `ratecal` in `dir` with `RATECAL_ARCHIVE` naming `dir/archive`.
fn with_archive(args: &[&str], dir: &Path) -> Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_ratecal"))
        .args(args)
        .current_dir(dir)
        .env("RATECAL_ARCHIVE", dir.join("archive"))
        .output()
        .unwrap()
}

/// How many calibrations of SIM-0001 the archive's trend counts, and its list's entries.
fn counted(dir: &Path) -> (u64, usize) {
    let o = ratecal(
        &[
            "archive",
            "trend",
            "SIM-0001",
            "--archive",
            "archive",
            "--format",
            "json",
        ],
        dir,
    );
    assert_eq!(code(&o), 0, "{}", text(&o));
    let trend = json_of(&o);
    let o = ratecal(
        &[
            "archive",
            "list",
            "--archive",
            "archive",
            "--format",
            "json",
        ],
        dir,
    );
    assert_eq!(code(&o), 0, "{}", text(&o));
    let list = json_of(&o);
    (
        trend["calibrations"].as_u64().unwrap(),
        list.as_array().map_or(0, Vec::len),
    )
}

#[test]
fn a_run_archived_before_its_approval_stays_one_calibration_one_entry() {
    // `run` with an archive set adds the unapproved run; approved and added again, the
    // entry is replaced, not doubled; the unapproved copy added later is not added again.
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::write(dir.join("s.yaml"), certified_station("2099-12-31")).unwrap();
    std::fs::write(dir.join("p.rcal"), support::MINI).unwrap();
    let o = with_archive(
        &["run", "p.rcal", "--station", "s.yaml", "--out", "cal"],
        dir,
    );
    assert!(matches!(code(&o), 0 | 3), "{}", text(&o));
    assert!(text(&o).contains("archived"), "{}", text(&o));
    assert_eq!(counted(dir), (1, 1));
    crate::certificate_cli::copy_dir(&dir.join("cal"), &dir.join("cal-unapproved"));
    approve(dir, "cal");
    let o = ratecal(&["archive", "add", "cal", "--archive", "archive"], dir);
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert!(
        flat(&text(&o)).contains("replacing the unapproved entry"),
        "{}",
        text(&o)
    );
    assert_eq!(
        counted(dir),
        (1, 1),
        "the approved run was added a second time"
    );
    let o = ratecal(
        &["archive", "add", "cal-unapproved", "--archive", "archive"],
        dir,
    );
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert!(flat(&text(&o)).contains("not added again"), "{}", text(&o));
    assert_eq!(counted(dir), (1, 1));
    let o = ratecal(&["archive", "check", "--archive", "archive"], dir);
    assert_eq!(code(&o), 0, "{}", text(&o));
    // The approved entry is the one certified.
    let o = certificate(dir, "cal", &["--format", "json"]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert_eq!(json_of(&o)["number"], numbered(1).as_str());

    // The other order: added, approved, added again: one entry too.
    let o = ratecal(
        &["run", "p.rcal", "--station", "s.yaml", "--out", "cal2"],
        dir,
    );
    assert!(matches!(code(&o), 0 | 3), "{}", text(&o));
    let o = ratecal(&["archive", "add", "cal2", "--archive", "archive"], dir);
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert_eq!(counted(dir), (2, 2));
    approve(dir, "cal2");
    let o = ratecal(&["archive", "add", "cal2", "--archive", "archive"], dir);
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert_eq!(counted(dir), (2, 2));
}

// -- items 5 and 6: what an assessor looks for, in every format ---------------------------

const SCRIPT: &str = "ACME <script>alert(1)</script> & Co";

/// Every element an assessor looks for, in the text of one format.
fn holds_every_element(format: &str, all: &str) {
    for want in [
        "Customer address",
        "Date of receipt",
        "2026-11-20",
        "Condition on receipt",
        "sealed box, undamaged",
        "IMU temperature",
        "Measurement points",
        "accel.z",
        "gyro.",
        "Reference standard",
        "DAQ timebase",
        "TF-2026-0311",
        "gravity survey",
        "GS-2025-017",
        "thermometer",
        "TH-2026-1142",
        "Deviations",
        "The results relate only to the item calibrated.",
    ] {
        assert!(all.contains(want), "{format}: no `{want}` in {all}");
    }
}

#[test]
fn an_assessor_finds_every_element_in_every_format_and_the_users_text_escaped() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    mini(dir, "run", &certified_station("2099-12-31"), true);
    let who = [
        "--customer",
        SCRIPT,
        "--customer-address",
        "1 <b>Main</b> Street, Springfield",
        "--received",
        "2026-11-20",
        "--condition",
        "sealed box, undamaged",
    ];
    let o = certificate(dir, "run", &with(&who, &["--format", "json"]));
    assert_eq!(code(&o), 0, "{}", text(&o));
    let j = json_of(&o);
    let id = &j["identification"];
    assert_eq!(id["customer"], SCRIPT, "JSON keeps the text as typed");
    assert_eq!(id["customer_address"], "1 <b>Main</b> Street, Springfield");
    assert_eq!(id["item_received"], "2026-11-20");
    assert_eq!(id["item_condition"], "sealed box, undamaged");
    let results = support::json(&dir.join("run/results.json"));
    let range = &results["environment"]["imu_temp_range_c"];
    assert!(
        range.is_array(),
        "the simulator records the IMU's temperature"
    );
    assert_eq!(j["method"]["imu_temperature_c"], *range);
    // One point per attitude and rate point of the recording, each with its numbers.
    let points = j["measurement_points"].as_array().unwrap();
    let manifest = std::fs::read_to_string(dir.join("run/manifest.yaml")).unwrap();
    let segments =
        manifest.matches("kind: static").count() + manifest.matches("kind: rate").count();
    assert_eq!(points.len(), segments, "{points:?}");
    for p in points {
        for key in [
            "segment",
            "condition",
            "channel",
            "reference",
            "reading",
            "error",
            "U",
            "k",
            "unit",
            "verdict",
        ] {
            assert!(!p[key].is_null(), "{key} in {p}");
        }
        let (r, m, e) = (
            p["reference"].as_f64().unwrap(),
            p["reading"].as_f64().unwrap(),
            p["error"].as_f64().unwrap(),
        );
        assert!((m - r - e).abs() < 1e-12 * r.abs().max(1.0), "{p}");
        assert!(p["U"].as_f64().unwrap() > 0.0, "{p}");
    }
    let stat = points.iter().find(|p| p["channel"] == "accel.z").unwrap();
    assert!(
        (stat["reference"].as_f64().unwrap() - 9.8156).abs() < 1e-9,
        "{stat}"
    );
    let refs = j["traceability"]["references"].as_array().unwrap();
    let names: Vec<&str> = refs
        .iter()
        .map(|r| r["standard"].as_str().unwrap())
        .collect();
    assert_eq!(
        names,
        [
            "rate table",
            "DAQ timebase",
            "gravity survey",
            "thermometer"
        ]
    );
    assert!(refs.iter().all(|r| r["valid"] == true), "{refs:?}");
    assert!(j["deviations"].is_array());

    // Markdown and HTML: the same content, what the user typed escaped.
    for format in ["md", "html"] {
        let o = certificate(dir, "run", &with(&who, &["--format", format]));
        assert_eq!(code(&o), 0, "{}", text(&o));
        let out = String::from_utf8(o.stdout).unwrap();
        assert!(
            !out.contains("<script>"),
            "{format} runs the user's script: {out}"
        );
        assert!(!out.contains("<b>Main"), "{format}: {out}");
        assert!(out.contains("&lt;script&gt;"), "{format}: {out}");
        holds_every_element(format, &flat(&out));
    }
    let o = certificate(dir, "run", &with(&who, &["--out", "c.pdf"]));
    assert_eq!(code(&o), 0, "{}", text(&o));
    if let Some(pages) = pdf_pages(&std::fs::read(dir.join("c.pdf")).unwrap()) {
        let all = flat(&pages.join("\n"));
        holds_every_element("pdf", &all);
        assert!(
            all.contains(SCRIPT),
            "the PDF prints the text as typed: {all}"
        );
    }

    // Absent, each is "not stated"; a date of receipt that is no date is refused.
    mini(dir, "plain", &certified_station("2099-12-31"), true);
    let o = certificate(dir, "plain", &["--format", "md"]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let md = flat(&String::from_utf8_lossy(&o.stdout));
    for field in [
        "Customer address",
        "Date of receipt",
        "Condition on receipt",
    ] {
        assert!(
            md.contains(&format!("**{field}**: not stated")),
            "{field}: {md}"
        );
    }
    let o = certificate(dir, "plain", &["--received", "yesterday"]);
    assert_eq!(code(&o), 1, "{}", text(&o));
    assert!(unwrapped(&o).contains("YYYY-MM-DD"), "{}", text(&o));
}

#[test]
fn with_allow_expired_no_traceability_is_claimed_through_an_expired_reference() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    // The table expired, the other references in date.
    let station = certified_station("2099-12-31").replace(
        "calibration: { certificate: NMI-2026-0815, issued_by: National Metrology Institute, due: 2099-12-31 }",
        "calibration: { certificate: NMI-2026-0815, issued_by: National Metrology Institute, due: 2001-01-31 }",
    );
    mini(dir, "run", &station, true);
    let o = certificate(dir, "run", &["--format", "json", "--allow-expired"]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let j = json_of(&o);
    let statement = j["traceability"]["statement"].as_str().unwrap();
    assert!(!statement.contains("are traceable"), "{statement}");
    assert!(
        statement.contains("not shown to be traceable"),
        "{statement}"
    );
    assert_eq!(j["traceability"]["references"][0]["valid"], false);
    assert!(
        j["deviations"].to_string().contains("--allow-expired"),
        "{}",
        j["deviations"]
    );
    // Only the thermometer expired: refused at its key; allowed, the claim leaves it out.
    let station = certified_station("2099-12-31").replace(
        "certificate: TH-2026-1142, issued_by: Example Temperature Lab, due: 2099-12-31",
        "certificate: TH-2026-1142, issued_by: Example Temperature Lab, due: 2001-01-31",
    );
    mini(dir, "thermo", &station, true);
    let o = certificate(dir, "thermo", &["--format", "json"]);
    assert_eq!(code(&o), 1, "{}", text(&o));
    assert!(text(&o).contains("thermometer"), "{}", text(&o));
    let o = certificate(dir, "thermo", &["--format", "json", "--allow-expired"]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let statement = json_of(&o)["traceability"]["statement"]
        .as_str()
        .unwrap()
        .to_string();
    let claim = &statement[..statement.find('.').unwrap()];
    assert!(claim.contains("NMI-2026-0815"), "{statement}");
    assert!(!claim.contains("TH-2026-1142"), "{statement}");
    assert!(
        statement.contains("does not extend through it"),
        "{statement}"
    );
}

// -- item 7: imported recordings -----------------------------------------------------------

/// A generated session at 100 Hz: six faces of 3 s each (+z, -z, +x, -x, +y, -y up), then
/// 3 s turning about z at 100 deg/s; accelerometers in g (a small bias and scale error),
/// gyros in deg/s.
fn six_faces() -> (String, String) {
    let faces = ["+z", "-z", "+x", "-x", "+y", "-y"];
    let mut data = String::from("acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z\n");
    let mut map = String::from(
        "source: { format: csv }\nimu:\n  time: { rate_hz: 100 }\n  columns: { ax: acc_x, ay: \
         acc_y, az: acc_z, gx: gyr_x, gy: gyr_y, gz: gyr_z }\n  units: { accel: g, gyro: \
         deg/s }\nsegments:\n",
    );
    for (f, up) in faces.iter().enumerate() {
        let k = usize::from(up.as_bytes()[1] - b'x');
        let sign = if up.starts_with('-') { -1.0 } else { 1.0 };
        for i in 0..300 {
            let n = ((i * 7919) % 13) as f64 * 1e-5;
            let mut a = [0.002 + n, -0.001, 0.003 - n];
            a[k] += sign * (1.0 + 3e-4 * k as f64);
            data.push_str(&format!("{},{},{},0.3,-0.2,0.1\n", a[0], a[1], a[2]));
        }
        map.push_str(&format!(
            "  - {{ id: face{f}, kind: static, samples: [{}, {}], up: {up} }}\n",
            f * 300 + 20,
            f * 300 + 280
        ));
    }
    for i in 0..300 {
        let n = ((i * 7919) % 13) as f64 * 1e-4;
        data.push_str(&format!("0.002,-0.001,1.003,0.3,-0.2,{}\n", 100.0 + n));
    }
    map.push_str(
        "  - { id: turn, kind: rate, samples: [1820, 2080], axis: z, rate_dps: 100 }\nsite: \
         { latitude_deg: 55.7, gravity_mps2: 9.8156 }\n",
    );
    (data, map)
}

/// Imports the generated session into `dir/name` (with `extra` options), analyses it into
/// the folder, approves and archives it.
fn imported(dir: &Path, name: &str, extra: &[&str]) {
    let (data, map) = six_faces();
    std::fs::write(dir.join("data.csv"), data).unwrap();
    std::fs::write(dir.join("map.yaml"), map).unwrap();
    let mut args = vec!["import", "data.csv", "--map", "map.yaml", "--out", name];
    args.extend_from_slice(extra);
    let o = ratecal(&args, dir);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let results = format!("{name}/results.json");
    let o = ratecal(&["analyze", name, "--out", &results], dir);
    assert!(matches!(code(&o), 0 | 3), "{}", text(&o));
    approve(dir, name);
    let o = ratecal(&["archive", "add", name, "--archive", "archive"], dir);
    assert_eq!(code(&o), 0, "{}", text(&o));
}

#[test]
fn an_imported_recording_is_certified_like_a_run_with_its_station() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    // The station is the simulator's (drivers `sim`): an import is never a dry run.
    std::fs::write(dir.join("s.yaml"), certified_station("2099-12-31")).unwrap();
    imported(dir, "imp", &["--station", "s.yaml"]);
    assert_eq!(
        std::fs::read(dir.join("imp/station.yaml")).unwrap(),
        std::fs::read(dir.join("s.yaml")).unwrap()
    );
    let seal = support::json(&dir.join("imp/seal.json"));
    assert!(seal["files"]["station.yaml"].is_string(), "sealed: {seal}");
    let o = ratecal(&["verify", "imp"], dir);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let o = certificate(dir, "imp", &["--format", "json"]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let j = json_of(&o);
    assert_eq!(j["number"], numbered(1).as_str());
    assert_eq!(j["specimen"], false);
    assert_eq!(j["draft"], false);
    assert!(
        j["notes"].to_string().contains("imported"),
        "{}",
        j["notes"]
    );
    assert_eq!(
        j["traceability"]["references"][0]["certificate"],
        "NMI-2026-0815"
    );

    // A station file that is not one: refused before anything is written.
    std::fs::write(dir.join("bad.yaml"), "site: 3\n").unwrap();
    let o = ratecal(
        &[
            "import",
            "data.csv",
            "--map",
            "map.yaml",
            "--out",
            "bad",
            "--station",
            "bad.yaml",
        ],
        dir,
    );
    assert_eq!(code(&o), 1, "{}", text(&o));
    assert!(!dir.join("bad").exists());

    // Without --station: refused with help naming it, exit 1.
    imported(dir, "bare", &[]);
    let o = certificate(dir, "bare", &["--format", "json"]);
    assert_eq!(code(&o), 1, "{}", text(&o));
    let t = unwrapped(&o);
    assert!(
        t.contains("imported recording without a station file"),
        "{t}"
    );
    assert!(t.contains("help") && t.contains("--station"), "{t}");
}
