//! Recordings of the simulated station (drivers registry, paused clock): a station built
//! from the default one with edits, and a plan run on it into a recording folder.

use super::manifest;
use ratecal_drivers::{DEFAULT_STATION_YAML, Station, registry};
use ratecal_plan::Plan;
use ratecal_recording::{Columns, RecordingWriter};
use ratecal_run::{NoProgress, RunOptions, RunStatus, execute};
use std::path::Path;

/// The default station with its `effects: {}` replaced and the other edits applied.
pub fn station(effects: &str, extra: &[(&str, &str)]) -> Station {
    let mut yaml = DEFAULT_STATION_YAML.replace("effects: {}", &format!("effects: {effects}"));
    for (a, b) in extra {
        assert!(yaml.contains(a), "{a}");
        yaml = yaml.replace(a, b);
    }
    Station::from_yaml(&yaml, "test.yaml").unwrap()
}

/// Runs `plan` on the simulated station into `dir` (virtual time), to completion.
pub fn record(st: &Station, plan: &Plan, seed: u64, dir: &Path) {
    let rt = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .start_paused(true)
        .build()
        .unwrap();
    rt.block_on(async {
        let (mut table, mut imu) = registry::build(st, seed).unwrap();
        let mut m = manifest(&plan.name);
        m.station.site = st.site();
        let cols = Columns {
            imu_temp: true,
            ambient: true,
            ..Columns::default()
        };
        let mut w = RecordingWriter::create(dir, m, cols).unwrap();
        let out = execute(
            plan,
            table.as_mut(),
            imu.as_mut(),
            &mut w,
            &mut NoProgress,
            &RunOptions::default(),
        )
        .await
        .unwrap();
        assert_eq!(out.status, RunStatus::Completed, "{:?}", out.warnings);
    });
}
