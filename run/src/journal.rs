//! The run journal (`journal.jsonl`): one JSON object a line, every command, settle
//! outcome, acquisition, warning and abort with its recording-clock time. `--resume` reads
//! it back to find the last completed step.

use serde::{Deserialize, Serialize};

/// One journal line: the recording-clock time, the step (if any) and the event.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JournalEntry {
    /// Recording-clock time, s.
    pub t: f64,
    /// Step the event belongs to.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub step: Option<String>,
    /// What happened.
    #[serde(flatten)]
    pub event: JournalEvent,
}

/// What a journal line records.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "event", rename_all = "snake_case")]
pub enum JournalEvent {
    /// The run (or a resumed part of it) starts at step `from_step`.
    Start {
        /// Procedure name.
        procedure: String,
        /// First step index executed.
        from_step: usize,
        /// Whether this continues an interrupted run.
        resumed: bool,
    },
    /// A step starts.
    StepStart {
        /// Index in the plan.
        index: usize,
    },
    /// A step completed; `segments` counts every segment recorded so far in the run.
    StepEnd {
        /// Index in the plan.
        index: usize,
        /// Segments in the manifest at this point.
        segments: usize,
    },
    /// A command was sent to the table.
    Command {
        /// The command, as text.
        command: String,
    },
    /// Settle conditions held.
    Settled {
        /// Time it took, s.
        after_s: f64,
    },
    /// Settle timed out.
    SettleTimeout {
        /// Time waited, s.
        after_s: f64,
        /// `abort`, `warn` or `continue`.
        action: String,
        /// The conditions that did not hold.
        unmet: String,
    },
    /// A hold (timed wait).
    Hold {
        /// Duration, s.
        duration_s: f64,
    },
    /// An acquisition started.
    AcquireStart {
        /// Segment id.
        segment: String,
    },
    /// An acquisition ended and its segment was recorded.
    AcquireEnd {
        /// Segment id.
        segment: String,
        /// Start, s.
        t_start: f64,
        /// End, s.
        t_end: f64,
    },
    /// The operator remounted the IMU.
    Remount {
        /// New `C_PB`, row-major.
        rotation: [[f64; 3]; 3],
        /// Instruction given.
        message: String,
    },
    /// A rule with the `warn` action fired, or something else worth noting.
    Warning {
        /// Rule text or cause.
        rule: String,
        /// The values that fired it.
        values: String,
    },
    /// The run aborts.
    Abort {
        /// Rule text or cause.
        rule: String,
        /// The values that fired it.
        values: String,
    },
    /// The safe stop ended (`at_rest` false when it timed out or the table failed).
    SafeState {
        /// Whether the table was seen at rest.
        at_rest: bool,
    },
    /// A block of a stream was written: the stream's running hash after it
    /// (`ratecal_recording::chain`), written by the recording writer.
    Block {
        /// The stream's file (`imu.csv`).
        stream: String,
        /// First byte of the block.
        offset: u64,
        /// Bytes in it.
        len: u64,
        /// The chain value after it, hex.
        chain: String,
    },
    /// A resumed run's staged files are about to replace the sealed ones (the intent of
    /// docs/run-folders.md, on record in the journal that replaces the sealed one; `t` 0).
    Commit {
        /// Files moved in from the pending folder.
        moves: Vec<String>,
        /// Files removed (the old seal).
        removes: Vec<String>,
    },
    /// The run ended.
    End {
        /// `completed` or `aborted`.
        status: String,
    },
}

/// Where an interrupted run continues.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ResumePoint {
    /// First step not completed.
    pub next_step: usize,
    /// Segments recorded by the completed steps (later ones are dropped from the manifest).
    pub segments: usize,
    /// Whether the run already completed (nothing to resume).
    pub completed: bool,
}

/// Reads a journal and finds where to resume. A torn last line (a crash mid-write) and
/// unreadable lines are skipped.
pub fn resume_point(journal: &str) -> ResumePoint {
    let mut p = ResumePoint::default();
    for line in journal.lines() {
        let Ok(e) = serde_json::from_str::<JournalEntry>(line) else {
            continue;
        };
        match e.event {
            JournalEvent::StepEnd { index, segments } => {
                p.next_step = index + 1;
                p.segments = segments;
                p.completed = false;
            }
            JournalEvent::End { status } => p.completed = status == "completed",
            JournalEvent::Start { .. } => p.completed = false,
            _ => {}
        }
    }
    p
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resume_after_torn_line() {
        let lines = [
            JournalEntry {
                t: 0.0,
                step: None,
                event: JournalEvent::StepStart { index: 0 },
            },
            JournalEntry {
                t: 5.0,
                step: None,
                event: JournalEvent::StepEnd {
                    index: 0,
                    segments: 2,
                },
            },
            JournalEntry {
                t: 6.0,
                step: None,
                event: JournalEvent::StepStart { index: 1 },
            },
        ];
        let mut text: String = lines
            .iter()
            .map(|e| serde_json::to_string(e).unwrap() + "\n")
            .collect();
        text.push_str("{\"t\":7.0,\"event\":\"step_e");
        let p = resume_point(&text);
        assert_eq!(
            p,
            ResumePoint {
                next_step: 1,
                segments: 2,
                completed: false
            }
        );
    }
}
