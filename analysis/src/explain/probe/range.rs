//! Plausible ranges of the library's forms (docs/effects.md, "Plausible ranges"): the
//! largest magnitude a consumer part shows for a term of each form, in the form's unit
//! ([`Form::unit`]), before the IMU grade's scale ([`crate::explain::plausible::grade_scale`]).
//!
//! Where a form has registry physics of the same shape, the range is the registry's
//! (`accel_second_order`, the scale asymmetries, `g_sensitivity`, the scale's thermal
//! coefficient, `gyro_scale_nonlinearity`); a change with time is bounded by what the bias
//! or scale can change over the recording's span.

use super::Form;
use ratecal_physics::effects::Sensor;

/// Largest bias change of a consumer part within a recording: 100 mg, in ug.
const ACCEL_BIAS_CHANGE_UG: f64 = 1e5;
/// Largest gyro bias change of a consumer part within a recording: 1 deg/s, in deg/h.
const GYRO_BIAS_CHANGE_DPH: f64 = 3600.0;
/// Largest scale-factor change within a recording: 1 %, in ppm.
const SCALE_CHANGE_PPM: f64 = 1e4;

/// The consumer-grade range of a term of `form` on `sensor`, for a recording of `span_h`
/// hours (a drift's coefficient is bounded by the change it makes over the span).
pub(crate) fn max_abs(form: Form, sensor: Sensor, span_h: f64) -> f64 {
    let gyro = sensor == Sensor::Gyro;
    let bias = if gyro {
        GYRO_BIAS_CHANGE_DPH
    } else {
        ACCEL_BIAS_CHANGE_UG
    };
    // At least a minute: the bound of a drift over a very short span is not physics.
    let span_h = span_h.max(1.0 / 60.0);
    match form {
        // g^2 sensitivity: as `g_sensitivity`'s 1 deg/s per g, per g^2.
        Form::ForceSquare | Form::ForceProduct(..) | Form::ForceAbs if gyro => 3600.0,
        // accel_second_order's 5000 ug/g^2 (0.5 % of a 2 g full scale).
        Form::ForceSquare | Form::ForceProduct(..) | Form::ForceCube => 5000.0,
        // The registry's scale asymmetry.
        Form::ForceAbs | Form::RateAbs => 10_000.0,
        // -tau^2/2 of a timing error of at most a second (time_offset's range), in ms^2.
        Form::ForceRateSquare => 5e5,
        // gyro_scale_nonlinearity's 50 ppm per deg/s.
        Form::RateSquare => 50.0,
        // 1 % at 250 deg/s as a cubic term.
        Form::RateCube => 0.2,
        Form::Drift { .. } => bias / span_h,
        Form::Drift2 { .. } => bias / (span_h * span_h),
        Form::Decay { .. } | Form::Step { .. } => bias,
        Form::ScaleDrift { .. } => SCALE_CHANGE_PPM / span_h,
        Form::ScaleStep { .. } => SCALE_CHANGE_PPM,
        // The registry's scale thermal coefficient.
        Form::ThermalScale => 500.0,
    }
}
