//! `run`: the interpreter. It walks a checked [`Plan`](ratecal_plan::Plan), drives a rate
//! table and an IMU through the driver traits, records both streams continuously into a
//! [`RunSink`] (normally a [`RecordingWriter`]), evaluates settle conditions and abort rules
//! on the live data, and on any abort (rule, settle timeout, driver or recording error,
//! Ctrl-C) brings the table to a safe state before it closes the recording.
//!
//! The loop sleeps on the tokio clock in short ticks and drains whatever samples became
//! available, so a simulated station run under a paused clock
//! (`Builder::new_current_thread().enable_all().start_paused(true)`) goes as fast as the CPU
//! allows, and a hardware station runs in real time through the same code.
//!
//! Time: the recording clock is 0 at the start of the run (or `RunOptions::t_offset` when a
//! run is resumed); driver time stamps are shifted onto it.

use ratecal_drivers::{ImuSample, TableSample};
use ratecal_recording::{AbortRecord, RecordingWriter, Segment, SyncRecord};
use std::io;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::time::Duration;

mod command;
mod exec;
mod journal;
mod links;
mod live;
mod monitor;

pub use exec::execute;

/// What the operator is told, last and plainly, when the safe stop could not be confirmed
/// (the table refused it, or its feedback never showed it at rest).
pub const NOT_AT_REST: &str = "the table was NOT confirmed at rest: check it before approaching";
pub use journal::{JournalEntry, JournalEvent, ResumePoint, resume_point};

/// Where a run's data goes. [`RecordingWriter`] is the implementation that writes a run
/// folder; tests may collect in memory.
pub trait RunSink {
    /// IMU samples, on the recording clock.
    fn imu(&mut self, samples: &[ImuSample]) -> io::Result<()>;
    /// Table feedback samples, on the recording clock.
    fn table(&mut self, samples: &[TableSample]) -> io::Result<()>;
    /// One journal event.
    fn journal(&mut self, entry: &JournalEntry) -> io::Result<()>;
    /// A completed segment (persist it: the manifest is rewritten at each one).
    fn segment(&mut self, segment: Segment) -> io::Result<()>;
    /// The run ended: record its status and close the streams.
    fn end(&mut self, status: &RunStatus) -> io::Result<()>;
    /// Pushes what is buffered to the disk (called at least every second of a run, so a
    /// crash or a pulled plug loses at most that).
    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
    /// Waits until every segment handed to [`RunSink::segment`] is persisted: the error of
    /// one that could not be (called before the run is said to be completed).
    fn settle(&mut self) -> io::Result<()> {
        Ok(())
    }
    /// How the hardware links delivered their samples (called before `end`).
    fn links(&mut self, _sync: &SyncRecord) {}
}

/// Hooks the caller implements to follow a run (a progress bar) and to talk to the operator.
/// Every method has a do-nothing default.
pub trait Progress {
    /// A step starts (`index` in the plan's steps).
    fn step(&mut self, _index: usize, _name: &str) {}
    /// The recording clock advanced to `t_s` (called at most every half second of run time).
    fn time(&mut self, _t_s: f64) {}
    /// Something the operator should read (warnings, remount instructions).
    fn message(&mut self, _text: &str) {}
    /// Asks the operator to do something (remount the IMU) and confirm; `false` aborts.
    /// A simulated station confirms at once.
    fn confirm(&mut self, _text: &str) -> bool {
        true
    }
}

/// A [`Progress`] that shows nothing and confirms everything.
pub struct NoProgress;

impl Progress for NoProgress {}

/// Knobs of a run.
#[derive(Debug, Clone)]
pub struct RunOptions {
    /// Control-loop period (drain, monitor, settle evaluation).
    pub tick: Duration,
    /// First step to execute (steps before it completed in an earlier, interrupted run).
    pub start_step: usize,
    /// Segments already in the manifest from those earlier steps.
    pub resume_segments: usize,
    /// Recording-clock time of the start (0 for a new run; after the last sample when
    /// resuming, so that time keeps increasing).
    pub t_offset: f64,
    /// Set to `true` (e.g. by a Ctrl-C handler) to abort the run through the safe path.
    pub cancel: Option<Arc<AtomicBool>>,
    /// How long the safe stop may take before the recording is closed anyway, s.
    pub safe_stop_timeout_s: f64,
    /// A stream that delivers nothing for this long aborts the run (dropout), s.
    pub stall_timeout_s: f64,
    /// When resuming: the last static segment the earlier steps recorded (a manual station
    /// asks the operator to place the unit in that pose again).
    pub last_pose: Option<ratecal_recording::Segment>,
}

impl Default for RunOptions {
    fn default() -> Self {
        RunOptions {
            tick: Duration::from_millis(20),
            start_step: 0,
            resume_segments: 0,
            t_offset: 0.0,
            cancel: None,
            safe_stop_timeout_s: 120.0,
            stall_timeout_s: 1.0,
            last_pose: None,
        }
    }
}

/// How a run ended.
#[derive(Debug, Clone, PartialEq)]
pub enum RunStatus {
    /// Every step ran.
    Completed,
    /// Stopped early, table brought to the safe state.
    Aborted(AbortRecord),
}

impl RunStatus {
    /// `completed` or `aborted`, as the manifest writes it.
    pub fn as_str(&self) -> &'static str {
        match self {
            RunStatus::Completed => "completed",
            RunStatus::Aborted(_) => "aborted",
        }
    }
}

/// What [`execute`] returns.
#[derive(Debug, Clone, PartialEq)]
pub struct RunOutcome {
    /// Completed or aborted (with why).
    pub status: RunStatus,
    /// Recording-clock time at the start of this execution, s.
    pub t_start: f64,
    /// Recording-clock time at the end, s.
    pub t_end: f64,
    /// Segments recorded by this execution.
    pub segments: usize,
    /// Steps completed (including those completed before a resume).
    pub steps_completed: usize,
    /// IMU samples received (the recording holds those with finite values).
    pub imu_samples: u64,
    /// Table samples received.
    pub table_samples: u64,
    /// Warnings raised (rules with `warn`, settle timeouts with `warn`).
    pub warnings: Vec<String>,
    /// Hardware links' delivery and the table-to-IMU synchronisation (`None`: simulated).
    pub sync: Option<SyncRecord>,
}

impl RunSink for RecordingWriter {
    fn imu(&mut self, samples: &[ImuSample]) -> io::Result<()> {
        self.write_imu(samples)
    }

    fn table(&mut self, samples: &[TableSample]) -> io::Result<()> {
        self.write_table(samples)
    }

    fn journal(&mut self, entry: &JournalEntry) -> io::Result<()> {
        let line = serde_json::to_string(entry).map_err(io::Error::other)?;
        self.write_journal_line(&line)
    }

    fn segment(&mut self, segment: Segment) -> io::Result<()> {
        // The writer thread syncs and rewrites the manifest while the run goes on; a
        // checkpoint that fails takes its segment out again (its data may not all be
        // written) and fails the next call here, `flush` or `settle`.
        self.manifest_mut().segments.push(segment);
        self.checkpoint_begin()
    }

    fn flush(&mut self) -> io::Result<()> {
        self.sync()
    }

    fn settle(&mut self) -> io::Result<()> {
        RecordingWriter::settle(self)
    }

    fn links(&mut self, sync: &SyncRecord) {
        if let Some(run) = self.manifest_mut().run.as_mut() {
            run.sync = Some(sync.clone());
        }
    }

    fn end(&mut self, status: &RunStatus) -> io::Result<()> {
        if let Some(run) = self.manifest_mut().run.as_mut() {
            run.status = status.as_str().to_string();
            run.abort = match status {
                RunStatus::Aborted(a) => Some(a.clone()),
                RunStatus::Completed => None,
            };
        }
        self.finish()
    }
}
