//! The driver traits. Both are pull-based: the interpreter sleeps on the (possibly
//! virtual) tokio clock in short ticks and drains every sample that became available,
//! so a simulated station costs no timer per sample.

use async_trait::async_trait;

/// Which table axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum TableAxisId {
    /// Outer axis.
    Outer,
    /// Inner axis.
    Inner,
}

/// A command to the table. Angles in degrees, rates in deg/s.
#[derive(Debug, Clone, PartialEq)]
pub enum TableCommand {
    /// Position both axes (acceleration- and rate-limited move), then hold.
    MoveTo {
        /// Outer angle, deg.
        outer_deg: f64,
        /// Inner angle, deg.
        inner_deg: f64,
    },
    /// Ramp an axis to a constant rate.
    Rate {
        /// Axis.
        axis: TableAxisId,
        /// Rate, deg/s.
        rate_dps: f64,
    },
    /// Decelerate an axis to rest and hold where it stops.
    Stop {
        /// Axis.
        axis: TableAxisId,
    },
    /// Sway an axis: `center + amplitude sin(2 pi (t - t0) / period)`.
    Oscillate {
        /// Axis.
        axis: TableAxisId,
        /// Centre, deg.
        center_deg: f64,
        /// Amplitude, deg.
        amplitude_deg: f64,
        /// Period, s.
        period_s: f64,
    },
    /// Safe state: decelerate both axes within the table's limits and stop.
    SafeStop,
}

// The samples are the recording format's rows: defined with it, so that the replay driver
// and the recording writer share them without the format depending on the drivers.
pub use ratecal_recording::{ImuSample, TableSample};

/// Static facts about a table.
#[derive(Debug, Clone, PartialEq)]
pub struct TableInfo {
    /// Model name.
    pub model: String,
    /// Maximum rate per axis, deg/s.
    pub max_rate_dps: f64,
    /// Maximum angular acceleration per axis, deg/s^2.
    pub max_accel_dps2: f64,
    /// Feedback rate, Hz.
    pub feedback_hz: f64,
    /// Whether the table is simulated.
    pub simulated: bool,
}

/// Static facts about an IMU.
#[derive(Debug, Clone, PartialEq)]
pub struct ImuInfo {
    /// Model name.
    pub model: String,
    /// Serial number.
    pub serial: String,
    /// Grade (`tactical`, `navigation`, `consumer`...).
    pub grade: String,
    /// Sample rate, Hz.
    pub sample_hz: f64,
    /// Accelerometer range, m/s^2.
    pub accel_range_mps2: f64,
    /// Gyro range, deg/s.
    pub gyro_range_dps: f64,
    /// Whether the IMU is simulated.
    pub simulated: bool,
}

/// What went wrong, for the engine to branch on (never on message text).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DriverErrorKind {
    /// No answer in time.
    Timeout,
    /// The link failed (socket closed, serial error).
    Transport,
    /// The instrument itself reported a fault.
    Instrument,
    /// The command is outside what the device can do.
    InvalidCommand,
}

/// A driver error.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{message}")]
pub struct DriverError {
    /// Kind.
    pub kind: DriverErrorKind,
    /// Message for people.
    pub message: String,
}

impl DriverError {
    /// Builds an error.
    pub fn new(kind: DriverErrorKind, message: impl Into<String>) -> Self {
        DriverError {
            kind,
            message: message.into(),
        }
    }

    /// Kind of the error.
    pub fn kind(&self) -> DriverErrorKind {
        self.kind
    }
}

/// How a hardware link delivered its samples: counts, and the delay from the (mapped)
/// device stamp to host arrival, per batch.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LinkStats {
    /// Samples received.
    pub samples: u64,
    /// Batches (reads, feedback replies) received.
    pub batches: u64,
    /// Frames refused for a wrong CRC (skipped).
    pub corrupted: u64,
    /// Samples missing from the device's counter (lost in transit, or during a stall).
    pub lost: u64,
    /// Times the link was rebuilt.
    pub reconnects: u32,
    /// Least delay from stamp to arrival, s (negative: the stamps run this much late).
    pub latency_min_s: f64,
    /// Mean delay, s.
    pub latency_mean_s: f64,
    /// Largest delay, s.
    pub latency_max_s: f64,
    /// Host time minus device time at the map's latest anchor, s: a sample's device stamp
    /// is its host-clock `t` minus this (`None` before the first batch).
    pub device_offset_s: Option<f64>,
}

/// What the operator of a manual station is asked for. Vectors are body axes (unit).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum OperatorAsk {
    /// A pose: `up` the body axis brought up within `tolerance_deg` (`None`: a free pose).
    Pose {
        /// The body axis to bring up.
        up: Option<[f64; 3]>,
        /// How far from it the pose may be, deg.
        tolerance_deg: f64,
    },
    /// A hand turn about a body axis by an angle (`None`: a free turn).
    Turn {
        /// Body axis and angle, deg.
        about: Option<([f64; 3], f64)>,
    },
    /// The pose just found was refused: the operator is asked again.
    Refused,
}

/// A rate table.
#[async_trait]
pub trait TableDriver: Send {
    /// Static facts.
    fn info(&self) -> TableInfo;
    /// Sends a command; returns once the table accepted it (not once the motion ended).
    async fn command(&mut self, cmd: TableCommand) -> Result<(), DriverError>;
    /// Appends every feedback sample that became available since the last call.
    async fn read(&mut self, out: &mut Vec<TableSample>) -> Result<(), DriverError>;
    /// How the link delivered its samples (`None` for a simulated or replayed table).
    fn link_stats(&self) -> Option<LinkStats> {
        None
    }
    /// Passes a request to the operator of a manual station (the interpreter has prompted
    /// it; a simulated operator acts on it). A rate table has no operator: refused.
    async fn ask(&mut self, _ask: OperatorAsk) -> Result<(), DriverError> {
        Err(DriverError::new(
            DriverErrorKind::InvalidCommand,
            "this table has no operator to place or turn the unit",
        ))
    }
}

/// An IMU.
#[async_trait]
pub trait ImuDriver: Send {
    /// Static facts.
    fn info(&self) -> ImuInfo;
    /// Appends every sample that became available since the last call.
    async fn read(&mut self, out: &mut Vec<ImuSample>) -> Result<(), DriverError>;
    /// The operator remounted the IMU with a new `C_PB` (row-major); a simulator changes its
    /// physics, hardware ignores it.
    async fn remount(&mut self, _rotation: [[f64; 3]; 3]) -> Result<(), DriverError> {
        Ok(())
    }
    /// How the link delivered its samples (`None` for a simulated or replayed IMU).
    fn link_stats(&self) -> Option<LinkStats> {
        None
    }
}
