//! Setting a run up: its summary, the model, the global system, the recorders and the output;
//! and each stage's start.

use super::control::StepControl;
use super::journal::Journal;
use super::{balance, failed, restart, Dimension, RunError, RunRequest, Simulation};
use crate::analysis::StageAnalysis;
use crate::assembly::{Phase, System};
use crate::case::{Case, Stage, Stiffness};
use crate::io::RunOutput;
use crate::layout::Dim;
use crate::model::{grid_of, Active, Model};
use crate::parallel::Collective;
use crate::progress::Progress;
use crate::summary::Summary;
use std::time::Instant;

/// The summary of a run of `req` that starts.
pub(super) fn summary_of(req: &RunRequest) -> Summary {
    Summary::new(
        req.case_label.clone(),
        req.overrides.clone(),
        req.case.end_time(),
        req.coll.size(),
        crate::assembly::petsc_options().unwrap_or_default(),
    )
}

/// Every face traction acts on some material point: a region that holds no point of its bodies
/// with the loaded face on the material's surface would load nothing, silently. Collective.
fn loads_that_act<const D: usize>(case: &Case, model: &Model<D>, coll: &Collective) -> Result<(), String> {
    for (i, l) in case.loads.iter().enumerate() {
        let crate::case::Load::ParticleTraction(t) = l else { continue };
        let here = model.loads.iter().find(|d| d.name == l.name()).map_or(0, |d| d.size());
        if coll.sum(&[here as f64])?[0] == 0.0 {
            return Err(format!(
                "key `loads[{i}].region`: load `{}` acts on no material point: no point of {} lies in its region \
                 with its {} face on the surface of the material",
                l.name(),
                t.body.as_ref().map_or("any body".to_string(), |b| format!("body `{b}`")),
                serde_json::to_string(&t.face).unwrap_or_default()
            ));
        }
    }
    Ok(())
}

/// `test-jacobian` checks the exact tangent: a case whose Newton matrix is one of [001]'s mapped
/// stiffnesses is refused, naming the way to check it.
pub(super) fn refuse_approximate_tangent(case: &Case) -> Result<(), RunError> {
    if case.jacobian_stiffness() == Stiffness::Particle {
        return Ok(());
    }
    Err(RunError::Input(format!(
        "key `stabilisation.stiffness`: test-jacobian checks the exact tangent, and `{}` replaces its material \
         block by [001]'s approximate stiffness (Newton then converges linearly, by design); check the case \
         with `--set stabilisation.stiffness=particle`",
        case.stabilisation.stiffness.name()
    )))
}

impl<'a, const D: usize, const M: usize, const N: usize> Simulation<'a, D, M, N>
where
    Dim<D>: Dimension<D>,
{
    /// The run of `req`: the global system of its first stage's unknowns (a restarted run's:
    /// its checkpoint's stage), the model on this rank's cells, the recorders, the history's
    /// columns and the field output; then the checkpoint's state or the loads' start, and the
    /// recorders' first observation (step 0).
    pub(super) fn set_up(
        req: &RunRequest<'a>,
        out: &'a mut RunOutput,
        summary: &'a mut Summary,
    ) -> Result<Simulation<'a, D, M, N>, RunError> {
        let t0 = Instant::now();
        let (case, coll) = (req.case, req.coll);
        let input = |e: String| RunError::Input(e);
        let first = req.restart.as_ref().map_or(0, |(_, cp)| cp.stage as usize).min(case.stages.len() - 1);
        let layout = StageAnalysis::of(case, &case.stages[first]).layout.in_dim(D);
        let system = System::<D, M, N>::new(coll, &grid_of(case), layout, None, case.jacobian_stiffness())
            .map_err(|e| input(e.to_string()))?;
        let setup_stage = system.phase(Phase::Setup).map_err(|e| input(e.to_string()))?;
        let model = Model::<D>::of_case(case, |c| system.space().owns_cell_in(c));
        loads_that_act(case, &model, coll).map_err(input)?;
        let recorders = crate::recorders::registered(case, &model, coll).map_err(input)?;
        summary.particles = coll.sum(&[model.particles.len() as f64]).map_err(input)?[0] as usize;
        summary.grid_dofs = system.space().total_dofs();
        let columns: Vec<String> = recorders.iter().flat_map(|r| r.columns()).collect();
        coll.agree(out.begin(&*summary)).map_err(input)?;
        coll.agree(out.start_history(&columns)).map_err(input)?;
        if case.output.fields_every > 0 {
            out.start_fields(crate::fields::grid_geometry(&model), coll.communicator()).map_err(input)?;
        }
        drop(setup_stage);
        summary.timings.setup_s = t0.elapsed().as_secs_f64();
        let display = Progress::new(!req.quiet && coll.rank() == 0, coll.rank() == 0, case.end_time());
        let nodes = system.space().block_of(&[]);
        let mut sim = Simulation {
            case,
            coll,
            model,
            system,
            t: 0.0,
            step: 0,
            recorders,
            journal: Journal::new(out, summary, display, columns),
            nodes,
            last_reactions: Vec::new(),
            balance: balance::Balance::new(req.balance_threshold),
            restart: restart::Restart::new(req.checkpoint_every, req.interrupt.clone()),
            grip: Vec::new(),
            stage_start: false,
        };
        let warnings = crate::diagnostics::physics::warnings(case, &sim.model);
        sim.journal.warn(warnings);
        match &req.restart {
            Some((label, cp)) => sim.restore(label, cp)?,
            None => sim.model.set_load_increments(0.0, crate::model::LoadsAt::Start, coll).map_err(RunError::Input)?,
        }
        sim.observe(0.0, (0, 0), None, true)?;
        sim.journal.summary.memory.peak_rise.setup_mib = crate::io::peak_memory_mib().unwrap_or(0.0);
        sim.milestone()?;
        Ok(sim)
    }

    /// Sets the stage's analysis type up: its time treatment and its materials' strengths on the
    /// model and, when its unknowns per node differ from the last stage's, a new global system
    /// (DMDA, matrix, SNES) for them. Returns the stage's loads and boundaries and its step
    /// control (a restarted run's from its checkpoint).
    pub(super) fn begin_stage(&mut self, index: usize, stage: &Stage) -> Result<(Active, StepControl), RunError> {
        let analysis = StageAnalysis::of(self.case, stage);
        self.model.integration = analysis.integration;
        self.model.take_stage_materials(self.case, stage);
        self.system.forget_increment();
        let layout = analysis.layout.in_dim(D);
        if self.system.layout() != layout {
            let owners = self.system.space().owners().clone();
            self.replace_system(layout, &owners)?;
        }
        let end: f64 = self.case.stages[..=index].iter().map(|s| s.duration).sum();
        let mut control = StepControl::new(stage, end, analysis.dt_limit);
        let resumed = self.restart.resume(&mut control);
        let active = self.model.active(stage);
        // The ledger books the first step of a stage from the balance of its start (not of a
        // stage a restart resumes, whose start was booked before).
        self.stage_start = !resumed;
        self.journal.progress(&format!(
            "stage `{}` ({}): t = {:.6e} → {:.6e} s, Δt = {:.3e} s",
            stage.name,
            analysis.describe(),
            self.t,
            control.t_end,
            control.dt
        ));
        Ok((active, control))
    }

    /// A new global system with `layout` on the distribution `owners`, keeping the count of reused
    /// matrix structures; the last step's reactions belong to the old one.
    pub(super) fn replace_system(
        &mut self,
        layout: crate::layout::Layout,
        owners: &crate::distribution::Owners<D>,
    ) -> Result<(), RunError> {
        let reused = self.system.reused_patterns;
        self.system = System::new(self.coll, &self.model.grid, layout, Some(owners), self.case.jacobian_stiffness())
            .map_err(failed)?;
        self.system.reused_patterns = reused;
        self.last_reactions = Vec::new();
        self.journal.summary.grid_dofs = self.system.space().total_dofs();
        Ok(())
    }
}
