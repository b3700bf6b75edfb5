//! Snapshot of every bundled template against the fixed fixtures, plus the properties a
//! report must have whatever its styling: the full hash, the dry-run banner, each section.

use crate::render_common;
use ratecal_render::{Format, Templates, render, render_all};
use render_common::{foreign, full, minimal};

const SHA: &str = "9f2c4e1ab7d35c08e6f1a2b3c4d5e6f708192a3b4c5d6e7f8091a2b3c4d5e6f7";
const STATION_SHA: &str = "3b1d0f9e8c7a6b5d4e3f2a1b0c9d8e7f6a5b4c3d2e1f0a9b8c7d6e5f4a3b2c1d";

#[test]
fn markdown_full_snapshot() {
    let md = render(&full(), &Templates::bundled(), Format::Markdown).unwrap();
    insta::assert_snapshot!("markdown_full", md);
}

#[test]
fn html_full_snapshot() {
    let html = render(&full(), &Templates::bundled(), Format::Html).unwrap();
    insta::assert_snapshot!("html_full", html);
}

#[test]
fn markdown_foreign_snapshot() {
    let md = render(&foreign(), &Templates::bundled(), Format::Markdown).unwrap();
    insta::assert_snapshot!("markdown_foreign", md);
}

#[test]
fn html_foreign_snapshot() {
    let html = render(&foreign(), &Templates::bundled(), Format::Html).unwrap();
    insta::assert_snapshot!("html_foreign", html);
}

#[test]
fn every_section_of_the_seed_is_present() {
    for r in render_all(&full(), &Templates::bundled()).unwrap() {
        for heading in [
            "Traceability",
            "1. Calibration object",
            "2. Calibration equipment",
            "3. Environmental conditions",
            "4. Calibration process",
            "5. Results",
            "Residual analysis",
            "Repeatability",
            "Accuracy verification",
            "Acceptance checks",
            "6. Conclusions and recommendations",
            "Equipment maintenance",
        ] {
            assert!(
                r.text.contains(heading),
                "{} lacks {heading:?}",
                r.file_name
            );
        }
        // Traceability: hashes in full, never abbreviated; run id, operator, dates, version.
        assert!(
            r.text.contains(SHA) && r.text.contains(STATION_SHA),
            "{}",
            r.file_name
        );
        for s in [
            "2026-11-20T09-00-00Z-imu-2d-standard",
            "A. Operator",
            "2026-11-20T09:14:27Z",
            "0.1.0",
        ] {
            assert!(r.text.contains(s), "{} lacks {s}", r.file_name);
        }
        assert!(
            r.text.contains("DRY RUN: NOT A CALIBRATION CERTIFICATE"),
            "{}",
            r.file_name
        );
        // Object and equipment, from the manifest including keys the typed manifest ignores.
        for s in ["TAC-440", "SN-00172", "Example Inertial", "Acme DRT-200"] {
            assert!(r.text.contains(s), "{} lacks {s}", r.file_name);
        }
        // Every acceptance check with value, limit, uncertainty and verdict; the overall
        // verdict is the worst one (gyro.error failed).
        for s in [
            "accel.residual.std",
            "gyro.bias.std",
            "gyro.error",
            "INDETERMINATE",
            "NOT EVALUATED",
        ] {
            assert!(r.text.contains(s), "{} lacks {s}", r.file_name);
        }
        assert!(
            r.text.contains("do not meet the standard"),
            "{}",
            r.file_name
        );
        assert!(
            r.text.contains("gyro.scale.z"),
            "unobservable parameter named"
        );
        assert!(
            r.text.contains("12 months"),
            "recalibration interval from the plan's meta"
        );
    }
}

#[test]
fn dry_run_banner_comes_before_anything_else() {
    let html = render(&full(), &Templates::bundled(), Format::Html).unwrap();
    let body = html.find("<body>").unwrap();
    let banner = html.find("id=\"dry-run\"").unwrap();
    let h1 = html.find("<h1>").unwrap();
    assert!(body < banner && banner < h1);
    let md = render(&full(), &Templates::bundled(), Format::Markdown).unwrap();
    assert!(md.trim_start().starts_with("> **DRY RUN"));
}

#[test]
fn a_real_run_has_no_banner_and_a_foreign_one_says_so() {
    let mut input = full();
    input.manifest.as_mut().unwrap()["run"]["dry_run"] = serde_json::json!(false);
    let html = render(&input, &Templates::bundled(), Format::Html).unwrap();
    assert!(!html.contains("DRY RUN"));
    assert!(html.contains("measurement"));
    let md = render(&foreign(), &Templates::bundled(), Format::Markdown).unwrap();
    assert!(!md.contains("DRY RUN"));
    assert!(md.contains("recording from another acquisition system"));
    assert!(md.contains("Environmental conditions: not recorded"));
}

#[test]
fn html_carries_every_plot_inline() {
    let html = render(&full(), &Templates::bundled(), Format::Html).unwrap();
    // Residuals (accel, gyro), rate fit, Allan, temperature, one finding (a figure of one
    // panel per channel: an `<svg>` inside its own).
    assert_eq!(html.matches("<svg xmlns").count(), 6);
    for title in [
        "Accelerometer residuals",
        "Gyroscope residuals",
        "Gyro rate-point fit",
        "Allan deviation of the static block",
        "Temperature over the run",
        "Residuals before and after",
    ] {
        assert!(
            html.contains(&format!("<title>{title}")),
            "missing plot {title}"
        );
    }
    // Self-contained: no external resources.
    for s in ["src=\"http", "href=\"http", "<script src", "<link "] {
        assert!(!html.contains(s), "external resource {s}");
    }
    // Plots are inserted unescaped; text values are escaped.
    assert!(!html.contains("&lt;svg"));
}

#[test]
fn foreign_recording_plots_what_it_has() {
    let html = render(&foreign(), &Templates::bundled(), Format::Html).unwrap();
    // Residuals (accel, gyro), rate-point residuals, Allan; no temperature series, no findings.
    assert_eq!(html.matches("<svg ").count(), 4);
    // No findings section at all: never a "No findings." beside a warning that points at
    // explain.
    assert!(!html.contains("No findings.") && !html.contains("id=\"findings\""));
    assert!(!html.contains("<title>Temperature"));
}

#[test]
fn minimal_results_without_manifest_still_make_a_report() {
    for r in render_all(&minimal(), &Templates::bundled()).unwrap() {
        assert!(
            r.text.contains("6. Conclusions and recommendations"),
            "{}",
            r.file_name
        );
        assert!(r.text.contains("not recorded"), "{}", r.file_name);
        assert!(
            r.text.contains("cannot be declared to meet the standard"),
            "{}",
            r.file_name
        );
        assert!(!r.text.contains("DRY RUN"), "{}", r.file_name);
    }
}

/// A failed sanity check: the report says the recording is not fit for judgment, names
/// the check in the verdict line, the sanity table and the conclusions, and does not tell
/// the reader the results meet (or miss) the standard.
#[test]
fn a_failed_sanity_check_is_not_fit_for_judgment() {
    let mut input = foreign();
    input.results["verdict"] = "incomplete".into();
    input.results["verdict_reason"] =
        "the recording is not fit for judgment: sanity check gravity_magnitude_at_rest failed"
            .into();
    input.results["sanity"] = serde_json::json!([
        { "check": "gravity_magnitude_at_rest", "status": "fail",
          "detail": "segment accel_static/1: |specific force| 1.0009 m/s^2" },
        { "check": "gyro_at_rest", "status": "pass", "detail": "worst segment ..." }
    ]);
    for format in [Format::Markdown, Format::Html] {
        let text = render(&input, &Templates::bundled(), format).unwrap();
        assert!(
            text.contains(
                "INCOMPLETE</span>: the recording is not fit for judgment: sanity check gravity_magnitude_at_rest failed"
            ) || text.contains(
                "**INCOMPLETE**: the recording is not fit for judgment: sanity check gravity_magnitude_at_rest failed"
            ),
            "{format:?}"
        );
        assert!(text.contains("not fit for judgment</strong>: sanity check <code>gravity_magnitude_at_rest</code> failed")
            || text.contains("**not fit for judgment**: sanity check `gravity_magnitude_at_rest` failed"), "{format:?}");
        assert!(!text.contains("meet the standard"), "{format:?}");
        assert!(!text.contains("PASS"), "{format:?}");
    }
}
