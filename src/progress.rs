//! What `porompm run` shows while it runs: a progress bar on standard error (stage, step,
//! simulated time, Newton iterations of the last step, elapsed time and ETA from the rate at which
//! simulated time advances), and event lines (a stage starts, a step is cut, the run stops early).
//!
//! The bar is drawn only on rank 0, only when standard error is a terminal, and not with `--quiet`;
//! event lines are printed by rank 0 unless `--quiet` (so a log file keeps them, without the bar).

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;

/// Resolution of the bar: positions per run.
const TICKS: u64 = 10_000;

/// The run's progress display.
pub struct Progress {
    bar: Option<ProgressBar>,
    lines: bool,
    rank0: bool,
    end: f64,
}

impl Progress {
    /// A display for a run up to simulated time `end` [s]; `speak` is false on ranks other than 0
    /// and with `--quiet`; `rank0` is true on rank 0 only (warnings are printed there even with
    /// `--quiet`).
    pub fn new(speak: bool, rank0: bool, end: f64) -> Progress {
        let bar = (speak && std::io::stderr().is_terminal()).then(|| {
            let b = ProgressBar::with_draw_target(Some(TICKS), ProgressDrawTarget::stderr_with_hz(4));
            let style = ProgressStyle::with_template("{elapsed:>4} {bar:16} {percent:>3}% {msg} ETA {eta}")
                .unwrap_or_else(|_| ProgressStyle::default_bar());
            b.set_style(style);
            b.set_message("starting,");
            b
        });
        Progress { bar, lines: speak, rank0, end }
    }

    /// A warning line: printed on rank 0 also with `--quiet` (through the bar when there is one).
    pub fn warning(&self, msg: &str) {
        match &self.bar {
            Some(b) => b.println(msg),
            None if self.rank0 => eprintln!("{msg}"),
            None => {}
        }
    }

    /// An event line.
    pub fn message(&self, msg: &str) {
        match &self.bar {
            Some(b) => b.println(msg),
            None if self.lines => eprintln!("{msg}"),
            None => {}
        }
    }

    /// After an accepted step.
    pub fn step(&self, stage: &str, step: usize, t: f64, newton: usize) {
        if let Some(b) = &self.bar {
            let fraction = if self.end > 0.0 { (t / self.end).clamp(0.0, 1.0) } else { 1.0 };
            b.set_position((fraction * TICKS as f64).round() as u64);
            b.set_message(format!("{stage}: step {step}, t = {t:.3e} s, {newton} Newton,"));
        }
    }

    /// Removes the bar (before the final report).
    pub fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        self.finish();
    }
}
