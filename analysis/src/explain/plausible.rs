//! Physically plausible ranges: the largest magnitude a real part, consumer to navigation
//! grade, shows for each parameter (a lever arm of metres, a time offset of seconds or a
//! misalignment of radians is not a calibration result). The registry gives each
//! parameter its range (`Param::max_abs`, docs/effects.md); the probe library's forms
//! have theirs (`probe::range`), scaled by the IMU's grade. Explain does not report an
//! effect whose fit lands outside, and does not fit one whose range the recording cannot
//! resolve (`observe`).

use ratecal_physics::effects::Param;

/// The largest plausible magnitude of parameter `p`, in the parameter's unit; `None` when
/// no bound applies (a user effect's own units).
pub(crate) fn max_abs(p: &Param) -> Option<f64> {
    p.max_abs.is_finite().then_some(p.max_abs)
}

/// The factor on a library form's consumer-grade range for the IMU grade the manifest
/// states (`imu: { grade: ... }`); a missing or unknown grade keeps the consumer range.
/// Generous on purpose: a range is the largest magnitude a part of the grade shows, and a
/// tactical part's thermal scale coefficient of 120 ppm/degC is real.
pub(crate) fn grade_scale(grade: Option<&str>) -> f64 {
    match grade.map(|g| g.trim().to_ascii_lowercase()).as_deref() {
        Some("navigation") | Some("strategic") => 0.1,
        Some("tactical") => 0.3,
        Some("industrial") | Some("automotive") => 0.5,
        _ => 1.0,
    }
}
