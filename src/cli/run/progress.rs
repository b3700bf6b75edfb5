//! The progress bar of `ratecal run` (indicatif), shown only when stderr is a terminal.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use ratecal_ops::run::{Shown, hms};
use ratecal_run::Progress;
use std::io::IsTerminal;

/// Step name, run time (simulated or real) against the estimated total.
pub struct Bar {
    bar: Option<ProgressBar>,
    simulated: bool,
    /// Last whole second shown (the bar moves once a second of run time, not every tick).
    shown: Option<u64>,
}

impl Bar {
    /// A bar over `estimated_s` seconds of run time; hidden when stderr is not a terminal.
    pub fn new(estimated_s: f64, simulated: bool) -> Self {
        let bar = std::io::stderr().is_terminal().then(|| {
            let b = ProgressBar::with_draw_target(
                Some(estimated_s.max(1.0) as u64),
                ProgressDrawTarget::stderr(),
            );
            let style =
                ProgressStyle::with_template("{spinner} [{elapsed_precise}] {bar:30} {msg}")
                    .unwrap_or_else(|_| ProgressStyle::default_bar());
            b.set_style(style);
            b
        });
        Bar {
            bar,
            simulated,
            shown: None,
        }
    }
}

impl Shown for Bar {
    fn finish(&mut self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}

impl Progress for Bar {
    fn step(&mut self, _index: usize, name: &str) {
        if let Some(b) = &self.bar {
            b.set_prefix(name.to_string());
        }
    }

    fn time(&mut self, t_s: f64) {
        if self.shown == Some(t_s as u64) {
            return;
        }
        self.shown = Some(t_s as u64);
        if let Some(b) = &self.bar {
            b.set_position(t_s as u64);
            let total = b.length().unwrap_or(0);
            let clock = if self.simulated { "simulated" } else { "run" };
            b.set_message(format!(
                "{} | {clock} {} / ~{}",
                b.prefix(),
                hms(t_s),
                hms(total as f64)
            ));
        }
    }

    fn message(&mut self, text: &str) {
        match &self.bar {
            Some(b) => b.println(text),
            None => errln!("{text}"),
        }
    }

    fn confirm(&mut self, text: &str) -> bool {
        if self.simulated {
            self.message(&format!("operator: {text} (simulated: done)"));
            return true;
        }
        if let Some(b) = &self.bar {
            b.suspend(|| ask(text))
        } else {
            ask(text)
        }
    }
}

/// Asks the operator on the terminal; anything but `n`/`no` confirms.
fn ask(text: &str) -> bool {
    errln!("operator: {text}\npress Enter when done (or type `no` to abort)");
    let mut line = String::new();
    if std::io::stdin().read_line(&mut line).is_err() {
        return false;
    }
    !matches!(line.trim(), "n" | "no")
}
