//! Progress as lines, for a standard error that is not a terminal (a pipe, a scheduler's
//! log file): one line when a step starts and one per minute of run time within a step,
//! each with the wall time since the start, the run's clock (simulated or real) and what it
//! does, said as it happens. With `json`, each line is a JSON object whose keys
//! (docs/run-folders.md, "Progress lines") stay stable: `event`, `wall_s`, `run_s`,
//! `clock`, `estimated_s`, `step_index`, `step`, and `text` for a message.

use super::{Shown, hms};
use ratecal_run::Progress;
use std::time::Instant;

/// Run time between two lines within one step, s.
pub const EVERY_S: f64 = 60.0;

/// The line logger.
pub struct LogLines {
    json: bool,
    simulated: bool,
    estimated_s: f64,
    started: Instant,
    /// Run time last seen, s.
    t_s: f64,
    /// The current step (index, name).
    step: Option<(usize, String)>,
    /// Run time of the next line within the step.
    next_s: f64,
}

impl LogLines {
    /// A logger for a run of `estimated_s` s of run time; `json` for JSON lines.
    pub fn new(estimated_s: f64, simulated: bool, json: bool) -> Self {
        LogLines {
            json,
            simulated,
            estimated_s,
            started: Instant::now(),
            t_s: 0.0,
            step: None,
            next_s: EVERY_S,
        }
    }

    fn emit(&self, event: &str, text: &str) {
        let wall_s = self.started.elapsed().as_secs_f64();
        let clock = if self.simulated { "simulated" } else { "real" };
        if self.json {
            let mut v = serde_json::json!({
                "event": event,
                "wall_s": (wall_s * 1000.0).round() / 1000.0,
                "run_s": (self.t_s * 1000.0).round() / 1000.0,
                "clock": clock,
                "estimated_s": self.estimated_s.round(),
            });
            if let Some((i, name)) = &self.step {
                v["step_index"] = serde_json::json!(i);
                v["step"] = serde_json::json!(name);
            }
            if !text.is_empty() {
                v["text"] = serde_json::json!(text);
            }
            errln!("{v}");
        } else {
            let step = self
                .step
                .as_ref()
                .map_or(String::new(), |(i, n)| format!(" step {} {n}:", i + 1));
            errln!(
                "[wall {} | {clock} {} / ~{}]{step} {text}",
                hms(wall_s),
                hms(self.t_s),
                hms(self.estimated_s)
            );
        }
    }
}

impl Shown for LogLines {
    fn finish(&mut self) {
        self.emit("end", "run ended");
    }
}

impl Progress for LogLines {
    fn step(&mut self, index: usize, name: &str) {
        self.step = Some((index, name.to_string()));
        self.next_s = self.t_s + EVERY_S;
        self.emit("step", "started");
    }

    fn time(&mut self, t_s: f64) {
        self.t_s = t_s;
        if self.step.is_some() && t_s >= self.next_s {
            while self.next_s <= t_s {
                self.next_s += EVERY_S;
            }
            self.emit("progress", "running");
        }
    }

    fn message(&mut self, text: &str) {
        self.emit("message", text);
    }

    fn confirm(&mut self, text: &str) -> bool {
        if self.simulated {
            self.message(&format!("operator: {text} (simulated: done)"));
            return true;
        }
        self.emit("operator", text);
        errln!("press Enter when done (or type `no` to abort)");
        let mut line = String::new();
        if std::io::stdin().read_line(&mut line).is_err() {
            return false;
        }
        !matches!(line.trim(), "n" | "no")
    }
}
