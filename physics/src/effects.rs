//! The catalogue of effects the nominal model leaves out (spec/physics.md), with their
//! canonical ids and parameter names.

/// Canonical effect id.
pub type EffectId = &'static str;

/// One catalogue entry: id, what it is, and its parameter names with units.
#[derive(Debug, Clone, Copy)]
pub struct EffectInfo {
    /// Canonical id, e.g. `lever_arm`.
    pub id: EffectId,
    /// One line of physics, for reports.
    pub physics: &'static str,
    /// Canonical parameter names.
    pub params: &'static [&'static str],
    /// Unit of the parameters.
    pub unit: &'static str,
}

/// Every effect of the catalogue, in the spec's order.
pub const EFFECTS: &[EffectInfo] = &[
    EffectInfo { id: "earth_rate", physics: "gyros sense the Earth's rotation, projected on the body axes", params: &["latitude_deg"], unit: "deg" },
    EffectInfo {
        id: "lever_arm",
        physics: "accelerometer sensing points are not at the rotation centre: centripetal and tangential acceleration",
        params: &["rxx_mm", "rxy_mm", "rxz_mm", "ryx_mm", "ryy_mm", "ryz_mm", "rzx_mm", "rzy_mm", "rzz_mm"],
        unit: "mm",
    },
    EffectInfo { id: "time_offset", physics: "IMU and table clocks disagree", params: &["tau_ms"], unit: "ms" },
    EffectInfo { id: "accel_misalignment", physics: "off-diagonal terms of K_a", params: &["xy_mrad", "xz_mrad", "yx_mrad", "yz_mrad", "zx_mrad", "zy_mrad"], unit: "mrad" },
    EffectInfo { id: "gyro_misalignment", physics: "off-diagonal terms of K_g", params: &["xy_mrad", "xz_mrad", "yx_mrad", "yz_mrad", "zx_mrad", "zy_mrad"], unit: "mrad" },
    EffectInfo {
        id: "g_sensitivity",
        physics: "gyro bias depends on specific force",
        params: &["xx_dps_per_g", "xy_dps_per_g", "xz_dps_per_g", "yx_dps_per_g", "yy_dps_per_g", "yz_dps_per_g", "zx_dps_per_g", "zy_dps_per_g", "zz_dps_per_g"],
        unit: "deg/s per g",
    },
    EffectInfo { id: "gyro_thermal_drift", physics: "gyro bias follows temperature", params: &["x", "y", "z"], unit: "deg/s per degC" },
    EffectInfo { id: "accel_thermal_drift", physics: "accelerometer bias follows temperature", params: &["x", "y", "z"], unit: "m/s^2 per degC" },
    EffectInfo { id: "gyro_scale_nonlinearity", physics: "gyro output gains n_i w_i |w_i|", params: &["x", "y", "z"], unit: "ppm per deg/s" },
];

/// Looks up an effect by its canonical id.
pub fn effect(id: &str) -> Option<&'static EffectInfo> {
    EFFECTS.iter().find(|e| e.id == id)
}
