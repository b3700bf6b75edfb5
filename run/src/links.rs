//! What the hardware links report at the end of a run, as the manifest's `run.sync`.

use ratecal_drivers::LinkStats;
use ratecal_recording::{LinkRecord, SyncRecord};

/// `shift`: recording time minus host time.
fn link_record(s: &LinkStats, shift: f64) -> LinkRecord {
    LinkRecord {
        samples: s.samples,
        corrupted: s.corrupted,
        lost: s.lost,
        reconnects: s.reconnects,
        latency_min_ms: s.latency_min_s * 1e3,
        latency_mean_ms: s.latency_mean_s * 1e3,
        latency_max_ms: s.latency_max_s * 1e3,
        device_offset_s: s.device_offset_s.map(|o| o + shift),
    }
}

/// Each link's stamps run late by minus its least arrival delay (the anchor's delay above
/// the least one seen); the table-to-IMU skew is the difference. `shift` is what moved the
/// host clock onto the recording's.
pub(super) fn sync_record(
    table: Option<LinkStats>,
    imu: Option<LinkStats>,
    shift: f64,
) -> Option<SyncRecord> {
    if table.is_none() && imu.is_none() {
        return None;
    }
    let skew = match (&table, &imu) {
        (Some(t), Some(i)) if t.batches > 0 && i.batches > 0 => {
            Some(i.latency_min_s - t.latency_min_s)
        }
        _ => None,
    };
    Some(SyncRecord {
        table_minus_imu_s: skew,
        imu: imu.as_ref().map(|s| link_record(s, shift)),
        table: table.as_ref().map(|s| link_record(s, shift)),
    })
}
