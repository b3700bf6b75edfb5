//! Physically plausible ranges: the largest magnitude a real part, consumer to navigation
//! grade, shows for each parameter (a lever arm of metres, a time offset of seconds or a
//! misalignment of radians is not a calibration result). Explain does not report an effect
//! whose fit lands outside.

use ratecal_physics::effects::Param;

/// The largest plausible magnitude of parameter `p` of effect `id`, in the parameter's
/// unit; `None` when no bound applies (a user effect's own units).
pub(crate) fn max_abs(id: &str, p: &Param) -> Option<f64> {
    let _ = id;
    Some(match p.unit {
        "mm" => 300.0,
        "ms" => 1000.0,
        "s" => 1.0,
        "mrad" => 50.0,
        "deg/s per g" => 1.0,
        "ppm per deg/s" => 1000.0,
        "ug/g^2" => 10_000.0,
        "ppm" => 100_000.0,
        "ppm/degC" => 1000.0,
        "deg/h" => 60.0,
        _ => return None,
    })
}
