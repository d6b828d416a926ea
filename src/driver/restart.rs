//! Checkpoints and restarts: `checkpoint.h5` every `--checkpoint-every` steps and after SIGINT or
//! SIGTERM (the run then stops after its current step), and a run that continues from one
//! (`--restart`): its points, time, counters, step control and recorders' states.

use super::control::StepControl;
use super::{failed, Dimension, RunError, Simulation};
use crate::layout::Dim;
use crate::model::LoadsAt;
use crate::state::{self, Checkpoint};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

/// Where a restarted run continues: the stage's index, its Δt and accepted steps at that Δt.
#[derive(Debug, Clone, Copy)]
struct Resume {
    stage: usize,
    dt: f64,
    successes: usize,
}

/// The run's checkpoints and interrupts.
pub(super) struct Restart {
    /// `--checkpoint-every` (0: never).
    every: usize,
    /// `main`'s SIGINT/SIGTERM flag.
    interrupt: Option<Arc<AtomicBool>>,
    /// Where a restarted run continues, until its stage begins.
    resume: Option<Resume>,
}

impl Restart {
    /// Checkpoints every `every` steps; `interrupt` is raised by a signal.
    pub fn new(every: usize, interrupt: Option<Arc<AtomicBool>>) -> Restart {
        Restart { every, interrupt, resume: None }
    }

    /// The stage the run starts in (a restarted run's: its checkpoint's).
    pub fn resume_stage(&self) -> usize {
        self.resume.map_or(0, |r| r.stage)
    }

    /// A restarted run's step control from its checkpoint (once); whether there was one.
    pub fn resume(&mut self, control: &mut StepControl) -> bool {
        let Some(r) = self.resume.take() else { return false };
        control.dt = r.dt;
        control.successes = r.successes;
        true
    }

    /// Whether any rank was sent SIGINT or SIGTERM (collective).
    pub fn interrupted(&self, coll: &crate::parallel::Collective) -> Result<bool, RunError> {
        let local = self.interrupt.as_ref().is_some_and(|f| f.load(Ordering::SeqCst));
        coll.any(local).map_err(RunError::Failed)
    }
}

impl<const D: usize, const M: usize, const N: usize> Simulation<'_, D, M, N>
where
    Dim<D>: Dimension<D>,
{
    /// After an accepted step in stage `stage_index`: `checkpoint.h5` every `--checkpoint-every`
    /// steps; when `interrupted`, one more and the run stops (`RunError::Interrupted`); otherwise
    /// the running summary's counts kept up to date.
    pub(super) fn checkpoint(
        &mut self,
        stage_index: usize,
        control: &StepControl,
        interrupted: bool,
    ) -> Result<(), RunError> {
        let every = self.restart.every;
        if every > 0 && self.step.is_multiple_of(every) {
            self.write_checkpoint(stage_index, control)?;
        }
        if !interrupted {
            let kept = self.journal.keep_summary(self.step.is_multiple_of(self.case.output.history_every));
            return super::on_every_rank(self.coll, kept);
        }
        self.write_checkpoint(stage_index, control)?;
        Err(RunError::Interrupted(format!(
            "interrupted (SIGINT or SIGTERM) at t = {:.6e} s after {} complete steps; the fields of the last step and \
             checkpoint.h5 are written: continue with `porompm run ... --restart {}`",
            self.t,
            self.step,
            self.journal.out.path_of("checkpoint.h5")
        )))
    }

    /// Writes `checkpoint.h5` after an accepted step in stage `stage_index` (collective).
    fn write_checkpoint(&mut self, stage_index: usize, control: &StepControl) -> Result<(), RunError> {
        let t0 = Instant::now();
        let local = state::records_of(&self.model.particles);
        let slab = self.coll.sorted_slab(&local, state::record_len(D));
        let at = moment_between!(self);
        let mut recorders = Vec::new();
        for r in &self.recorders {
            if let Some(s) = r.state(&at).map_err(RunError::Failed)? {
                recorders.push((r.name().to_string(), s));
            }
        }
        // In the order the file keeps them (and its checksum sees them in).
        recorders.sort_by(|a, b| a.0.cmp(&b.0));
        let s = &*self.journal.summary;
        let cp = Checkpoint {
            case_fingerprint: state::case_fingerprint(self.case),
            time: self.t,
            step: self.step as u64,
            stage: stage_index as u64,
            dt: control.dt,
            successes: control.successes as u64,
            counters: [
                s.step_cuts,
                s.snes_iterations,
                s.ksp_iterations,
                s.matrix_structure_reuses,
                s.line_search_retries,
            ]
            .map(|c| c as u64),
            recorders,
            load_totals: self.model.loads.iter().map(|l| l.increments.as_ref().map_or(0.0, |s| s.total)).collect(),
            dim: D,
            particles: slab.values,
            first: slab.offset as u64,
            total: slab.total as u64,
        };
        self.journal.out.write_checkpoint(&cp, self.coll.communicator()).map_err(RunError::Failed)?;
        self.journal.summary.timings.output_s += t0.elapsed().as_secs_f64();
        Ok(())
    }

    /// Continues from checkpoint `cp` (read from `label`): refuses one of another case, then takes
    /// its particles, time, counters, recorders' states and step control.
    pub(super) fn restore(&mut self, label: &str, cp: &Checkpoint) -> Result<(), RunError> {
        let refuse = |why: String| RunError::Input(format!("cannot restart from checkpoint {label}: {why}"));
        state::check_case(cp, self.case).map_err(refuse)?;
        // The checkpoint's records and the case's points as generated, each redistributed to the
        // same slabs of ids, must match; then every point goes to the rank owning its cell.
        if cp.total as usize != self.journal.summary.particles {
            return Err(refuse(format!(
                "it holds {} material points but this case has {} (a different case or grid)",
                cp.total, self.journal.summary.particles
            )));
        }
        let ps = &self.model.particles;
        let generated: Vec<f64> =
            (0..ps.len()).flat_map(|k| [ps.id[k] as f64, ps.body[k] as f64, ps.material[k] as f64]).collect();
        let generated = self.coll.sorted_slab(&generated, 3).values;
        let generated: Vec<[f64; 3]> = generated.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        let records = self.coll.sorted_slab(&cp.particles, state::record_len(D)).values;
        self.coll.agree(state::check_points(&records, D, &generated)).map_err(refuse)?;
        self.model.particles = state::particles_from_flat(&records);
        crate::distribution::migrate(&mut self.model, self.case, self.system.space().owners(), self.coll);
        self.model.resolve_targets(self.case);
        self.t = cp.time;
        self.model.set_load_increments(self.t, LoadsAt::Restart(&cp.load_totals), self.coll).map_err(failed)?;
        self.step = cp.step as usize;
        let s = &mut *self.journal.summary;
        s.time_s = cp.time;
        s.steps = self.step;
        [s.step_cuts, s.snes_iterations, s.ksp_iterations, s.matrix_structure_reuses, s.line_search_retries] =
            cp.counters.map(|c| c as usize);
        self.system.reused_patterns = s.matrix_structure_reuses;
        let note = self.restore_recorders(cp).map_err(refuse)?;
        if let Some(n) = &note {
            self.journal.progress(&format!("restart: {n}"));
        }
        self.journal.summary.restarted_from =
            Some(state::RestartInfo { checkpoint: label.to_string(), time_s: cp.time, step: self.step, note });
        self.restart.resume = Some(Resume { stage: cp.stage as usize, dt: cp.dt, successes: cp.successes as usize });
        self.journal.progress(&format!("restarted from {label} at t = {:.6e} s, step {}", cp.time, cp.step));
        Ok(())
    }

    /// Every recorder's state from `cp`; what one could not restore, if anything.
    fn restore_recorders(&mut self, cp: &Checkpoint) -> Result<Option<String>, String> {
        let at = moment_between!(self);
        let mut notes = Vec::new();
        for r in self.recorders.iter_mut() {
            let state = cp.recorders.iter().find(|(name, _)| name == r.name()).map(|(_, s)| &s[..]);
            notes.extend(r.restore(crate::recorders::FromCheckpoint {
                state,
                at: &at,
                summary: self.journal.summary,
            })?);
        }
        Ok((!notes.is_empty()).then(|| notes.join("; ")))
    }
}
