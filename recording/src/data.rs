//! The streams' rows as drivers hand them over ([`ImuSample`], [`TableSample`]) and as the
//! reader returns them, one vector per column ([`ImuStream`], [`TableStream`]).

use crate::Manifest;

/// One table feedback sample (a row of `table.csv`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TableSample {
    /// Time since the station's start, s.
    pub t: f64,
    /// Measured outer angle, deg.
    pub outer_deg: f64,
    /// Measured inner angle, deg.
    pub inner_deg: f64,
    /// Measured outer rate, deg/s.
    pub outer_rate_dps: f64,
    /// Measured inner rate, deg/s.
    pub inner_rate_dps: f64,
    /// Lab air temperature, degC, if the station measures it.
    pub ambient_c: Option<f64>,
    /// Host arrival time of the feedback line, s, on the clock of `t` (hardware links only;
    /// `t_host - t` is the sample's arrival delay).
    pub t_host: Option<f64>,
}

/// One IMU sample (a row of `imu.csv`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImuSample {
    /// Time stamp since the station's start, s.
    pub t: f64,
    /// Accelerometer outputs, m/s^2.
    pub accel: [f64; 3],
    /// Gyro outputs, deg/s.
    pub gyro: [f64; 3],
    /// Internal temperature, degC.
    pub temp_c: Option<f64>,
    /// Host arrival time of the frame, s, on the clock of `t` (hardware links only;
    /// `t_host - t` is the sample's arrival delay).
    pub t_host: Option<f64>,
}

/// The IMU stream, one vector per column: the analysis borrows a segment's channels as
/// slices instead of copying them.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ImuStream {
    /// Time stamps, s.
    pub t: Vec<f64>,
    /// Accelerometer outputs per axis (x, y, z), m/s^2.
    pub accel: [Vec<f64>; 3],
    /// Gyro outputs per axis (x, y, z), deg/s.
    pub gyro: [Vec<f64>; 3],
    /// IMU internal temperature, degC (optional column).
    pub temp: Option<Vec<f64>>,
}

/// The table feedback stream, columnar.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TableStream {
    /// Time stamps, s.
    pub t: Vec<f64>,
    /// Outer angle, deg (may run past 360).
    pub outer: Vec<f64>,
    /// Inner angle, deg.
    pub inner: Vec<f64>,
    /// Outer rate, deg/s.
    pub outer_rate: Vec<f64>,
    /// Inner rate, deg/s.
    pub inner_rate: Vec<f64>,
    /// Lab air temperature, degC (optional column).
    pub ambient: Option<Vec<f64>>,
}

/// A whole recording in memory.
#[derive(Debug, Clone, PartialEq)]
pub struct Recording {
    /// Manifest.
    pub manifest: Manifest,
    /// IMU stream.
    pub imu: ImuStream,
    /// Table stream.
    pub table: TableStream,
}
