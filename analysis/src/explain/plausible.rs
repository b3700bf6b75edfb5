//! Physically plausible ranges: the largest magnitude a real part, consumer to navigation
//! grade, shows for each parameter (a lever arm of metres, a time offset of seconds or a
//! misalignment of radians is not a calibration result). The registry gives each
//! parameter its range (`Param::max_abs`, docs/effects.md); explain does not report an
//! effect whose fit lands outside.

use ratecal_physics::effects::Param;

/// The largest plausible magnitude of parameter `p`, in the parameter's unit; `None` when
/// no bound applies (a user effect's own units, a probe).
pub(crate) fn max_abs(p: &Param) -> Option<f64> {
    p.max_abs.is_finite().then_some(p.max_abs)
}
