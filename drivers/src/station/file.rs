//! The station file's structure (YAML). Every section refuses unknown keys; quantities
//! carry their units (see `quantity.rs`), keys whose name ends in a unit take bare numbers.
//! `docs/station.md` documents every key.

use super::driver::DriverSpec;
use super::effects::{EffectsSpec, TableEffectsSpec};
use super::quantity::{
    Accel, AccelDensity, Angle, Freq, Pressure, Rate, RateDensity, RateWalk, Ratio, Rotation, Temp,
    TempDelta, TempRate, Time, UnitVec, damping, finite, fraction, frequency, positive,
};
use serde::{Deserialize, Serialize};

use super::faults::FaultSpec;

/// A whole station: site, table, mount, IMU, temperature, environment and rehearsed faults.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Station {
    /// Free-form name of the station.
    #[serde(default)]
    pub name: String,
    /// Where the station is.
    pub site: SiteSpec,
    /// The rate table.
    pub table: TableSpec,
    /// How the IMU is mounted on the platform.
    #[serde(default)]
    pub mount: MountSpec,
    /// The IMU.
    pub imu: ImuSpec,
    /// Lab and IMU temperature behaviour.
    #[serde(default)]
    pub temperature: TemperatureSpec,
    /// Conditions measured once, recorded in the manifest.
    #[serde(default)]
    pub environment: Option<EnvironmentSpec>,
    /// The data acquisition's timing (the certificate's budget).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub daq: Option<DaqSpec>,
    /// The reference standards besides the table (a certificate names them with their
    /// calibrations): the DAQ's timebase, the gravity survey, the thermometer.
    #[serde(default)]
    pub references: ReferencesSpec,
    /// Faults to rehearse aborts with (simulated station only).
    #[serde(default)]
    pub faults: Vec<FaultSpec>,
    /// The terms of `imu.user_effects`, once the CLI has read their files.
    #[serde(skip)]
    pub user_terms: UserTerms,
}

/// The site: latitude and local gravity.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SiteSpec {
    /// Geodetic latitude, deg.
    #[serde(deserialize_with = "finite")]
    pub latitude_deg: f64,
    /// Local gravity, m/s^2 (the g-sensitivity is given per g: it divides by it).
    #[serde(deserialize_with = "positive")]
    pub gravity_mps2: f64,
    /// Standard uncertainty of `gravity_mps2`, m/s^2 (the certificate's budget).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gravity_u_mps2: Option<f64>,
    /// The lab's temperature stability: bound of the deviation from the mean during a
    /// calibration (the certificate's budget, rectangular).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub temperature_stability: Option<TempDelta>,
}

/// Settling behaviour of the table servo: a second-order loop.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SettlingSpec {
    /// Natural frequency of the servo loop.
    #[serde(deserialize_with = "frequency")]
    pub natural_frequency: Freq,
    /// Damping ratio (0 < damping <= 100; below 1 overshoots).
    #[serde(deserialize_with = "damping")]
    pub damping: f64,
    /// Fraction of the commanded acceleration fed forward, 0 to 1: the rest makes the
    /// tracking lag while accelerating and the overshoot after a move.
    #[serde(default = "default_feedforward", deserialize_with = "fraction")]
    pub feedforward: f64,
}

fn default_feedforward() -> f64 {
    0.8
}

impl ImuSpec {
    /// The static facts a driver of this IMU reports.
    pub fn info(&self, simulated: bool) -> crate::ImuInfo {
        crate::ImuInfo {
            model: self.model.clone(),
            serial: self.serial.clone(),
            grade: self.grade.clone(),
            sample_hz: self.sample_rate.0,
            accel_range_mps2: self.accel_range.0,
            gyro_range_dps: self.gyro_range.0,
            simulated,
        }
    }
}

impl Default for SettlingSpec {
    fn default() -> Self {
        SettlingSpec {
            natural_frequency: Freq(5.0),
            damping: 0.6,
            feedforward: default_feedforward(),
        }
    }
}

/// The dual-axis rate table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TableSpec {
    /// Which driver (a kind the registry lists, `registry/mod.rs`).
    pub driver: DriverSpec,
    /// Model name.
    #[serde(default = "default_table_model")]
    pub model: String,
    /// `a_o`, outer axis unit vector in the lab frame (ENU).
    pub outer_axis: UnitVec,
    /// `a_i`, inner axis unit vector at outer angle zero.
    pub inner_axis: UnitVec,
    /// Maximum rate per axis.
    #[serde(deserialize_with = "positive")]
    pub max_rate: Rate,
    /// Maximum angular acceleration per axis, deg/s^2.
    #[serde(deserialize_with = "positive")]
    pub max_accel_dps2: f64,
    /// Travel of the outer axis, [lowest, highest] (not stated: it turns without end).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub outer_travel: Option<[Angle; 2]>,
    /// Travel of the inner axis, [lowest, highest] (not stated: it turns without end).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inner_travel: Option<[Angle; 2]>,
    /// Encoder noise on the angle feedback (1 sigma).
    #[serde(default)]
    pub position_noise: Angle,
    /// Rate ripple on the rate feedback (1 sigma, white).
    #[serde(default)]
    pub rate_ripple: Rate,
    /// Servo settling behaviour.
    #[serde(default)]
    pub settling: SettlingSpec,
    /// Feedback sample rate.
    #[serde(deserialize_with = "frequency")]
    pub feedback_rate: Freq,
    /// Station-side catalogue effects (the encoder eccentricity) under their canonical ids.
    #[serde(default)]
    pub effects: TableEffectsSpec,
    /// Manufacturer (the certificate's identification).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub manufacturer: Option<String>,
    /// Serial number of the table.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub serial: Option<String>,
    /// The manufacturer's accuracy class.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub accuracy_class: Option<String>,
    /// Rate accuracy, a ratio of the rate (bound of a rectangular distribution).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rate_accuracy: Option<Ratio>,
    /// Position accuracy of each axis (bound of a rectangular distribution).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub position_accuracy: Option<Angle>,
    /// Orthogonality (and wobble) of the two axes (bound of a rectangular distribution).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis_orthogonality: Option<Angle>,
    /// The table's own calibration: the reference standard certificates trace to.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub calibration: Option<TableCalibration>,
}

/// The data acquisition (`daq`): what the certificate's budget needs of its timing.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DaqSpec {
    /// Accuracy of the clock that times the samples, a ratio (bound of a rectangular
    /// distribution): a rate is an angle over a time, so it enters every gyro scale factor.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub clock_accuracy: Option<Ratio>,
}

/// An IMU's temperature coefficients (`imu.temperature_coefficients`), bare numbers per
/// degC in the results' units; each absent one is "not stated" on a certificate.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TemperatureCoefficients {
    /// Accelerometer bias, m/s^2 per degC.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub accel_bias: Option<f64>,
    /// Gyro bias, deg/s per degC.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gyro_bias: Option<f64>,
    /// Accelerometer scale factor, ppm per degC.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub accel_scale: Option<f64>,
    /// Gyro scale factor, ppm per degC.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gyro_scale: Option<f64>,
}

/// The reference standards other than the table (`references`), each optional: their
/// calibration certificates, as a certificate lists them.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReferencesSpec {
    /// The DAQ's timebase (the clock that times the samples).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub daq_timebase: Option<TableCalibration>,
    /// The survey that gives the site's gravity (`site.gravity_mps2`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gravity_survey: Option<TableCalibration>,
    /// The thermometer that records the temperatures.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thermometer: Option<TableCalibration>,
}

/// A reference standard's calibration certificate (`table.calibration`, and each of
/// `references`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TableCalibration {
    /// Its certificate number.
    pub certificate: String,
    /// Who issued it.
    pub issued_by: String,
    /// When it is due, YYYY-MM-DD.
    pub due: String,
}

fn default_table_model() -> String {
    "dual-axis rate table".into()
}

/// The IMU mount: `C_PB`, row-major (its columns are the body axes in P).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MountSpec {
    /// `C_PB`, row-major.
    pub rotation: Rotation,
}

impl Default for MountSpec {
    fn default() -> Self {
        MountSpec {
            rotation: Rotation([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]),
        }
    }
}

/// The IMU: identity, sampling, noise, nominal errors and catalogue effects.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImuSpec {
    /// Which driver (a kind the registry lists; `sim` needs the simulated table: it senses
    /// the table's true motion).
    pub driver: DriverSpec,
    /// Model name.
    #[serde(default)]
    pub model: String,
    /// Serial number.
    #[serde(default)]
    pub serial: String,
    /// Grade (`tactical`, `navigation`, `consumer`...).
    #[serde(default)]
    pub grade: String,
    /// Output sample rate.
    #[serde(deserialize_with = "frequency")]
    pub sample_rate: Freq,
    /// Accelerometer range (outputs saturate there).
    #[serde(deserialize_with = "positive")]
    pub accel_range: Accel,
    /// Gyro range (outputs saturate there).
    #[serde(deserialize_with = "positive")]
    pub gyro_range: Rate,
    /// Accelerometer white-noise density; per-sample sigma = density * sqrt(sample rate).
    #[serde(default)]
    pub accel_noise_density: AccelDensity,
    /// Gyro white-noise density; per-sample sigma = density * sqrt(sample rate).
    #[serde(default)]
    pub gyro_noise_density: RateDensity,
    /// Sigma of a first-order Gauss-Markov gyro bias. Not the Allan deviation's
    /// bias-instability floor a report prints (about 0.66 of this sigma at its best
    /// averaging time): one name per quantity. `gyro_bias_instability`, its former name,
    /// is still read.
    #[serde(default, alias = "gyro_bias_instability")]
    pub gyro_bias_markov_sigma: Rate,
    /// Correlation time of the Gauss-Markov bias.
    #[serde(default = "default_correlation", deserialize_with = "positive")]
    pub gyro_bias_correlation_time: Time,
    /// Gyro bias random walk.
    #[serde(default)]
    pub gyro_bias_random_walk: RateWalk,
    /// Accelerometer biases (outputs at zero input), x y z.
    #[serde(default)]
    pub accel_bias: [Accel; 3],
    /// Gyro biases (outputs at zero input, at the thermal reference), x y z.
    #[serde(default)]
    pub gyro_bias: [Rate; 3],
    /// Accelerometer scale-factor errors (K - 1), x y z.
    #[serde(default)]
    pub accel_scale: [Ratio; 3],
    /// Gyro scale-factor errors (K - 1), x y z.
    #[serde(default)]
    pub gyro_scale: [Ratio; 3],
    /// Catalogue effects under their canonical ids.
    #[serde(default)]
    pub effects: EffectsSpec,
    /// Temperature coefficients from the IMU's data sheet (the certificate's budget).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub temperature_coefficients: Option<TemperatureCoefficients>,
    /// User effects (`*.effect` files, docs/user-effects.md) by reference: id -> its file
    /// and parameter values. The CLI reads the files and hands the terms in
    /// ([`Station::user_terms`]); the simulator applies them as registry effects.
    #[serde(default, skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub user_effects: std::collections::BTreeMap<String, UserEffectRef>,
}

/// A user effect in a station file: the `.effect` file that defines it (relative to the
/// station file's folder) and its parameters' values, in the units the file declares.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UserEffectRef {
    /// The `.effect` file.
    pub file: String,
    /// Parameter name -> value (0 when absent).
    #[serde(default)]
    pub values: std::collections::BTreeMap<String, f64>,
}

/// The user effects' terms, read from their files by the CLI: equal whatever they hold
/// (a station's identity is its text).
#[derive(Debug, Clone, Default)]
pub struct UserTerms(pub Vec<ratecal_physics::effects::Term>);

impl PartialEq for UserTerms {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

fn default_correlation() -> Time {
    Time(300.0)
}

/// Lab air and IMU internal temperature.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TemperatureSpec {
    /// Lab (or chamber) air.
    #[serde(default)]
    pub ambient: AmbientSpec,
    /// IMU internal temperature.
    #[serde(default)]
    pub imu: ImuTemperatureSpec,
    /// Reference temperature of the thermal drifts (`T_ref`).
    #[serde(default = "default_reference")]
    pub reference: Temp,
    /// Whether the table feedback carries the ambient temperature (the `ambient` column).
    #[serde(default = "yes")]
    pub report_ambient: bool,
}

fn yes() -> bool {
    true
}

fn default_reference() -> Temp {
    Temp(20.0)
}

impl Default for TemperatureSpec {
    fn default() -> Self {
        TemperatureSpec {
            ambient: AmbientSpec::default(),
            imu: ImuTemperatureSpec::default(),
            reference: default_reference(),
            report_ambient: true,
        }
    }
}

/// Lab air: `mean + drift * t + noise`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AmbientSpec {
    /// Temperature at the start.
    pub mean: Temp,
    /// Linear drift.
    #[serde(default)]
    pub drift: TempRate,
    /// Sensor noise (1 sigma, white).
    #[serde(default)]
    pub noise: TempDelta,
}

impl Default for AmbientSpec {
    fn default() -> Self {
        AmbientSpec {
            mean: Temp(20.0),
            drift: TempRate(0.0),
            noise: TempDelta(0.0),
        }
    }
}

/// IMU internal temperature: ambient plus a warm-up `offset (1 - exp(-t / time_constant))`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImuTemperatureSpec {
    /// Steady offset over ambient once warm.
    #[serde(default)]
    pub warmup_offset: TempDelta,
    /// Warm-up time constant.
    #[serde(default = "default_warmup")]
    pub warmup_time_constant: Time,
    /// Sensor noise (1 sigma, white).
    #[serde(default)]
    pub noise: TempDelta,
}

fn default_warmup() -> Time {
    Time(600.0)
}

impl Default for ImuTemperatureSpec {
    fn default() -> Self {
        ImuTemperatureSpec {
            warmup_offset: TempDelta(0.0),
            warmup_time_constant: default_warmup(),
            noise: TempDelta(0.0),
        }
    }
}

/// Conditions measured once (recorded in the manifest's `environment`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnvironmentSpec {
    /// Air temperature.
    #[serde(default)]
    pub temperature: Option<Temp>,
    /// Relative humidity (`"45 %"`).
    #[serde(default)]
    pub humidity: Option<Ratio>,
    /// Air pressure.
    #[serde(default)]
    pub pressure: Option<Pressure>,
    /// Vibration level.
    #[serde(default)]
    pub vibration: Option<Accel>,
}
