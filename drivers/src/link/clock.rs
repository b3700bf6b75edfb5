//! Device time onto the host clock. A device stamps its samples on its own clock; the host
//! notes when each batch arrives. The map is anchored on the newest sample of the first
//! batch (the least delayed one) and kept; the arrival delays seen afterwards say how far
//! the anchor was from the least delay ever seen, which is the estimate of how late this
//! link's stamps are, reported per link (`LinkStats`).

use crate::LinkStats;

/// Maps device time onto host time and keeps the arrival statistics.
#[derive(Debug, Clone, Default)]
pub struct ClockMap {
    offset: Option<f64>,
    newest: f64,
    /// Statistics so far.
    pub stats: LinkStats,
    sum_latency: f64,
}

impl ClockMap {
    /// A batch whose newest sample has device time `newest_s` arrived at host time
    /// `host_s`. A device clock that went back by more than a second (the device restarted)
    /// re-anchors the map.
    pub fn arrival(&mut self, newest_s: f64, host_s: f64, samples: u64) {
        if self.offset.is_none() || newest_s < self.newest - 1.0 {
            self.offset = Some(host_s - newest_s);
            self.stats.device_offset_s = self.offset;
        }
        self.newest = newest_s;
        let latency = host_s - self.map(newest_s);
        let s = &mut self.stats;
        if s.batches == 0 {
            (s.latency_min_s, s.latency_max_s) = (latency, latency);
        }
        s.batches += 1;
        s.samples += samples;
        s.latency_min_s = s.latency_min_s.min(latency);
        s.latency_max_s = s.latency_max_s.max(latency);
        self.sum_latency += latency;
        s.latency_mean_s = self.sum_latency / s.batches as f64;
    }

    /// Host time of device time `device_s` (device time itself before the first batch).
    pub fn map(&self, device_s: f64) -> f64 {
        device_s + self.offset.unwrap_or(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_late_anchor_shows_as_a_negative_least_delay() {
        let mut c = ClockMap::default();
        // Device clock 100 s ahead; the first batch arrives 5 ms late, later ones 1 ms.
        c.arrival(0.0, -100.0 + 0.005, 1);
        c.arrival(1.0, -99.0 + 0.001, 1);
        assert!((c.map(1.0) - (-98.995)).abs() < 1e-9);
        assert!(
            (c.stats.latency_min_s + 0.004).abs() < 1e-9,
            "{:?}",
            c.stats
        );
    }
}
