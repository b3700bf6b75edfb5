//! The link faults of a station file, as the emulator plays them (times on the session's
//! clock, s).

use crate::station::{FaultSpec, LinkName, Station};

/// A dropped link: closed at `at`, refused until `at + duration`.
#[derive(Debug, Clone, Copy)]
pub(super) struct Drop {
    pub link: LinkName,
    pub at: f64,
    pub duration: f64,
}

/// Every link fault of a station.
#[derive(Debug, Clone, Default)]
pub(super) struct LinkFaults {
    pub drops: Vec<Drop>,
    stalls: Vec<(LinkName, f64, f64)>,
    corrupt: Vec<(f64, f64, u32)>,
    flag: Option<f64>,
    saturation: Vec<(f64, f64)>,
}

fn within(t: f64, at: f64, duration: f64) -> bool {
    t >= at && t < at + duration
}

impl LinkFaults {
    pub fn of(station: &Station) -> Self {
        let mut f = LinkFaults::default();
        for spec in &station.faults {
            match *spec {
                FaultSpec::LinkDrop { at, link, duration } => f.drops.push(Drop {
                    link,
                    at: at.0,
                    duration: duration.0,
                }),
                FaultSpec::Stall { at, link, duration } => f.stalls.push((link, at.0, duration.0)),
                FaultSpec::CorruptFrames {
                    at,
                    duration,
                    every,
                } => f.corrupt.push((at.0, duration.0, every.max(1))),
                FaultSpec::TableFaultFlag { at } => {
                    f.flag = Some(f.flag.map_or(at.0, |a: f64| a.min(at.0)));
                }
                FaultSpec::ImuSaturation { at, duration } => f.saturation.push((at.0, duration.0)),
                FaultSpec::Table { .. }
                | FaultSpec::ImuDropout { .. }
                | FaultSpec::TemperatureExcursion { .. } => {}
            }
        }
        f
    }

    /// When the outage of `link` that holds at `t` ends (it refuses connections until
    /// then: inside a drop's outage).
    pub fn outage(&self, link: LinkName, t: f64) -> Option<f64> {
        self.drops
            .iter()
            .filter(|d| d.link == link && within(t, d.at, d.duration))
            .map(|d| d.at + d.duration)
            .reduce(f64::max)
    }

    /// When the stall of `link` that holds at `t` ends.
    pub fn stall_end(&self, link: LinkName, t: f64) -> Option<f64> {
        self.stalls
            .iter()
            .filter(|s| s.0 == link && within(t, s.1, s.2))
            .map(|s| s.1 + s.2)
            .reduce(f64::max)
    }

    /// One frame in how many is corrupted at `t`.
    pub fn corrupt_every(&self, t: f64) -> Option<u32> {
        self.corrupt
            .iter()
            .filter(|c| within(t, c.0, c.1))
            .map(|c| c.2)
            .min()
    }

    /// Whether the table's fault flag is up at `t`.
    pub fn flagged(&self, t: f64) -> bool {
        self.flag.is_some_and(|at| t >= at)
    }

    /// Whether the IMU saturates at `t`.
    pub fn saturated(&self, t: f64) -> bool {
        self.saturation.iter().any(|s| within(t, s.0, s.1))
    }
}
