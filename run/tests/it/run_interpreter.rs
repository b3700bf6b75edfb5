//! The interpreter on a fake station under a paused clock: settle waits, timeouts, abort
//! rules with persistence, segments and their kinds, files on disk after an abort, resume.

use crate::common;
use common::plans::*;
use common::*;
use ratecal_plan::*;
use ratecal_recording::{Columns, Manifest, RecordingWriter, SegmentKind, sha256_hex};
use ratecal_run::{NoProgress, RunOptions, RunOutcome, RunStatus, execute, resume_point};
use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

async fn run_on(dir: &Path, plan: &Plan, faults: Faults, opts: RunOptions) -> (RunOutcome, Shared) {
    let (mut table, mut imu, shared) = station(faults);
    let mut w = RecordingWriter::create(
        dir,
        manifest(&plan.name),
        Columns {
            imu_temp: true,
            ambient: true,
            ..Columns::default()
        },
    )
    .unwrap();
    let out = execute(plan, &mut table, &mut imu, &mut w, &mut NoProgress, &opts)
        .await
        .unwrap();
    (out, shared)
}

fn read_manifest(dir: &Path) -> Manifest {
    serde_saphyr::from_str(&std::fs::read_to_string(dir.join("manifest.yaml")).unwrap()).unwrap()
}

/// Streams on disk are well formed: strictly increasing time, expected columns, hashes.
fn check_streams(dir: &Path) -> (Vec<Vec<f64>>, Vec<Vec<f64>>) {
    let (ih, imu) = csv_rows(&dir.join("imu.csv"));
    let (th, table) = csv_rows(&dir.join("table.csv"));
    assert_eq!(ih, ["t", "ax", "ay", "az", "gx", "gy", "gz", "temp"]);
    assert_eq!(
        th,
        ["t", "outer", "inner", "outer_rate", "inner_rate", "ambient"]
    );
    for rows in [&imu, &table] {
        assert!(
            rows.windows(2).all(|w| w[1][0] > w[0][0]),
            "time must increase"
        );
        assert!(
            rows[0][0] >= 0.0 && rows[0][0] < 0.05,
            "streams start at 0: {}",
            rows[0][0]
        );
    }
    let m = read_manifest(dir);
    let run = m.run.unwrap();
    for f in ["imu.csv", "table.csv"] {
        assert_eq!(
            run.files_sha256[f],
            sha256_hex(&std::fs::read(dir.join(f)).unwrap()),
            "{f}"
        );
    }
    (imu, table)
}

#[tokio::test(start_paused = true)]
async fn settle_waits_for_the_table_and_segments_carry_the_motion() {
    let dir = tempfile::tempdir().unwrap();
    let p = plan(
        vec![rule(
            "table.attitude_error > 5 arcsec for 1 s",
            AbortCondition::Above {
                signal: Signal::AttitudeError,
                limit: 5.0 / 3600.0,
            },
            1.0,
        )],
        vec![
            step(
                "static",
                vec![
                    mv(90.0, 0.0),
                    settle(2.0, Some(1.0 / 3600.0), None, 60.0, OnTimeout::Abort),
                    acquire("static/1", 3.0),
                ],
            ),
            step(
                "rates",
                vec![
                    Node::Do(Action::Spin {
                        axis: Axis::Inner,
                        rate_dps: 10.0,
                    }),
                    settle(1.0, None, Some(0.01), 30.0, OnTimeout::Abort),
                    acquire("rate/inner/+10", 2.0),
                    Node::Do(Action::Stop { axis: None }),
                    settle(1.0, None, Some(0.01), 30.0, OnTimeout::Abort),
                ],
            ),
            step(
                "sway",
                vec![
                    Node::Do(Action::Oscillate {
                        axis: Axis::Outer,
                        amplitude_deg: 10.0,
                        period_s: 5.0,
                        center_deg: Some(0.0),
                        duration_s: 5.0,
                    }),
                    Node::Repeat {
                        count: 2,
                        var: Some("k".into()),
                        body: vec![acquire("sway/{k}", 5.0)],
                    },
                ],
            ),
        ],
    );
    let (out, shared) = run_on(dir.path(), &p, Faults::default(), RunOptions::default()).await;
    assert_eq!(out.status, RunStatus::Completed);
    let m = read_manifest(dir.path());
    let ids: Vec<_> = m.segments.iter().map(|s| s.id.as_str()).collect();
    assert_eq!(ids, ["static/1", "rate/inner/+10", "sway/1", "sway/2"]);
    let s = &m.segments[0];
    assert_eq!(
        (s.kind, s.pitch_deg, s.roll_deg),
        (SegmentKind::Static, Some(90.0), Some(0.0))
    );
    // 90 deg at 20 deg/s takes at least 4.5 s; the settle may not end before.
    assert!(s.t_start >= 4.5, "static segment starts at {}", s.t_start);
    assert!((s.t_end - s.t_start - 3.0).abs() < 1e-9);
    let r = &m.segments[1];
    assert_eq!(
        (r.kind, r.axis.as_deref(), r.rate_dps),
        (SegmentKind::Rate, Some("inner"), Some(10.0))
    );
    let o = &m.segments[2];
    assert_eq!(
        (
            o.kind,
            o.axis.as_deref(),
            o.amplitude_deg,
            o.period_s,
            o.center_deg
        ),
        (
            SegmentKind::Oscillation,
            Some("outer"),
            Some(10.0),
            Some(5.0),
            Some(0.0)
        )
    );
    assert!((m.segments[3].t_start - m.segments[2].t_end).abs() < 1e-9);
    assert_eq!(m.run.as_ref().unwrap().status, "completed");

    let (imu, table) = check_streams(dir.path());
    // Inside the static segment the IMU reads g [sin th, cos th sin phi, cos th cos phi] at
    // pitch 90: [g, 0, 0]; the table is within 1 arcsec of 90 deg.
    for row in imu.iter().filter(|r| r[0] >= s.t_start && r[0] <= s.t_end) {
        assert!(
            (row[1] - G).abs() < 1e-3 && row[2].abs() < 1e-3 && row[3].abs() < 1e-3,
            "{row:?}"
        );
    }
    for row in table
        .iter()
        .filter(|r| r[0] >= s.t_start && r[0] <= s.t_end)
    {
        assert!((row[1] - 90.0).abs() < 1.0 / 3600.0 + 1e-6, "{row:?}");
    }
    // Inside the rate segment the inner axis turns at 10 deg/s (X gyro reads it).
    for row in table
        .iter()
        .filter(|r| r[0] >= m.segments[1].t_start && r[0] <= m.segments[1].t_end)
    {
        assert!((row[4] - 10.0).abs() < 0.01, "{row:?}");
    }
    // Streams cover every segment.
    let last = imu.last().unwrap()[0].min(table.last().unwrap()[0]);
    assert!(m.segments.iter().all(|s| s.t_end <= last + 0.02));
    // The run ends with the table brought to rest after the sway.
    let (wo, wi) = rates(&shared);
    assert!(wo.abs() < 0.05 && wi.abs() < 0.05);
    let journal = std::fs::read_to_string(dir.path().join("journal.jsonl")).unwrap();
    assert_eq!(journal.matches("\"event\":\"settled\"").count(), 3);
    assert_eq!(journal.matches("\"event\":\"acquire_end\"").count(), 4);
}

/// An abort must leave: status aborted with rule/time/step/values, the table at rest, every
/// sample up to the end on disk, well-formed streams with their hashes.
fn check_aborted(dir: &Path, out: &RunOutcome, shared: &Shared, rule_part: &str) -> f64 {
    let RunStatus::Aborted(rec) = &out.status else {
        panic!("expected an abort, got {:?}", out.status)
    };
    assert!(rec.rule.contains(rule_part), "rule {:?}", rec.rule);
    let m = read_manifest(dir);
    let run = m.run.as_ref().unwrap();
    assert_eq!(run.status, "aborted");
    assert_eq!(run.abort.as_ref(), Some(rec));
    let (wo, wi) = rates(shared);
    assert!(
        wo.abs() < 0.05 && wi.abs() < 0.05,
        "table not at rest: {wo} {wi}"
    );
    assert!(commands(shared).contains(&ratecal_drivers::TableCommand::SafeStop));
    let (imu, _) = check_streams(dir);
    let journal = std::fs::read_to_string(dir.join("journal.jsonl")).unwrap();
    assert!(journal.contains("\"event\":\"abort\""));
    rec.t.max(imu.last().unwrap()[0])
}

fn spin_plan(aborts: Vec<AbortRule>, step_aborts: Vec<AbortRule>) -> Plan {
    let mut s = step(
        "spin",
        vec![
            Node::Do(Action::Spin {
                axis: Axis::Outer,
                rate_dps: 15.0,
            }),
            settle(1.0, None, Some(0.05), 30.0, OnTimeout::Abort),
            acquire("rate/outer/+15", 60.0),
        ],
    );
    s.aborts = step_aborts;
    plan(aborts, vec![s])
}

#[tokio::test(start_paused = true)]
async fn settle_timeout_aborts_to_a_safe_state() {
    let dir = tempfile::tempdir().unwrap();
    // 1e-9 deg cannot be met with 0.2 arcsec encoder dither.
    let p = plan(
        vec![],
        vec![step(
            "s",
            vec![
                Node::Do(Action::Spin {
                    axis: Axis::Inner,
                    rate_dps: 20.0,
                }),
                Node::Do(Action::Hold { duration_s: 3.0 }),
                mv(10.0, 0.0),
                settle(1.0, Some(1e-9), None, 20.0, OnTimeout::Abort),
                acquire("never", 1.0),
            ],
        )],
    );
    let (out, shared) = run_on(dir.path(), &p, Faults::default(), RunOptions::default()).await;
    check_aborted(dir.path(), &out, &shared, "settle timeout");
    let RunStatus::Aborted(rec) = &out.status else {
        unreachable!()
    };
    // Timeout counted from the settle's start (after 3 s of hold): fires at 23 s.
    assert!((rec.t - 23.0).abs() < 0.03, "{}", rec.t);
    assert_eq!(rec.step.as_deref(), Some("s"));
    assert!(rec.values.contains("attitude error"));
    assert!(read_manifest(dir.path()).segments.is_empty());
}

#[tokio::test(start_paused = true)]
async fn settle_timeout_warn_goes_on() {
    let dir = tempfile::tempdir().unwrap();
    let p = plan(
        vec![],
        vec![step(
            "s",
            vec![
                mv(10.0, 0.0),
                settle(1.0, Some(1e-9), None, 20.0, OnTimeout::Warn),
                acquire("a", 1.0),
            ],
        )],
    );
    let (out, _) = run_on(dir.path(), &p, Faults::default(), RunOptions::default()).await;
    assert_eq!(out.status, RunStatus::Completed);
    assert_eq!(out.warnings.len(), 1);
    // The acquisition follows the 20 s timeout.
    let t_start = read_manifest(dir.path()).segments[0].t_start;
    assert!((t_start - 20.0).abs() < 0.03, "{t_start}");
}

#[tokio::test(start_paused = true)]
async fn temperature_excursion_fires_after_its_persistence() {
    let band = AbortCondition::Outside {
        signal: Signal::AmbientTemperature,
        lo: 18.0,
        hi: 22.0,
    };
    // A 1.5 s excursion under a 2 s persistence does not fire; a long one fires 2 s after it began.
    let dir = tempfile::tempdir().unwrap();
    let p = spin_plan(
        vec![rule(
            "ambient.temperature outside 18 degC .. 22 degC for 2 s",
            band.clone(),
            2.0,
        )],
        vec![],
    );
    let faults = Faults {
        ambient_excursion: Some((10.0, 11.5, 25.0)),
        ..Faults::default()
    };
    let (out, _) = run_on(dir.path(), &p, faults, RunOptions::default()).await;
    assert_eq!(out.status, RunStatus::Completed);

    let dir = tempfile::tempdir().unwrap();
    let faults = Faults {
        ambient_excursion: Some((10.0, 1e9, 25.0)),
        ..Faults::default()
    };
    let (out, shared) = run_on(dir.path(), &p, faults, RunOptions::default()).await;
    check_aborted(dir.path(), &out, &shared, "ambient.temperature outside");
    let RunStatus::Aborted(rec) = &out.status else {
        unreachable!()
    };
    assert!((rec.t - 12.0).abs() < 1e-6, "fired at {}", rec.t);
    assert!(rec.values.contains("25"), "{}", rec.values);
    // The table was spinning at 15 deg/s: it decelerated (>= 15/40 s) before the end, and
    // samples kept being recorded through the safe stop.
    let (_, table) = csv_rows(&dir.path().join("table.csv"));
    assert!(table.last().unwrap()[0] >= 12.0 + 15.0 / MAX_ACCEL);
}

#[tokio::test(start_paused = true)]
async fn step_scoped_rule_and_stuck_imu() {
    let dir = tempfile::tempdir().unwrap();
    let p = spin_plan(
        vec![],
        vec![rule(
            "imu.stuck for 0.5 s",
            AbortCondition::ImuAbnormal,
            0.5,
        )],
    );
    let faults = Faults {
        imu_stuck_at: Some(8.0),
        ..Faults::default()
    };
    let (out, shared) = run_on(dir.path(), &p, faults, RunOptions::default()).await;
    check_aborted(dir.path(), &out, &shared, "imu.stuck");
    let RunStatus::Aborted(rec) = &out.status else {
        unreachable!()
    };
    // First repeated sample at 8.005 s, persistence 0.5 s.
    assert!((rec.t - 8.505).abs() < 0.011, "{}", rec.t);
    assert_eq!(rec.step.as_deref(), Some("spin"));
}

#[tokio::test(start_paused = true)]
async fn table_fault_aborts() {
    let dir = tempfile::tempdir().unwrap();
    let p = spin_plan(vec![], vec![]);
    let faults = Faults {
        table_fault_at: Some(9.0),
        ..Faults::default()
    };
    let (out, shared) = run_on(dir.path(), &p, faults, RunOptions::default()).await;
    let end = check_aborted(dir.path(), &out, &shared, "table driver error (Instrument)");
    assert!(end >= 9.0);
}

#[tokio::test(start_paused = true)]
async fn imu_dropout_aborts_and_keeps_the_table_stream() {
    let dir = tempfile::tempdir().unwrap();
    let p = spin_plan(vec![], vec![]);
    let faults = Faults {
        imu_dropout_at: Some(9.0),
        ..Faults::default()
    };
    let (out, shared) = run_on(dir.path(), &p, faults, RunOptions::default()).await;
    check_aborted(dir.path(), &out, &shared, "IMU dropout");
    let RunStatus::Aborted(rec) = &out.status else {
        unreachable!()
    };
    // Last sample 8.995 s, stall limit 1 s: detected at the first tick after 9.995 s.
    assert!(rec.t > 9.995 && rec.t < 10.02, "{}", rec.t);
    let (imu, table) = check_streams(dir.path());
    assert!((imu.last().unwrap()[0] - 8.995).abs() < 1e-9);
    assert!(table.last().unwrap()[0] > rec.t);
}

#[tokio::test(start_paused = true)]
async fn ctrl_c_takes_the_abort_path() {
    let dir = tempfile::tempdir().unwrap();
    let p = spin_plan(vec![], vec![]);
    let cancel = Arc::new(AtomicBool::new(false));
    let c = cancel.clone();
    tokio::spawn(async move {
        tokio::time::sleep(std::time::Duration::from_secs(7)).await;
        c.store(true, std::sync::atomic::Ordering::Relaxed);
    });
    let opts = RunOptions {
        cancel: Some(cancel),
        ..RunOptions::default()
    };
    let (out, shared) = run_on(dir.path(), &p, Faults::default(), opts).await;
    check_aborted(dir.path(), &out, &shared, "Ctrl-C");
}

#[tokio::test(start_paused = true)]
async fn resume_continues_after_the_last_completed_step() {
    let dir = tempfile::tempdir().unwrap();
    let body = |n: u32, pitch: f64| {
        step(
            &format!("s{n}"),
            vec![
                mv(pitch, 0.0),
                settle(1.0, Some(2.0 / 3600.0), None, 60.0, OnTimeout::Abort),
                acquire(&format!("seg/{n}/a"), 5.0),
                acquire(&format!("seg/{n}/b"), 5.0),
            ],
        )
    };
    let p = plan(vec![], vec![body(1, 10.0), body(2, 20.0), body(3, 30.0)]);
    // Interrupt in the middle of step 2 (after its first segment).
    let cancel = Arc::new(AtomicBool::new(false));
    let c = cancel.clone();
    tokio::spawn(async move {
        tokio::time::sleep(std::time::Duration::from_secs(28)).await;
        c.store(true, std::sync::atomic::Ordering::Relaxed);
    });
    let (out, _) = run_on(
        dir.path(),
        &p,
        Faults::default(),
        RunOptions {
            cancel: Some(cancel),
            ..RunOptions::default()
        },
    )
    .await;
    assert!(matches!(out.status, RunStatus::Aborted(_)));
    assert_eq!(out.steps_completed, 1);
    let before = read_manifest(dir.path()).segments;
    assert_eq!(before.len(), 3, "{before:?}");

    let point = resume_point(&std::fs::read_to_string(dir.path().join("journal.jsonl")).unwrap());
    assert_eq!(
        (point.next_step, point.segments, point.completed),
        (1, 2, false)
    );
    let (mut w, last_t) = RecordingWriter::append(dir.path(), false).unwrap();
    let last_t = last_t.unwrap();
    w.manifest_mut().segments.truncate(point.segments);
    w.manifest_mut().run.as_mut().unwrap().status = "running".into();
    let (mut table, mut imu, _) = station(Faults::default());
    let opts = RunOptions {
        start_step: point.next_step,
        resume_segments: point.segments,
        t_offset: last_t + 1.0,
        ..RunOptions::default()
    };
    let out = execute(&p, &mut table, &mut imu, &mut w, &mut NoProgress, &opts)
        .await
        .unwrap();
    assert_eq!(out.status, RunStatus::Completed);
    assert_eq!(out.steps_completed, 3);
    let m = read_manifest(dir.path());
    let ids: Vec<_> = m.segments.iter().map(|s| s.id.as_str()).collect();
    assert_eq!(
        ids,
        [
            "seg/1/a", "seg/1/b", "seg/2/a", "seg/2/b", "seg/3/a", "seg/3/b"
        ]
    );
    assert!(m.segments.windows(2).all(|w| w[1].t_start >= w[0].t_end));
    assert!(m.segments[2].t_start > last_t);
    assert_eq!(m.segments[2].pitch_deg, Some(20.0));
    assert_eq!(m.run.unwrap().abort, None);
    // One continuous recording: time strictly increasing across the resume, hashes valid.
    check_streams(dir.path());
}
