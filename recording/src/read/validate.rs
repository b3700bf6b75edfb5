//! The manifest's station and segment numbers, checked for what no real station can have:
//! a recording from another acquisition system with a NaN gravity or a mistyped axis is
//! refused where the value is written, rather than analysed into NaN results.

// A refused manifest is built once per read: the error's size costs nothing.
#![allow(clippy::result_large_err)]

use super::locate::{find_segment, locate};
use crate::error::{RecordingError, line_col};
use crate::excerpt::Excerpt;
use crate::{Manifest, Mount};
use ratecal_physics::{Mat3, check_rotation};

/// Tolerance on unit vectors and on the orthonormality of a mount.
const UNIT_TOL: f64 = 1e-3;

/// Checks the station block and each segment's numbers (`text` is the manifest's text,
/// `file` its name).
pub(crate) fn manifest(file: &str, text: &str, m: &Manifest) -> Result<(), RecordingError> {
    let at = |key: &str, from: usize, problem: String, help: &str| {
        let (offset, len) = locate(text, key, from);
        let (line, column) = line_col(text, offset);
        RecordingError::BadStation {
            file: file.to_string(),
            line,
            column,
            problem,
            help: help.to_string(),
            src: Excerpt::around(file, text.as_bytes(), offset, offset + len).0,
            span: Excerpt::around(file, text.as_bytes(), offset, offset + len).1,
        }
    };
    let station = text.find("station").unwrap_or(0);
    let site = &m.station.site;
    if !(site.latitude_deg.is_finite() && site.latitude_deg.abs() <= 90.0) {
        return Err(at(
            "latitude_deg",
            station,
            format!("latitude {} deg is not on the Earth", site.latitude_deg),
            "the site's latitude in degrees, -90 .. 90, north positive",
        ));
    }
    let g = site.gravity_mps2;
    if !(g.is_finite() && (9.7..=9.9).contains(&g)) {
        return Err(at(
            "gravity_mps2",
            station,
            format!("gravity {g} m/s^2 is not the Earth's"),
            "local gravity in m/s^2: on the Earth's surface it lies between 9.78 and 9.84",
        ));
    }
    for (key, v) in [
        ("outer_axis", m.station.table.outer_axis),
        ("inner_axis", m.station.table.inner_axis),
    ] {
        let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        if !(norm.is_finite() && (norm - 1.0).abs() <= UNIT_TOL) {
            return Err(at(
                key,
                station,
                format!("{key} {v:?} is not a unit vector (length {norm})"),
                "a table axis is a unit vector in the lab frame (ENU), e.g. [0, -1, 0]",
            ));
        }
    }
    if let Some(problem) = m.station.mount.as_ref().and_then(not_a_rotation) {
        return Err(at("rotation", station, problem, MOUNT_HELP));
    }
    let mut from = text.find("segments").unwrap_or(0);
    for seg in &m.segments {
        from = find_segment(text, &seg.id, from);
        if let Some(problem) = seg.mount.as_ref().and_then(not_a_rotation) {
            return Err(at("rotation", from, problem, MOUNT_HELP));
        }
        let numbers = [
            ("rate_dps", seg.rate_dps),
            ("amplitude_deg", seg.amplitude_deg),
            ("period_s", seg.period_s),
            ("center_deg", seg.center_deg),
            ("pitch_deg", seg.pitch_deg),
            ("roll_deg", seg.roll_deg),
        ];
        for (key, v) in numbers {
            let Some(v) = v else { continue };
            let positive = key != "period_s" || v > 0.0;
            if !(v.is_finite() && positive) {
                return Err(at(
                    key,
                    from,
                    format!("segment `{}`: {key} {v} is not a value it can have", seg.id),
                    "a finite number in the unit its name gives (period_s above 0)",
                ));
            }
        }
    }
    Ok(())
}

const MOUNT_HELP: &str =
    "C_PB, row-major: a proper rotation (orthonormal rows, determinant +1), identity if absent";

/// Why a mount matrix is not a proper rotation, if it is not.
fn not_a_rotation(m: &Mount) -> Option<String> {
    let r = Mat3::from_fn(|i, j| m.rotation[i][j]);
    check_rotation(&r, UNIT_TOL)
        .err()
        .map(|why| format!("the mount rotation {why}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotations_proper_and_not() {
        let m = |rotation| Mount { rotation };
        let id = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        assert_eq!(not_a_rotation(&m(id)), None);
        let yaw90 = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
        assert_eq!(not_a_rotation(&m(yaw90)), None);
        let mirror = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]];
        assert!(not_a_rotation(&m(mirror)).unwrap().contains("reflection"));
        let scaled = [[1.01, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        assert!(not_a_rotation(&m(scaled)).unwrap().contains("orthonormal"));
        let nan = [[f64::NAN, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        assert!(not_a_rotation(&m(nan)).unwrap().contains("finite"));
    }
}
