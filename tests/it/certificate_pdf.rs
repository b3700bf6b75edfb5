//! The certificate as a laboratory's customer gets it: the binary (this build's, or the
//! release build named by `RATECAL_RELEASE_BIN`) issues a PDF whose text two readers that are not ours, poppler's
//! `pdftotext` and Python's `pypdf`, both read back with every element in order; the PDF is
//! PDF/A-2b with its fonts subset and embedded. Skipped, and saying so, only when
//! `pdftotext` or `pypdf` is not installed (`.ci/run` installs both).

use crate::support::{self, MINI, code, text};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Instant;

/// The binary under test: `RATECAL_RELEASE_BIN` when set (the release build, e.g.
/// `target/release/ratecal`: `cargo build --release` and set it to check the release build
/// the same way), else this test build's own `ratecal`. Typst typesets the same in both
/// profiles (printpdf compressed its streams only without debug assertions; nothing here
/// depends on them).
fn binary_under_test() -> PathBuf {
    std::env::var_os("RATECAL_RELEASE_BIN")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_BIN_EXE_ratecal")))
}

fn run(bin: &Path, args: &[&str], dir: &Path) -> Output {
    Command::new(bin)
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap()
}

/// What is missing of pdftotext and pypdf, if anything.
fn missing_tools() -> Vec<&'static str> {
    let mut missing = Vec::new();
    if Command::new("pdftotext").arg("-v").output().is_err() {
        missing.push("pdftotext (poppler-utils)");
    }
    let pypdf = Command::new("python3")
        .args(["-c", "import pypdf"])
        .output();
    if !pypdf.is_ok_and(|o| o.status.success()) {
        missing.push("pypdf (python3)");
    }
    missing
}

/// The PDF's text by pdftotext, pages separated by form feeds.
fn pdftotext(pdf: &Path) -> String {
    let o = Command::new("pdftotext")
        .args(["-raw", "-enc", "UTF-8"])
        .arg(pdf)
        .arg("-")
        .output()
        .unwrap();
    assert!(o.status.success(), "pdftotext: {}", text(&o));
    String::from_utf8(o.stdout).unwrap()
}

/// The PDF's text by pypdf, pages separated by form feeds.
fn pypdf(pdf: &Path) -> String {
    let script = "import sys, pypdf\n\
                  r = pypdf.PdfReader(sys.argv[1])\n\
                  sys.stdout.write('\\f'.join(p.extract_text() for p in r.pages))\n";
    let o = Command::new("python3")
        .args(["-c", script])
        .arg(pdf)
        .output()
        .unwrap();
    assert!(o.status.success(), "pypdf: {}", text(&o));
    String::from_utf8(o.stdout).unwrap()
}

/// Collapses whitespace, so that a phrase wrapped over two lines is still found.
fn flat(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// Finds each of `wanted` in `text`, each after the one before.
fn in_order(reader: &str, text: &str, wanted: &[String]) {
    let all = flat(text);
    let mut from = 0;
    for w in wanted {
        match all[from..].find(w.as_str()) {
            Some(i) => from += i + w.len(),
            None => panic!(
                "{reader}: `{w}` not found after byte {from} of the text: {}",
                &all[from.min(all.len())..]
            ),
        }
    }
}

/// A run of MINI with an acceptance check on the simulated station (not a dry run: its
/// certificate takes a number), approved and archived, in `dir/cal`.
fn approved_run(bin: &Path, dir: &Path) {
    let station = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/docs/examples/station.yaml"
    ))
    .unwrap()
    .replace("due: 2030-06-30", "due: 2099-12-31");
    std::fs::write(dir.join("s.yaml"), station).unwrap();
    let with_check = MINI.replacen(
        "  step statics",
        "  accept accel.bias.x <= 80 mg\n\n  step statics",
        1,
    );
    std::fs::write(dir.join("p.rcal"), with_check).unwrap();
    for args in [
        &["run", "p.rcal", "--station", "s.yaml", "--out", "cal"][..],
        &["key", "new", "keys"],
        &[
            "approve",
            "cal",
            "--signer",
            "A. Metrologist",
            "--role",
            "Head of laboratory",
            "--key",
            "keys/lab.key",
        ],
        &["archive", "add", "cal", "--archive", "archive"],
    ] {
        let o = run(bin, args, dir);
        assert!(matches!(code(&o), 0 | 3), "{args:?}: {}", text(&o));
    }
}

#[test]
fn a_certificate_reads_back_whole_and_in_order_in_pdftotext_and_pypdf() {
    let missing = missing_tools();
    if !missing.is_empty() {
        eprintln!("skipped: {} not installed", missing.join(" and "));
        return;
    }
    let bin = binary_under_test();
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    approved_run(&bin, dir);
    let lab = crate::certificate_cli::lab_in(dir);
    let lab = lab.as_str();
    let started = Instant::now();
    let o = run(
        &bin,
        &[
            "certificate",
            "cal",
            "--lab",
            lab,
            "--archive",
            "archive",
            "--customer",
            "ACME Avionics",
            "--order",
            "PO-4711",
            "--out",
            "cert.pdf",
        ],
        dir,
    );
    let took = started.elapsed();
    assert_eq!(code(&o), 0, "{}", text(&o));
    let pdf = dir.join("cert.pdf");
    let bytes = std::fs::read(&pdf).unwrap();
    eprintln!(
        "certificate: {:.3} s (whole process), PDF {} bytes",
        took.as_secs_f64(),
        bytes.len()
    );
    let results = support::json(&dir.join("cal/results.json"));
    let sha = results["model"]["procedure"]["sha256"].as_str().unwrap();
    let year = &ratecal_recording::rfc3339(std::time::SystemTime::now())[..4];
    let number = format!("EICL-{year}-000001");
    let poppler = pdftotext(&pdf);
    let pages = poppler
        .split('\u{c}')
        .filter(|p| !p.trim().is_empty())
        .count();
    assert!(pages >= 2, "{pages} pages");
    let header = |page: usize| -> Vec<String> {
        vec![
            "Example Inertial Calibration Laboratory".to_string(),
            "12 Gyroscope Lane, 2800 Kongens Lyngby, Denmark".into(),
            "Accredited to ISO/IEC 17025 by DANAK".into(),
            format!("Certificate No. {number}"),
            format!("page {page} of {pages}"),
        ]
    };
    let mut wanted: Vec<String> = [
        "Calibration certificate",
        "Identification",
        "ACME Avionics",
        "PO-4711",
        "IMU SIM-TAC-100",
        "SIM-0001",
        "tactical",
        "mini version 1.0.0",
        sha,
        "Example Motion Systems",
        "EMS-2A-0042",
        "Method and conditions",
        "Two static attitudes",
        "°C",
        "9.8156 m/s²",
        "Results",
        "value ± U",
        "accel.bias.x",
        "m/s² (k = ",
        "95 %",
        "Statements of conformity",
        "ILAC-G8",
        "accel.bias.x <= 80 mg",
        "Traceability",
        "NMI-2026-0815",
        "National Metrology Institute",
        "due 2099-12-31",
        "Approval",
        "A. Metrologist",
        "Head of laboratory",
        "SHA256",
        "Annex: uncertainty budget",
        "gyro.scale.y",
        "table rate accuracy",
        "rectangular",
        "This certificate shall not be reproduced except in full without the written \
         approval of the laboratory.",
    ]
    .map(String::from)
    .to_vec();
    wanted.push(format!("End of certificate {number}"));
    let check = |reader: &str, all: &str| {
        let each: Vec<&str> = all
            .split('\u{c}')
            .filter(|p| !p.trim().is_empty())
            .collect();
        assert_eq!(each.len(), pages, "{reader}'s pages");
        for (i, page) in each.iter().enumerate() {
            in_order(reader, page, &header(i + 1));
        }
        in_order(reader, all, &wanted);
    };
    check("pdftotext", &poppler);
    check("pypdf", &pypdf(&pdf));
    assert!(
        !flat(&poppler).contains("DRAFT"),
        "an approved certificate says DRAFT"
    );

    // PDF/A-2b, fonts subset and embedded (a subset's name carries a six-letter tag).
    let raw = String::from_utf8_lossy(&bytes);
    assert!(raw.contains("<pdfaid:part>2</pdfaid:part>"), "not PDF/A-2");
    assert!(raw.contains("<pdfaid:conformance>B</pdfaid:conformance>"));
    assert!(raw.contains("/FontFile2"), "no embedded TrueType font");
    assert!(
        raw.match_indices("+DejaVuSans").count() >= 1,
        "fonts not subset"
    );

    // Reissued with the same content: the same bytes.
    let again = run(
        &bin,
        &[
            "certificate",
            "cal",
            "--lab",
            lab,
            "--archive",
            "archive",
            "--customer",
            "ACME Avionics",
            "--order",
            "PO-4711",
            "--out",
            "again.pdf",
        ],
        dir,
    );
    assert_eq!(code(&again), 0, "{}", text(&again));
    assert!(
        std::fs::read(dir.join("again.pdf")).unwrap() == bytes,
        "not byte-identical"
    );
}
