//! The Type B figures a station file states, as the budget reads them
//! ([`ratecal_analysis::budget::terms::Stated`]): `run` and `analyze` hand them to the
//! analysis (results.json `budgets`), and `certificate` uses them for a results file
//! written before budgets were.

use ratecal_analysis::budget::terms::{Stated, TemperatureCoefficients};
use ratecal_drivers::Station;
use ratecal_folder::RunFolder;

/// What `station` states, at the site's `gravity_mps2`.
pub fn stated(station: &Station, gravity_mps2: f64) -> Stated {
    let t = &station.table;
    let deg = std::f64::consts::PI / 180.0;
    Stated {
        rate_accuracy: t.rate_accuracy.map(|r| r.get()),
        position_accuracy_rad: t.position_accuracy.map(|a| a.get() * deg),
        axis_orthogonality_rad: t.axis_orthogonality.map(|a| a.get() * deg),
        gravity_u_mps2: station.site.gravity_u_mps2,
        gravity_mps2,
        clock_accuracy: station
            .daq
            .as_ref()
            .and_then(|d| d.clock_accuracy)
            .map(|r| r.get()),
        temperature_stability_c: station.site.temperature_stability.map(|t| t.get()),
        temperature_coefficients: station
            .imu
            .temperature_coefficients
            .map(|c| TemperatureCoefficients {
                accel_bias: c.accel_bias,
                gyro_bias: c.gyro_bias,
                accel_scale: c.accel_scale,
                gyro_scale: c.gyro_scale,
            })
            .unwrap_or_default(),
    }
}

/// What the station file kept in run folder `dir` states (`None`: no station file, or one
/// that does not parse; the analysis then has no Type B figures).
pub fn stated_of_folder(dir: &std::path::Path) -> Option<Stated> {
    let run = RunFolder::new(dir);
    let (name, text) = run.station_text().ok()?;
    let station = Station::from_yaml(&text, &name).ok()?;
    let manifest = run.manifest_quiet()?;
    Some(stated(&station, manifest.station.site.gravity_mps2))
}
