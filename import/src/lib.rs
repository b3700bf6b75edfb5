//! `ratecal import`: a lab's own DAQ files (CSV of any delimiter, raw counts, no time
//! column, segments from a notebook or found from the signal) to a recording folder of
//! `spec/recording-format.md`, through a YAML import map. Nothing is resampled or
//! filtered: each sample is converted to the spec's units and body axes exactly (written
//! in its shortest exact form), and the manifest's `provenance:` says how, with the SHA-256
//! of the map and of every source. Data that do not fit the map (gravity in the wrong
//! unit, a gyro at rest reading tens of deg/s, time going backwards, a segment outside the
//! data, an `up` axis gravity contradicts) are refused with a located diagnostic, and
//! nothing is written.
//!
//! ```
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let dir = tempfile::tempdir()?;
//! let csv = dir.path().join("daq.csv");
//! let mut text = String::from("acc_x;acc_y;acc_z;gyr_x;gyr_y;gyr_z\n");
//! for i in 0..200 {
//!     let z = if i < 100 { 1.0 } else { -1.0 };
//!     text.push_str(&format!("0.001;-0.002;{z};0.1;0.2;0.3\n"));
//! }
//! std::fs::write(&csv, text)?;
//! let map = ratecal_import::load_map(
//!     "source: { format: csv }
//! imu:
//!   time: { rate_hz: 100 }
//!   columns: { ax: acc_x, ay: acc_y, az: acc_z, gx: gyr_x, gy: gyr_y, gz: gyr_z }
//!   units: { accel: g, gyro: deg/s }
//! segments:
//!   - { id: z_up, kind: static, samples: [10, 90], up: +z }
//!   - { id: z_down, kind: static, samples: [110, 190], up: -z }
//! site: { latitude_deg: 49.57, gravity_mps2: 9.8096 }
//! ",
//!     "map.yaml",
//! )?;
//! let out = dir.path().join("run");
//! let summary = ratecal_import::import(&[csv], &map, &out)?;
//! assert_eq!(summary.samples, 200);
//! let rec = ratecal_recording::read(&out)?;
//! assert_eq!(rec.imu.t[1], 0.01);
//! assert_eq!(rec.manifest.segments[0].t_start, 0.1);
//! assert_eq!(rec.manifest.segments[0].t_end, 0.89);
//! assert_eq!(rec.imu.accel[2][0], 9.80665);
//! # Ok(())
//! # }
//! ```

mod check;
mod error;
pub mod map;
mod read;
pub mod segment;
mod write;

pub use check::{GRAVITY_RANGE, GYRO_REST_MAX_DPS, RATE_RATIO, UP_TOLERANCE_DEG};
pub use error::{ErrorKind, ImportError, Say};
pub use map::{ImportMap, load_map};
pub use read::{Matrix, read_mat, sniff, split_cells};
pub use write::{Conversion, FileHash, Provenance, Summary, import};
