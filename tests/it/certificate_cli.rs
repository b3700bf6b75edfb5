//! `ratecal approve` and `ratecal certificate` end to end, the real binary on real run
//! folders: the PDF's text read back with a PDF library (lopdf, not our writer), the
//! refusals and their exit codes, and the numbering under concurrent processes.

use crate::pg;
use crate::support;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use support::{code, mini_run, ratecal, text};

/// The default station with the keys a certificate needs (`due` far ahead: the test
/// does not expire).
pub(crate) fn certified_station(due: &str) -> String {
    let s = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/docs/examples/station.yaml"
    ))
    .unwrap();
    s.replace("due: 2030-06-30", &format!("due: {due}"))
}

fn lab() -> String {
    concat!(env!("CARGO_MANIFEST_DIR"), "/docs/examples/lab.yaml").to_string()
}

/// The example laboratory in `dir/lab.yaml` (written once), its signer's public key
/// `dir/keys/lab.pub`, the key [`approve`] approves with.
pub(crate) fn lab_in(dir: &Path) -> String {
    let path = dir.join("lab.yaml");
    if !path.exists() {
        let text = std::fs::read_to_string(lab()).unwrap();
        assert!(text.contains("public_key: ../../keys/lab.pub"), "{text}");
        std::fs::write(&path, text.replace("../../keys/lab.pub", "keys/lab.pub")).unwrap();
    }
    path.display().to_string()
}

/// Every page's text, by poppler's pdftotext (not our writer); `None`, said on standard
/// error, when pdftotext is not installed (`.ci/run` installs it). lopdf cannot read the
/// ToUnicode maps krilla writes, which poppler, pypdf and Acrobat read.
pub(crate) fn pdf_pages(bytes: &[u8]) -> Option<Vec<String>> {
    if std::process::Command::new("pdftotext")
        .arg("-v")
        .output()
        .is_err()
    {
        eprintln!("skipped the PDF's text: pdftotext (poppler-utils) not installed");
        return None;
    }
    let tmp = tempfile::tempdir().unwrap();
    let pdf = tmp.path().join("c.pdf");
    std::fs::write(&pdf, bytes).unwrap();
    let o = Command::new("pdftotext")
        .args(["-raw", "-enc", "UTF-8"])
        .arg(&pdf)
        .arg("-")
        .output()
        .unwrap();
    assert!(o.status.success(), "pdftotext: {}", text(&o));
    let all = String::from_utf8(o.stdout).unwrap();
    Some(
        all.split('\u{c}')
            .filter(|p| !p.trim().is_empty())
            .map(String::from)
            .collect(),
    )
}

/// Collapses whitespace, so that a phrase wrapped over two lines is still found.
pub(crate) fn flat(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// A MINI run in `dir/name` on `station`, approved (or not) and archived in `dir/archive`.
/// Not a dry run: `station`'s drivers are the simulator's (virtual time, well under a
/// second), but the run is recorded as a real one, so its certificate takes a number.
pub(crate) fn mini(dir: &Path, name: &str, station: &str, approved: bool) -> PathBuf {
    std::fs::write(dir.join("s.yaml"), station).unwrap();
    std::fs::write(dir.join("p.rcal"), support::MINI).unwrap();
    let o = ratecal(
        &["run", "p.rcal", "--station", "s.yaml", "--out", name],
        dir,
    );
    assert!(matches!(code(&o), 0 | 3), "{}", text(&o));
    let manifest = std::fs::read_to_string(dir.join(name).join("manifest.yaml")).unwrap();
    assert!(manifest.contains("dry_run: false"), "{manifest}");
    if approved {
        approve(dir, name);
    }
    let o = ratecal(&["archive", "add", name, "--archive", "archive"], dir);
    assert_eq!(code(&o), 0, "{}", text(&o));
    dir.join(name)
}

pub(crate) fn certificate(dir: &Path, run: &str, extra: &[&str]) -> Output {
    let lab = lab_in(dir);
    let mut args = vec![
        "certificate",
        run,
        "--lab",
        lab.as_str(),
        "--archive",
        "archive",
    ];
    args.extend_from_slice(extra);
    ratecal(&args, dir)
}

pub(crate) fn json_of(o: &Output) -> serde_json::Value {
    serde_json::from_slice(&o.stdout).unwrap_or_else(|e| panic!("{e}: {}", text(o)))
}

/// The proof: a run of `procedures/imu-2d-standard` on the simulated station (not a
/// dry run: its certificate takes a number), approved, archived, certified.
#[test]
fn the_standard_procedure_gives_a_signed_certificate_whose_pdf_holds_every_element() {
    let procedure = support::procedures("imu-2d-standard");
    full_flow(
        &procedure,
        None,
        "imu-2d-standard version 1.1.0",
        "Static calibration of the accelerometers",
        "gyro.scale.x",
    );
}

/// The same on the two-attitude procedure (fast): every element of the PDF, the JSON keys,
/// a budget by hand.
#[test]
fn a_signed_certificate_pdf_holds_every_element() {
    let with_check = support::MINI.replacen(
        "  step statics",
        "  accept accel.bias.x <= 80 mg\n\n  step statics",
        1,
    );
    full_flow(
        "p.rcal",
        Some(&with_check),
        "mini version 1.0.0",
        "Two static attitudes",
        "gyro.scale.y",
    );
}

fn full_flow(procedure: &str, text_of: Option<&str>, label: &str, step: &str, gyro: &str) {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::write(dir.join("s.yaml"), certified_station("2099-12-31")).unwrap();
    if let Some(t) = text_of {
        std::fs::write(dir.join(procedure), t).unwrap();
    }
    let o = ratecal(
        &["run", procedure, "--station", "s.yaml", "--out", "cal"],
        dir,
    );
    assert!(matches!(code(&o), 0 | 3), "{}", text(&o));
    approve(dir, "cal");
    let o = ratecal(&["verify", "cal"], dir);
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert!(
        text(&o).contains("approval by A. Metrologist (Head of laboratory)"),
        "{}",
        text(&o)
    );
    let o = ratecal(&["archive", "add", "cal", "--archive", "archive"], dir);
    assert_eq!(code(&o), 0, "{}", text(&o));

    let o = certificate(
        dir,
        "cal",
        &[
            "--customer",
            "ACME Avionics",
            "--order",
            "PO-4711",
            "--out",
            "cert.pdf",
        ],
    );
    assert_eq!(code(&o), 0, "{}", text(&o));
    if let Some(pages) = pdf_pages(&std::fs::read(dir.join("cert.pdf")).unwrap()) {
        pdf_text_holds_every_element(&pages, dir, label, step, gyro);
    }

    // Fonts embedded: every font the PDF uses carries its file.
    let doc = lopdf::Document::load_mem(&std::fs::read(dir.join("cert.pdf")).unwrap()).unwrap();
    let descriptors: Vec<_> = doc
        .objects
        .values()
        .filter_map(|o| o.as_dict().ok())
        .filter(|d| {
            d.get(b"Type").ok().and_then(|t| t.as_name().ok()) == Some(b"FontDescriptor".as_slice())
        })
        .collect();
    assert!(!descriptors.is_empty());
    assert!(
        descriptors
            .iter()
            .all(|d| d.has(b"FontFile2") || d.has(b"FontFile3") || d.has(b"FontFile"))
    );

    // Reissued (the same customer and order: the content bound to the number): the same
    // number; the JSON holds the stable keys.
    let year = &ratecal_recording::rfc3339(std::time::SystemTime::now())[..4];
    let number = format!("EICL-{year}-000001");
    let results = support::json(&dir.join("cal/results.json"));
    let o = certificate(
        dir,
        "cal",
        &[
            "--customer",
            "ACME Avionics",
            "--order",
            "PO-4711",
            "--format",
            "json",
        ],
    );
    assert_eq!(code(&o), 0, "{}", text(&o));
    let j = json_of(&o);
    assert_eq!(j["number"], number.as_str());
    assert_eq!(j["draft"], false);
    let budget = j["budget"].as_array().unwrap();
    let g = budget.iter().find(|b| b["quantity"] == gyro).unwrap();
    for key in ["unit", "terms", "u_c", "nu_eff", "k", "U"] {
        assert!(g.get(key).is_some(), "budget entry lacks {key}: {g}");
    }
    // gyro.scale.x by hand: Type A from results.json with the fit's dof counted per
    // segment; Type B, all rectangular, from the example station: the table's 10 ppm rate
    // accuracy, the DAQ clock's 2 ppm, and the temperature term, the data sheet's
    // 10 ppm/degC gyro scale coefficient over the lab's +-1 degC.
    let u_a = results["parameters"][gyro]["u"].as_f64().unwrap();
    let segments = results["segments"].as_array().unwrap();
    // The gyro scale fit's own segments (`used_for` `gyro_scale`, else the full model's):
    // one-second blocks less one per segment, as docs/certificate.md states the rule.
    let count = |fit: &str| {
        segments
            .iter()
            .filter(|s| s["used_for"].as_array().unwrap().iter().any(|u| u == fit))
            .fold((0usize, 0.0f64), |(n, secs), s| {
                let d = s["t_end"].as_f64().unwrap() - s["t_start"].as_f64().unwrap();
                (n + 1, secs + d.round())
            })
    };
    let (used, seconds) = ["gyro_scale", "gyro_full", "gyro"]
        .into_iter()
        .map(count)
        .find(|c| c.0 > 0)
        .expect("some segment is used for the gyro scale");
    let nu_a = seconds - used as f64;
    let u_b = 10.0 / 3f64.sqrt();
    let u_clock = 2.0 / 3f64.sqrt();
    let u_temp = 10.0 * 1.0 / 3f64.sqrt();
    let u_c = (u_a * u_a + u_b * u_b + u_clock * u_clock + u_temp * u_temp).sqrt();
    let nu_eff = u_c.powi(4) / (u_a.powi(4) / nu_a);
    assert!((g["u_c"].as_f64().unwrap() - u_c).abs() < 1e-9 * u_c.max(1.0));
    assert!((g["nu_eff"].as_f64().unwrap() - nu_eff).abs() < 1e-6 * nu_eff);
    let k = g["k"].as_f64().unwrap();
    let t95 = ratecal_certificate::budget::coverage_factor(Some(nu_eff));
    assert!(
        (k - t95).abs() < 1e-9 && k > 1.96,
        "k {k} for nu_eff {nu_eff}"
    );
    assert!((g["U"].as_f64().unwrap() - k * u_c).abs() < 1e-9 * u_c.max(1.0));
    let terms = g["terms"].as_array().unwrap();
    assert_eq!(terms[0]["type"], "A");
    assert_eq!(terms[1]["source"], "table rate accuracy");
    assert_eq!(terms[1]["distribution"], "rectangular");
    assert_eq!(terms[1]["status"], "stated");
    let by_source = |s: &str| {
        terms
            .iter()
            .find(|t| t["source"] == s)
            .unwrap_or_else(|| panic!("{s}: {g}"))
    };
    assert!((by_source("DAQ clock accuracy")["u"].as_f64().unwrap() - u_clock).abs() < 1e-12);
    let temp = by_source("temperature sensitivity");
    assert!((temp["u"].as_f64().unwrap() - u_temp).abs() < 1e-12);
    assert_eq!(temp["distribution"], "rectangular");
}

/// The header on every page and every element of the certificate, in order.
fn pdf_text_holds_every_element(pages: &[String], dir: &Path, label: &str, step: &str, gyro: &str) {
    let n = pages.len();
    assert!(n >= 2, "{n} pages");
    let year = &ratecal_recording::rfc3339(std::time::SystemTime::now())[..4];
    let number = format!("EICL-{year}-000001");
    for (i, p) in pages.iter().enumerate() {
        let p = flat(p);
        for want in [
            "Example Inertial Calibration Laboratory".to_string(),
            "12 Gyroscope Lane".into(),
            "Accredited to ISO/IEC 17025".into(),
            format!("Certificate No. {number}"),
            format!("page {} of {n}", i + 1),
        ] {
            assert!(p.contains(&want), "page {}: no `{want}` in {p}", i + 1);
        }
        assert!(
            !p.contains("DRAFT"),
            "an approved certificate says DRAFT: {p}"
        );
    }
    let all = flat(&pages.join("\n"));
    let results = support::json(&dir.join("cal/results.json"));
    let manifest = std::fs::read_to_string(dir.join("cal/manifest.yaml")).unwrap();
    let started = manifest
        .lines()
        .find_map(|l| l.trim().strip_prefix("started: "))
        .unwrap();
    let calibration_date = started.trim_matches(|c| c == '\'' || c == '"')[..10].to_string();
    let sha = results["model"]["procedure"]["sha256"]
        .as_str()
        .unwrap()
        .to_string();
    let mut order = Vec::new();
    for want in [
        "ACME Avionics",
        "PO-4711",
        "SIM-TAC-100",
        "SIM-0001",
        "tactical",
        label,
        &sha,
        "Example Motion Systems",
        "EMS-2A-0042",
        &format!("Date of calibration {calibration_date}"),
        "Date of issue",
        "Method and conditions",
        step,
        "Ambient temperature mean",
        "9.8156 m/s²",
        "55.7°",
        "Results",
        gyro,
        "(k = ",
        "95 %",
        "Statements of conformity",
        "ILAC-G8",
        "Traceability",
        "NMI-2026-0815",
        "National Metrology Institute",
        "due 2099-12-31",
        "Approved by A. Metrologist",
        "Head of laboratory",
        "SHA256:",
        "Annex: uncertainty budget",
        "table rate accuracy",
        "reference gravity",
        "table position accuracy",
        "eff",
        "This certificate shall not be reproduced except in full without the written approval of the laboratory.",
        &format!("End of certificate {number}"),
    ] {
        let at = all
            .find(want)
            .unwrap_or_else(|| panic!("no `{want}` in the PDF text: {all}"));
        order.push((want.to_string(), at));
    }
    // The sections in the order.
    let pos = |w: &str| order.iter().find(|(x, _)| x == w).unwrap().1;
    assert!(pos("Method and conditions") < pos("Results"));
    assert!(pos("Results") < pos("Traceability"));
    assert!(pos("Traceability") < pos("Annex: uncertainty budget"));
}

#[test]
fn a_draft_says_so_on_every_page_and_refusals_have_their_exit_codes() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    // Not approved, gravity's uncertainty not stated.
    let station = certified_station("2099-12-31").replace("  gravity_u_mps2: 0.00002\n", "");
    mini(dir, "draft", &station, false);
    let o = certificate(dir, "draft", &["--out", "d.pdf"]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    if let Some(pages) = pdf_pages(&std::fs::read(dir.join("d.pdf")).unwrap()) {
        assert!(pages.iter().all(|p| p.contains("DRAFT")), "{pages:?}");
    }
    let o = certificate(dir, "draft", &["--format", "json"]);
    let j = json_of(&o);
    assert_eq!(j["draft"], true);
    let scale = j["budget"]
        .as_array()
        .unwrap()
        .iter()
        .find(|b| b["quantity"] == "accel.scale.x")
        .unwrap();
    let gravity = scale["terms"]
        .as_array()
        .unwrap()
        .iter()
        .find(|t| t["source"] == "reference gravity")
        .unwrap();
    assert_eq!(gravity["status"], "not_stated");
    assert!(
        gravity["u"].is_null(),
        "a figure not stated is never 0: {gravity}"
    );
    let md = certificate(dir, "draft", &["--format", "md"]);
    assert!(String::from_utf8_lossy(&md.stdout).contains("not stated"));
    let html = certificate(dir, "draft", &["--format", "html"]);
    assert!(String::from_utf8_lossy(&html.stdout).contains("DRAFT"));

    // Acceptance checks on calibrated parameters: evaluated with the results, in the
    // limit's unit, and stated on the certificate under the named decision rule.
    let accepting = support::MINI.replacen(
        "  step statics",
        "  accept accel.bias.x <= 80 mg\n  accept gyro.scale.x <= 300000 ppm guarded\n  accept accel.bias.z within ±80 mg\n  accept abs(gyro.scale.x) <= 300000 ppm\n  accept norm(accel.bias) <= 500 mg\n\n  step statics",
        1,
    );
    std::fs::write(dir.join("acc.rcal"), &accepting).unwrap();
    std::fs::write(dir.join("s.yaml"), &station).unwrap();
    let o = ratecal(
        &[
            "run",
            "acc.rcal",
            "--dry-run",
            "--station",
            "s.yaml",
            "--out",
            "acc",
            "--serial",
            "SN-4242",
        ],
        dir,
    );
    assert!(matches!(code(&o), 0 | 3), "{}", text(&o));
    let res = support::json(&dir.join("acc/results.json"));
    let acc = res["acceptance"].as_array().unwrap();
    let bias = acc
        .iter()
        .find(|a| a["quantity"] == "accel.bias.x")
        .unwrap();
    let b = res["parameters"]["accel.bias.x"]["value"].as_f64().unwrap();
    let mg = b.abs() / 9.80665 * 1000.0;
    assert!(
        (bias["value"].as_f64().unwrap() - mg).abs() < 1e-9 * mg.max(1.0),
        "{bias}"
    );
    assert_eq!(bias["verdict"], if mg <= 80.0 { "pass" } else { "fail" });
    let o = ratecal(&["archive", "add", "acc", "--archive", "archive"], dir);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let j = json_of(&certificate(dir, "acc", &["--format", "json"]));
    // `run --serial` sets the item's serial without editing the station file.
    assert_eq!(j["identification"]["item_serial"], "SN-4242");
    let conf = &j["conformity"];
    assert!(
        conf["rule"]
            .as_str()
            .unwrap()
            .contains("guarded acceptance"),
        "{conf}"
    );
    assert!(
        conf["checks"].to_string().contains("accel.bias.x <= 80 mg"),
        "{conf}"
    );
    // The new forms: `within` keeps the signed value and judges both sides; `abs` and
    // `norm` are stated like any check.
    let checks = conf["checks"].as_array().unwrap();
    let within = checks
        .iter()
        .find(|c| c["name"] == "accel.bias.z within +-80 mg")
        .unwrap_or_else(|| panic!("{conf}"));
    assert_eq!(within["op"], "within");
    let bz = res["parameters"]["accel.bias.z"]["value"].as_f64().unwrap() / 9.80665 * 1000.0;
    assert!((within["value"].as_f64().unwrap() - bz).abs() < 1e-9 * bz.abs().max(1.0));
    let conforms = bz.abs() <= 80.0;
    assert_eq!(within["verdict"], if conforms { "pass" } else { "fail" });
    for name in [
        "abs(gyro.scale.x) <= 300000 ppm",
        "norm(accel.bias) <= 500 mg",
    ] {
        assert!(checks.iter().any(|c| c["name"] == name), "{name}: {conf}");
    }
    let md =
        String::from_utf8_lossy(&certificate(dir, "acc", &["--format", "md"]).stdout).into_owned();
    assert!(md.contains("within ±80 mg"), "{md}");

    // One decision rule, one U: the run judged with the full budgets it stored, and the
    // certificate states the run's verdicts, each row with its rule and k.
    let budgets = res["budgets"]
        .as_array()
        .expect("results.json holds the budgets");
    for c in checks {
        let run = acc.iter().find(|a| a["name"] == c["name"]).unwrap();
        assert_eq!(c["verdict"], run["verdict"], "{c} / {run}");
        assert_eq!(c["U"], run["U"], "{c} / {run}");
        if !c["U"].is_null() {
            assert!(c["k"].as_f64().unwrap() >= 1.95, "{c}");
        }
        assert!(
            matches!(c["rule"].as_str(), Some("simple" | "guarded")),
            "{c}"
        );
    }
    let u_mg = |q: &str| {
        let b = budgets.iter().find(|b| b["quantity"] == q).unwrap();
        b["U"].as_f64().unwrap() / 9.80665 * 1000.0
    };
    let (lo, hi) = ["x", "y", "z"]
        .map(|a| u_mg(&format!("accel.bias.{a}")))
        .iter()
        .fold((f64::MAX, 0.0f64), |(l, h), u| (l.min(*u), h.max(*u)));
    let norm = checks
        .iter()
        .find(|c| c["name"] == "norm(accel.bias) <= 500 mg")
        .unwrap();
    let u_norm = norm["U"].as_f64().unwrap();
    // The norm's U propagates the components' full budgets (weights summing to one in
    // quadrature), not the fit's Type A alone.
    assert!(
        u_norm > 0.9 * lo && u_norm < 1.1 * hi,
        "U(norm) {u_norm} mg outside the components' {lo}..{hi} mg"
    );
    // The budget's U of a parameter is the one its check was judged with.
    let bias = checks
        .iter()
        .find(|c| c["name"] == "accel.bias.x <= 80 mg")
        .unwrap();
    assert!((bias["U"].as_f64().unwrap() - u_mg("accel.bias.x")).abs() < 1e-9);

    // A run not in the archive: exit 1, help names `ratecal archive add`.
    std::fs::write(dir.join("s.yaml"), &station).unwrap();
    let o = mini_run(dir, "loose", &["--station", "s.yaml"]);
    assert!(matches!(code(&o), 0 | 3), "{}", text(&o));
    let o = certificate(dir, "loose", &[]);
    assert_eq!(code(&o), 1, "{}", text(&o));
    assert!(text(&o).contains("ratecal archive add"), "{}", text(&o));

    // A folder that fails its seal: no certificate, exit 4.
    let results = dir.join("draft/results.json");
    let t = std::fs::read_to_string(&results).unwrap();
    std::fs::write(&results, t.replacen('{', "{ ", 1)).unwrap();
    let o = certificate(dir, "draft", &[]);
    assert_eq!(code(&o), 4, "{}", text(&o));
    assert!(o.stdout.is_empty());

    // An expired reference calibration: refused at the key, unless --allow-expired.
    mini(dir, "expired", &certified_station("2001-01-31"), true);
    let o = certificate(dir, "expired", &["--format", "json"]);
    assert_eq!(code(&o), 1, "{}", text(&o));
    let t = text(&o);
    assert!(
        t.contains("due: 2001-01-31") && t.contains("station.yaml:"),
        "{t}"
    );
    // (miette wraps the help line: read it unwrapped)
    assert!(
        flat(&t).replace("- ", "-").contains("--allow-expired"),
        "{t}"
    );
    let o = certificate(dir, "expired", &["--format", "json", "--allow-expired"]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert!(json_of(&o)["notes"].to_string().contains("--allow-expired"));

    // No reference calibration at all: refused unless --allow-untraceable.
    let none = certified_station("2099-12-31")
        .lines()
        .filter(|l| !l.contains("calibration:"))
        .collect::<Vec<_>>()
        .join("\n");
    mini(dir, "untraceable", &none, true);
    let o = certificate(dir, "untraceable", &["--format", "json"]);
    assert_eq!(code(&o), 1, "{}", text(&o));
    let t = text(&o);
    assert!(t.contains("station.yaml:"), "{t}");
    assert!(
        flat(&t).replace("- ", "-").contains("--allow-untraceable"),
        "{t}"
    );
    let o = certificate(
        dir,
        "untraceable",
        &["--format", "md", "--allow-untraceable"],
    );
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("not shown to be traceable"));
}

#[test]
fn numbers_are_unique_and_stable_across_concurrent_processes_and_an_amendment_replaces() {
    let tmp = tempfile::tempdir().unwrap();
    concurrent_numbering(tmp.path(), "archive");
}

/// The same on a PostgreSQL archive (a real server the test starts): the sequence and the
/// issued numbers live in the database, twelve processes race for them.
#[test]
fn numbers_are_unique_and_stable_on_a_postgresql_archive() {
    let Some(pg) = pg::Cluster::start() else {
        println!("skipped: postgresql not installed");
        return;
    };
    let tmp = tempfile::tempdir().unwrap();
    let url = pg.url();
    let o = ratecal(&["archive", "check", "--archive", &url], tmp.path());
    assert_eq!(code(&o), 0, "{}", text(&o));
    concurrent_numbering(tmp.path(), &url);
}

/// Four approved runs in `archive`, three concurrent `certificate` processes per run: one
/// number per run, four distinct, `PREFIX-YYYY-000001` to `000004`; an amendment takes the
/// fifth and names the one it replaces.
fn concurrent_numbering(dir: &Path, archive: &str) {
    let station = certified_station("2099-12-31");
    // One run, approved into four different folders (four archive ids).
    mini(dir, "r0", &station, true);
    let runs = ["r0", "r1", "r2", "r3"];
    if archive != "archive" {
        let o = ratecal(&["archive", "add", "r0", "--archive", archive], dir);
        assert_eq!(code(&o), 0, "{}", text(&o));
    }
    for (i, r) in runs.iter().enumerate().skip(1) {
        copy_dir(&dir.join("r0"), &dir.join(r));
        let o = ratecal(
            &[
                "approve",
                r,
                "--signer",
                &format!("Signer {i}"),
                "--role",
                "Engineer",
                "--key",
                "keys/lab.key",
            ],
            dir,
        );
        assert_eq!(code(&o), 0, "{}", text(&o));
        let o = ratecal(&["archive", "add", r, "--archive", archive], dir);
        assert_eq!(code(&o), 0, "{}", text(&o));
    }
    // Three processes per run, all at once.
    let lab = lab_in(dir);
    let children: Vec<(usize, std::process::Child)> = (0..12)
        .map(|i| {
            let child = Command::new(env!("CARGO_BIN_EXE_ratecal"))
                .args([
                    "certificate",
                    runs[i % 4],
                    "--lab",
                    &lab,
                    "--archive",
                    archive,
                    "--format",
                    "json",
                ])
                .current_dir(dir)
                .env_remove("RATECAL_ARCHIVE")
                .stdout(std::process::Stdio::piped())
                .stderr(std::process::Stdio::piped())
                .spawn()
                .unwrap();
            (i % 4, child)
        })
        .collect();
    let mut by_run: Vec<std::collections::BTreeSet<String>> = vec![Default::default(); 4];
    for (r, child) in children {
        let o = child.wait_with_output().unwrap();
        assert_eq!(code(&o), 0, "{}", text(&o));
        by_run[r].insert(json_of(&o)["number"].as_str().unwrap().to_string());
    }
    for set in &by_run {
        assert_eq!(set.len(), 1, "one run, one number: {set:?}");
    }
    let all: std::collections::BTreeSet<&String> = by_run.iter().flatten().collect();
    assert_eq!(all.len(), 4, "no two runs share a number: {by_run:?}");
    let year = &ratecal_recording::rfc3339(std::time::SystemTime::now())[..4];
    let expected: std::collections::BTreeSet<String> =
        (1..=4).map(|n| format!("EICL-{year}-{n:06}")).collect();
    assert_eq!(
        all.into_iter()
            .cloned()
            .collect::<std::collections::BTreeSet<_>>(),
        expected
    );

    // An amendment: the next number, naming the one it replaces.
    let old = by_run[0].iter().next().unwrap().clone();
    let cert = |extra: &[&str]| {
        let mut args = vec!["certificate", "r0", "--lab", &lab, "--archive", archive];
        args.extend_from_slice(extra);
        ratecal(&args, dir)
    };
    let o = cert(&[
        "--format",
        "json",
        "--amend",
        "--reason",
        "the serial was misprinted",
    ]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let j = json_of(&o);
    assert_eq!(j["number"], format!("EICL-{year}-000005").as_str());
    assert_eq!(j["replaces"], old.as_str());
    assert_eq!(j["amend_reason"], "the serial was misprinted");
    let o = cert(&["--format", "md"]);
    let md = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(
        md.contains(&format!("EICL-{year}-000005"))
            && md.contains(&format!("replaces certificate No. {old}")),
        "{md}"
    );
}

pub(crate) fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        let target = to.join(e.file_name());
        if e.file_type().unwrap().is_dir() {
            copy_dir(&e.path(), &target);
        } else {
            std::fs::copy(e.path(), target).unwrap();
        }
    }
}

/// `logo` in LAB.yaml: a path relative to the lab file; a missing or non-image file is
/// refused at the key (exit 1); a PNG is drawn on every page of the PDF.
#[test]
fn a_logo_that_cannot_be_read_is_refused_at_its_key() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    mini(dir, "run", &certified_station("2099-12-31"), false);
    let base = std::fs::read_to_string(lab()).unwrap();
    std::fs::create_dir_all(dir.join("lab")).unwrap();
    let with_logo = |logo: &str| {
        let path = dir.join("lab/lab.yaml");
        std::fs::write(&path, format!("{base}logo: {logo}\n")).unwrap();
        let lab = path.display().to_string();
        ratecal(
            &[
                "certificate",
                "run",
                "--lab",
                &lab,
                "--archive",
                "archive",
                "--format",
                "json",
            ],
            dir,
        )
    };
    let o = with_logo("missing.png");
    assert_eq!(code(&o), 1, "{}", text(&o));
    let t = flat(&text(&o));
    let line = base.lines().count() + 1;
    assert!(t.contains("the logo `missing.png` cannot be used"), "{t}");
    assert!(t.contains(&format!("lab.yaml:{line}:")), "{t}");
    assert!(t.contains("PNG or JPEG"), "{t}");
    std::fs::write(dir.join("lab/notes.png"), "not an image").unwrap();
    let o = with_logo("notes.png");
    assert_eq!(code(&o), 1, "{}", text(&o));
    assert!(
        text(&o).contains("neither a PNG nor a JPEG"),
        "{}",
        text(&o)
    );
    // A truncated PNG: the signature alone is not enough, the logo must decode.
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    png.extend_from_slice(&[0; 16]);
    std::fs::write(dir.join("lab/broken.png"), png).unwrap();
    let o = with_logo("broken.png");
    assert_eq!(code(&o), 1, "{}", text(&o));
    assert!(text(&o).contains("not a readable PNG"), "{}", text(&o));
    // A real PNG (written by the png crate, with an alpha channel) beside the lab file: the
    // path is relative to it, not to the working folder. The PDF draws it on every page.
    let (w, h) = (40u32, 16u32);
    let mut bytes = Vec::new();
    {
        let mut e = png::Encoder::new(&mut bytes, w, h);
        e.set_color(png::ColorType::Rgba);
        e.set_depth(png::BitDepth::Eight);
        let mut writer = e.write_header().unwrap();
        let pixels: Vec<u8> = (0..w * h)
            .flat_map(|i| [(i % 251) as u8, 40, 200, if i % 2 == 0 { 255 } else { 0 }])
            .collect();
        writer.write_image_data(&pixels).unwrap();
    }
    std::fs::write(dir.join("lab/logo.png"), &bytes).unwrap();
    let o = with_logo("logo.png");
    assert_eq!(code(&o), 0, "{}", text(&o));
    let lab = dir.join("lab/lab.yaml").display().to_string();
    let o = ratecal(
        &[
            "certificate",
            "run",
            "--lab",
            &lab,
            "--archive",
            "archive",
            "--out",
            "c.pdf",
        ],
        dir,
    );
    assert_eq!(code(&o), 0, "{}", text(&o));
    let doc = lopdf::Document::load(dir.join("c.pdf")).unwrap();
    let pages = doc.get_pages();
    assert!(!pages.is_empty());
    for (n, page) in pages {
        let (res, ids) = doc.get_page_resources(page).unwrap();
        let xobjects: Vec<&lopdf::Dictionary> = res
            .into_iter()
            .chain(ids.iter().filter_map(|id| doc.get_dictionary(*id).ok()))
            .filter_map(|r| r.get(b"XObject").ok())
            .filter_map(|x| match x {
                lopdf::Object::Reference(id) => doc.get_dictionary(*id).ok(),
                o => o.as_dict().ok(),
            })
            .collect();
        let image = xobjects
            .iter()
            .flat_map(|x| x.iter())
            .filter_map(|(_, v)| {
                doc.get_object(v.as_reference().ok()?)
                    .ok()?
                    .as_stream()
                    .ok()
            })
            .find(|s| s.dict.get(b"Subtype").and_then(|o| o.as_name()).ok() == Some(b"Image"))
            .unwrap_or_else(|| panic!("page {n} draws no image"));
        assert_eq!(
            image.dict.get(b"Width").unwrap().as_i64().unwrap(),
            i64::from(w)
        );
        assert_eq!(
            image.dict.get(b"Height").unwrap().as_i64().unwrap(),
            i64::from(h)
        );
        assert!(
            image.dict.get(b"SMask").is_ok(),
            "the alpha channel is a soft mask"
        );
        let content = String::from_utf8_lossy(&doc.get_page_content(page).unwrap()).into_owned();
        assert!(content.contains("Do"), "page {n} never draws the logo");
    }
}

// -- issue 37 item 2: the number bound to its content ------------------------------------

/// `PREFIX-YYYY-NNNNNN` of the example lab for sequence number `n`, this year.
pub(crate) fn numbered(n: u32) -> String {
    let year = &ratecal_recording::rfc3339(std::time::SystemTime::now())[..4];
    format!("EICL-{year}-{n:06}")
}

/// `args` then `more`.
pub(crate) fn with<'a>(args: &[&'a str], more: &[&'a str]) -> Vec<&'a str> {
    [args, more].concat()
}

/// `ratecal certificate verify PDF --archive archive` in `dir`.
fn verify_pdf(dir: &Path, pdf: &str) -> Output {
    ratecal(&["certificate", "verify", pdf, "--archive", "archive"], dir)
}

/// The help of a diagnostic, read unwrapped (miette wraps long help lines).
pub(crate) fn unwrapped(o: &Output) -> String {
    flat(&text(o)).replace("- ", "-")
}

/// Approves `name` in `dir` with the key `keys/lab.key` (made when missing), the key of
/// the signer [`lab_in`] lists.
pub(crate) fn approve(dir: &Path, name: &str) {
    if !dir.join("keys/lab.key").exists() {
        let o = ratecal(&["key", "new", "keys"], dir);
        assert_eq!(code(&o), 0, "{}", text(&o));
    }
    let o = ratecal(
        &[
            "approve",
            name,
            "--signer",
            "A. Metrologist",
            "--role",
            "Head of laboratory",
            "--key",
            "keys/lab.key",
        ],
        dir,
    );
    assert_eq!(code(&o), 0, "{}", text(&o));
}

#[test]
fn an_identical_reissue_gets_the_same_number_and_a_byte_identical_pdf() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    mini(dir, "run", &certified_station("2099-12-31"), true);
    let who = ["--customer", "ACME Avionics", "--order", "PO-4711"];
    let o = certificate(dir, "run", &with(&who, &["--out", "first.pdf"]));
    assert_eq!(code(&o), 0, "{}", text(&o));
    // Another format first, then the PDF again: the number and the bytes are the same.
    let o = certificate(dir, "run", &with(&who, &["--format", "json"]));
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert_eq!(json_of(&o)["number"], numbered(1).as_str());
    let o = certificate(dir, "run", &with(&who, &["--out", "again.pdf"]));
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert!(text(&o).contains("reissued"), "{}", text(&o));
    let first = std::fs::read(dir.join("first.pdf")).unwrap();
    let again = std::fs::read(dir.join("again.pdf")).unwrap();
    assert!(first == again, "a reissue is not byte-identical");
    // And it is the document the archive recorded under the number.
    let o = verify_pdf(dir, "again.pdf");
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert!(text(&o).contains(&numbered(1)), "{}", text(&o));
}

#[test]
fn other_content_under_an_issued_number_is_refused_with_help_naming_amend_and_reason() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    mini(dir, "run", &certified_station("2099-12-31"), true);
    let who = ["--customer", "ACME Avionics", "--order", "PO-4711"];
    let o = certificate(dir, "run", &with(&who, &["--out", "c.pdf"]));
    assert_eq!(code(&o), 0, "{}", text(&o));
    let others: [&[&str]; 3] = [
        &["--customer", "Other Corp", "--order", "PO-4711"],
        &["--customer", "ACME Avionics", "--order", "PO-9999"],
        &[],
    ];
    for other in others {
        let o = certificate(dir, "run", &with(other, &["--out", "other.pdf"]));
        assert_eq!(code(&o), 1, "{other:?}: {}", text(&o));
        let t = unwrapped(&o);
        assert!(t.contains(&numbered(1)), "{t}");
        assert!(t.contains("help"), "{t}");
        assert!(t.contains("--amend --reason"), "{t}");
        assert!(!dir.join("other.pdf").exists(), "{other:?} wrote a PDF");
        assert!(!dir.join(".other.pdf.partial").exists());
    }
    // The number still belongs to what was issued under it.
    let o = certificate(dir, "run", &with(&who, &["--format", "json"]));
    assert_eq!(code(&o), 0, "{}", text(&o));
    let j = json_of(&o);
    assert_eq!(j["number"], numbered(1).as_str());
    assert_eq!(j["identification"]["customer"], "ACME Avionics");
}

#[test]
fn an_amendment_needs_a_reason_takes_a_new_number_and_names_the_one_it_replaces() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    mini(dir, "run", &certified_station("2099-12-31"), true);
    let o = certificate(
        dir,
        "run",
        &[
            "--customer",
            "ACME",
            "--order",
            "PO-1",
            "--out",
            "first.pdf",
        ],
    );
    assert_eq!(code(&o), 0, "{}", text(&o));
    let amended = ["--customer", "ACME Avionics", "--order", "PO-1"];
    // No reason: refused, with help; nothing taken.
    let o = certificate(
        dir,
        "run",
        &with(&amended, &["--amend", "--format", "json"]),
    );
    assert_eq!(code(&o), 1, "{}", text(&o));
    assert!(unwrapped(&o).contains("--amend --reason"), "{}", text(&o));
    // A reason without --amend: a usage error.
    let o = certificate(dir, "run", &with(&amended, &["--reason", "why"]));
    assert_eq!(code(&o), 2, "{}", text(&o));
    let reason = "customer name incomplete";
    let o = certificate(
        dir,
        "run",
        &with(
            &amended,
            &["--amend", "--reason", reason, "--out", "amended.pdf"],
        ),
    );
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert!(text(&o).contains(&numbered(2)), "{}", text(&o));
    // Reissued: the amendment keeps its number, the one it replaces and its reason.
    let o = certificate(dir, "run", &with(&amended, &["--format", "json"]));
    assert_eq!(code(&o), 0, "{}", text(&o));
    let j = json_of(&o);
    assert_eq!(
        j["number"],
        numbered(2).as_str(),
        "the refusal burned a number"
    );
    assert_eq!(j["replaces"], numbered(1).as_str());
    assert_eq!(j["amend_reason"], reason);
    let md = certificate(dir, "run", &with(&amended, &["--format", "md"]));
    assert_eq!(code(&md), 0, "{}", text(&md));
    let md = flat(&String::from_utf8_lossy(&md.stdout));
    assert!(
        md.contains(&format!(
            "replaces certificate No. {} (reason: {reason})",
            numbered(1)
        )),
        "{md}"
    );
    if let Some(pages) = pdf_pages(&std::fs::read(dir.join("amended.pdf")).unwrap()) {
        let all = flat(&pages.join("\n"));
        assert!(
            all.contains(&format!("Certificate No. {}", numbered(2))),
            "{all}"
        );
        assert!(all.contains(&numbered(1)) && all.contains(reason), "{all}");
    }
    // Both PDFs are the archive's; the first says it was replaced.
    let o = verify_pdf(dir, "amended.pdf");
    assert_eq!(code(&o), 0, "{}", text(&o));
    let o = verify_pdf(dir, "first.pdf");
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert!(
        text(&o).contains(&format!("replaced by certificate No. {}", numbered(2))),
        "{}",
        text(&o)
    );
}

/// The crash harness's amendment (issue 38, item 6): `certificate --amend` stopped as
/// abruptly as a kill before it delivers and before it records, five times, burns no number
/// and leaves no document at `--out`; the amendment that then completes takes the next
/// number and replaces the certificate that was issued, not one nobody received.
#[test]
fn killed_amendments_burn_no_number_and_leave_no_document() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    mini(dir, "run", &certified_station("2099-12-31"), true);
    let first = ["--customer", "ACME", "--order", "PO-1"];
    let o = certificate(dir, "run", &with(&first, &["--out", "first.pdf"]));
    assert_eq!(code(&o), 0, "{}", text(&o));
    let lab = lab_in(dir);
    let amend = [
        "certificate",
        "run",
        "--lab",
        lab.as_str(),
        "--archive",
        "archive",
        "--customer",
        "ACME Avionics",
        "--order",
        "PO-1",
        "--amend",
        "--reason",
        "customer name incomplete",
        "--out",
        "amended.pdf",
    ];
    for point in [
        "certificate-before-deliver",
        "certificate-before-record",
        "certificate-before-record",
        "certificate-before-deliver",
        "certificate-before-record",
    ] {
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_ratecal"))
            .args(amend)
            .current_dir(dir)
            .env("RATECAL_CRASH_AT", point)
            .output()
            .unwrap();
        assert_ne!(code(&o), 0, "{point} did not stop it: {}", text(&o));
        assert!(
            !dir.join("amended.pdf").exists(),
            "a document without a recorded number appeared at --out ({point})"
        );
        // The certificate in force is still the first.
        let o = certificate(dir, "run", &with(&first, &["--format", "json"]));
        assert_eq!(code(&o), 0, "{point}: {}", text(&o));
        assert_eq!(json_of(&o)["number"], numbered(1).as_str(), "{point}");
    }
    let o = ratecal(&amend, dir);
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert!(
        text(&o).contains(&numbered(2)),
        "a killed amendment burned a number: {}",
        text(&o)
    );
    let o = verify_pdf(dir, "amended.pdf");
    assert_eq!(code(&o), 0, "{}", text(&o));
    let o = verify_pdf(dir, "first.pdf");
    assert!(
        text(&o).contains(&format!("replaced by certificate No. {}", numbered(2))),
        "{}",
        text(&o)
    );
    // No partial document is left beside the delivered one.
    let left: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".partial"))
        .collect();
    assert!(left.is_empty(), "{left:?}");
}

#[test]
fn a_draft_and_a_dry_run_specimen_take_no_number() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let station = certified_station("2099-12-31");
    // A draft: not approved.
    mini(dir, "draft", &station, false);
    let o = certificate(dir, "draft", &["--format", "json"]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let j = json_of(&o);
    assert!(j["number"].is_null(), "a draft took {}", j["number"]);
    assert_eq!(j["draft"], true);
    assert_eq!(j["specimen"], false);
    let o = certificate(dir, "draft", &["--out", "draft.pdf"]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    if let Some(pages) = pdf_pages(&std::fs::read(dir.join("draft.pdf")).unwrap()) {
        for p in &pages {
            assert!(flat(p).contains("Certificate No. DRAFT"), "{p}");
        }
    }
    // A draft amends nothing.
    let o = certificate(dir, "draft", &["--amend", "--reason", "why"]);
    assert_eq!(code(&o), 1, "{}", text(&o));
    assert!(unwrapped(&o).contains("help"), "{}", text(&o));

    // A dry run, approved: a specimen, marked on every page, the first included.
    let o = mini_run(dir, "dry", &["--station", "s.yaml"]);
    assert!(matches!(code(&o), 0 | 3), "{}", text(&o));
    approve(dir, "dry");
    let o = ratecal(&["archive", "add", "dry", "--archive", "archive"], dir);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let o = certificate(dir, "dry", &["--format", "json"]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let j = json_of(&o);
    assert!(j["number"].is_null(), "a dry run took {}", j["number"]);
    assert_eq!(j["specimen"], true);
    assert_eq!(j["draft"], false);
    let o = certificate(dir, "dry", &["--out", "dry.pdf"]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    if let Some(pages) = pdf_pages(&std::fs::read(dir.join("dry.pdf")).unwrap()) {
        for p in &pages {
            assert!(flat(p).contains("DRY RUN - SPECIMEN"), "{p}");
            assert!(!flat(p).contains("DRAFT"), "{p}");
        }
    }
    // A dry run not approved carries both markings.
    let o = mini_run(dir, "dry2", &["--station", "s.yaml"]);
    assert!(matches!(code(&o), 0 | 3), "{}", text(&o));
    let o = ratecal(&["archive", "add", "dry2", "--archive", "archive"], dir);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let o = certificate(dir, "dry2", &["--format", "md"]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let md = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(
        md.contains("DRY RUN - SPECIMEN") && md.contains("DRAFT - not approved"),
        "{md}"
    );

    // Neither burned a number: the first approved real run takes the first.
    mini(dir, "real", &station, true);
    let o = certificate(dir, "real", &["--format", "json"]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert_eq!(json_of(&o)["number"], numbered(1).as_str());
}

#[test]
fn certificate_verify_accepts_an_issued_pdf_and_refuses_an_altered_copy() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    mini(dir, "run", &certified_station("2099-12-31"), true);
    let o = certificate(dir, "run", &["--customer", "ACME", "--out", "c.pdf"]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let o = verify_pdf(dir, "c.pdf");
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert!(text(&o).contains(&numbered(1)), "{}", text(&o));
    assert!(text(&o).contains("unaltered"), "{}", text(&o));

    let bytes = std::fs::read(dir.join("c.pdf")).unwrap();
    // One byte changed in the middle of the file.
    let mut altered = bytes.clone();
    let mid = altered.len() / 2;
    altered[mid] ^= 0x01;
    std::fs::write(dir.join("altered.pdf"), &altered).unwrap();
    // A line appended (as an incremental update would).
    let mut appended = bytes.clone();
    appended.extend_from_slice(b"\n% edited\n");
    std::fs::write(dir.join("appended.pdf"), &appended).unwrap();
    for name in ["altered.pdf", "appended.pdf"] {
        let o = verify_pdf(dir, name);
        assert_eq!(code(&o), 1, "{name}: {}", text(&o));
        let t = unwrapped(&o);
        assert!(t.contains("altered") && t.contains("help"), "{t}");
    }
    // A draft was never issued under a number: not the archive's.
    mini(dir, "draft", &certified_station("2099-12-31"), false);
    let o = certificate(dir, "draft", &["--out", "d.pdf"]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let o = verify_pdf(dir, "d.pdf");
    assert_eq!(code(&o), 1, "{}", text(&o));
    // A file that is not there: exit 1 with help, no panic.
    let o = verify_pdf(dir, "missing.pdf");
    assert_eq!(code(&o), 1, "{}", text(&o));
    assert!(unwrapped(&o).contains("help"), "{}", text(&o));
}
