//! The `faults:` section of a station file: faults the simulator rehearses (a table axis,
//! an IMU dropout, a temperature excursion) and faults of the links that `ratecal emulate`
//! rehearses (a dropped connection, a stall, corrupted frames, a table fault flag, IMU
//! saturation).

use super::quantity::{Rate, TempDelta, Time};
use serde::{Deserialize, Serialize};

/// Which table axis a fault hits.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AxisName {
    /// Outer axis.
    Outer,
    /// Inner axis.
    Inner,
}

/// What a faulty table axis does.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TableFaultMode {
    /// Stops following commands: brakes to rest and stays there.
    Stuck,
    /// Runs away: ramps to `rate` and keeps turning whatever it is told.
    Runaway,
}

/// What a dropped-out IMU outputs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DropoutMode {
    /// NaN on every channel.
    Nan,
    /// The last good sample, repeated.
    Stuck,
    /// No samples at all.
    Missing,
}

/// A rehearsed fault (the simulator, and the emulator for the link faults).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum FaultSpec {
    /// A table axis stops following or runs away at `at`; only a safe stop still works.
    Table {
        /// When.
        at: Time,
        /// Which axis.
        axis: AxisName,
        /// Stuck or runaway.
        mode: TableFaultMode,
        /// Runaway rate.
        #[serde(default = "default_runaway")]
        rate: Rate,
    },
    /// The IMU drops out at `at` for `duration`.
    ImuDropout {
        /// When.
        at: Time,
        /// How long.
        duration: Time,
        /// NaN, stuck or missing samples.
        mode: DropoutMode,
    },
    /// The ambient temperature ramps by `delta` over `ramp`, holds for `duration`, ramps back.
    TemperatureExcursion {
        /// When it starts.
        at: Time,
        /// Size of the excursion.
        delta: TempDelta,
        /// Ramp time (up, and down again).
        #[serde(default = "default_ramp")]
        ramp: Time,
        /// How long it holds at the full excursion.
        duration: Time,
    },
    /// The emulator closes a link at `at` and refuses it for `duration` (0: at once back).
    LinkDrop {
        /// When.
        at: Time,
        /// Which link.
        link: LinkName,
        /// How long new connections are refused.
        #[serde(default)]
        duration: Time,
    },
    /// The emulator stops answering on a link (keeps it open) from `at` for `duration`.
    Stall {
        /// When.
        at: Time,
        /// Which link.
        link: LinkName,
        /// How long.
        duration: Time,
    },
    /// One IMU frame in `every` is sent with a wrong CRC from `at` for `duration`.
    CorruptFrames {
        /// When.
        at: Time,
        /// How long.
        duration: Time,
        /// One frame in this many is corrupted (at least 1).
        #[serde(default = "default_every")]
        every: u32,
    },
    /// The table raises its fault flag at `at` (amplifier fault): it answers feedback
    /// requests with `ERR FAULT` and accepts only `SAFE`.
    TableFaultFlag {
        /// When.
        at: Time,
    },
    /// The IMU's gyro x channel saturates (full scale, saturation flag set) from `at`.
    ImuSaturation {
        /// When.
        at: Time,
        /// How long.
        duration: Time,
    },
}

/// Which link of the emulated station a fault hits.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LinkName {
    /// The table's line-protocol link.
    Table,
    /// The IMU's frame stream.
    Imu,
}

fn default_every() -> u32 {
    10
}

fn default_runaway() -> Rate {
    Rate(20.0)
}

fn default_ramp() -> Time {
    Time(60.0)
}
