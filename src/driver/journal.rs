//! What a run writes and shows as it goes: `summary.json` (rewritten while it runs), the rows of
//! `history.csv` (kept on the writing rank for the figures), the progress display and its event
//! lines, and the warnings.

use super::{failed, RunError};
use crate::diagnostics::Warning;
use crate::io::RunOutput;
use crate::parallel::Collective;
use crate::plot::Figure;
use crate::progress::Progress;
use crate::recorders::Sink;
use crate::summary::Summary;
use std::time::{Duration, Instant};

/// The shortest wall time between two rewrites of the running summary.json.
const SUMMARY_INTERVAL: Duration = Duration::from_secs(1);

/// The probe figures: (history.csv field, axis label, scale, file stem).
const PROBE_FIGURES: &[(&str, &str, f64, &str)] = &[
    ("p_excess", "excess pore pressure [kPa]", 1e-3, "excess_pore_pressure"),
    ("uy", "vertical displacement [mm]", 1e3, "vertical_displacement"),
    ("ux", "horizontal displacement [mm]", 1e3, "horizontal_displacement"),
];

/// The run's output and display.
pub(super) struct Journal<'a> {
    pub out: &'a mut RunOutput,
    pub summary: &'a mut Summary,
    display: Progress,
    /// The columns and rows of history.csv, kept for the probe figures.
    history: (Vec<String>, Vec<Vec<f64>>),
    /// When the running summary.json was last rewritten.
    summary_written: Instant,
}

impl<'a> Journal<'a> {
    /// The journal of a run writing to `out` with `columns` in its history.
    pub fn new(out: &'a mut RunOutput, summary: &'a mut Summary, display: Progress, columns: Vec<String>) -> Self {
        Journal { out, summary, display, history: (columns, Vec::new()), summary_written: Instant::now() }
    }

    /// Runs `f` with a sink into the summary and the output; returns its values and the warnings
    /// it raised.
    pub fn with_sink<T>(
        &mut self,
        f: impl FnOnce(&mut Sink) -> Result<T, String>,
    ) -> Result<(T, Vec<Warning>), RunError> {
        let mut sink = Sink { summary: self.summary, warnings: Vec::new(), out: self.out, figures: Vec::new() };
        let value = f(&mut sink).map_err(RunError::Failed)?;
        Ok((value, sink.warnings))
    }

    /// One row of history.csv.
    pub fn history_row(&mut self, values: &[f64]) -> Result<(), RunError> {
        self.out.history_row(values).map_err(RunError::Failed)?;
        if self.out.is_writer() {
            self.history.1.push(values.to_vec());
        }
        Ok(())
    }

    /// Gives warnings: in the terminal (rank 0, also with `--quiet`) and in summary.json.
    pub fn warn(&mut self, warnings: Vec<Warning>) {
        for w in warnings {
            let at = w.time_s.map(|t| format!(" (t = {t:.6e} s)")).unwrap_or_default();
            self.display.warning(&format!("warning [{}]{at}: {}", w.kind, w.message));
            self.summary.warnings.push(w);
        }
    }

    /// An event line.
    pub fn progress(&self, msg: &str) {
        self.display.message(msg);
    }

    /// The progress bar after an accepted step.
    pub fn step(&self, stage: &str, step: usize, t: f64, newton: usize) {
        self.display.step(stage, step, t, newton);
    }

    /// Rewrites the running summary.json (rank 0, atomically) when the step wrote a history row
    /// and [`SUMMARY_INTERVAL`] has passed: an explicit stage takes tens of thousands of steps,
    /// and each rewrite is synchronised to disk.
    pub fn keep_summary(&mut self, row: bool) -> Result<(), RunError> {
        if row && self.summary_written.elapsed() >= SUMMARY_INTERVAL {
            self.out.write_summary(&*self.summary).map_err(failed)?;
            self.summary_written = Instant::now();
        }
        Ok(())
    }

    /// Draws the run's figures (the recorders' and the probes' histories; writing rank only); a
    /// figure that cannot be drawn is a warning, the run's results stand.
    pub fn figures(&mut self, mut figures: Vec<Figure>) {
        if !self.out.is_writer() {
            return;
        }
        figures.extend(crate::plot::probe_histories(&self.history.0, &self.history.1, PROBE_FIGURES));
        if let Err(e) = self.out.write_figures(&figures) {
            eprintln!("warning: the plots were not drawn: {e}");
        }
    }
}

/// What the summary of any run holds at its end, however it ended: the wall time since `start`,
/// the peak memory of rank 0 and of all ranks, PETSc's options, porompm's collectives.
/// Collective: every rank reaches it (a failed run's error was agreed by all ranks).
pub(super) fn settle(summary: &mut Summary, coll: &Collective, start: Instant) {
    summary.wall_time_s = start.elapsed().as_secs_f64();
    summary.peak_memory_mib = crate::io::peak_memory_mib();
    summary.peak_memory_total_mib = match summary.peak_memory_mib {
        Some(m) => coll.sum(&[m]).ok().map(|v| v[0]),
        None => None,
    };
    summary.petsc_options = crate::assembly::petsc_options().unwrap_or_default();
    summary.collectives = coll.traffic();
}
