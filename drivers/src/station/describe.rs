//! What a run's manifest says about the station.

use super::Station;
use ratecal_physics::{Geometry, Site};
use serde::Serialize;

/// The station facts a manifest records.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StationInfo {
    /// Station name.
    pub name: String,
    /// Site: latitude and gravity.
    pub site: Site,
    /// Axis geometry and mount rotation.
    pub geometry: Geometry,
    /// IMU identity.
    pub imu: ImuIdentity,
    /// Table model.
    pub table_model: String,
    /// Whether table and IMU are both simulated.
    pub simulated: bool,
    /// Conditions measured once, in the manifest's units; `None` if the station has none.
    pub environment: Option<Environment>,
}

/// IMU identity (free-form strings).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ImuIdentity {
    /// Model.
    pub model: String,
    /// Serial number.
    pub serial: String,
    /// Grade.
    pub grade: String,
}

/// The manifest's `environment` block (recording-format.md).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Environment {
    /// Air temperature, degC.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub temperature_c: Option<f64>,
    /// Relative humidity, %.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub humidity_pct: Option<f64>,
    /// Air pressure, kPa.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pressure_kpa: Option<f64>,
    /// Vibration, g (standard gravity).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub vibration_g: Option<f64>,
}

impl Station {
    /// Whether both of its drivers are simulations (a run may use virtual time).
    pub fn simulated(&self) -> bool {
        self.table.driver.kind.simulated && self.imu.driver.kind.simulated
    }

    /// The facts a manifest records about this station.
    pub fn describe(&self) -> StationInfo {
        StationInfo {
            name: self.name.clone(),
            site: self.site(),
            geometry: self.geometry(),
            imu: ImuIdentity {
                model: self.imu.model.clone(),
                serial: self.imu.serial.clone(),
                grade: self.imu.grade.clone(),
            },
            table_model: self.table.model.clone(),
            simulated: self.simulated(),
            environment: self.environment.map(|e| Environment {
                temperature_c: e.temperature.map(|t| t.0),
                humidity_pct: e.humidity.map(|h| h.0 * 100.0),
                pressure_kpa: e.pressure.map(|p| p.0),
                vibration_g: e.vibration.map(|v| v.0 / ratecal_physics::STANDARD_GRAVITY),
            }),
        }
    }
}
