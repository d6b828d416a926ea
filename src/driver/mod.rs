//! The algorithm on one page.
//!
//! ```text
//! run
//! ├── set up: model, global system, recorders, output                 (setup.rs)
//! ├── for each stage:                                                  run_stage
//! │   └── until the stage ends:                                        (the step loop)
//! │       ├── Δt ← the step control's (cuts, regrowth, events, stage end; control.rs)
//! │       ├── advance: prepare the step, solve it (Newton; explicit: the nodal update), its
//! │       │   forces, the particle update ([003] Eq. 24, [000] Eq. 11)  (step.rs)
//! │       ├── admitted: accept (time, loads, points to their ranks, load balance; balance.rs)
//! │       │   and record (the recorders, history.csv, fields, checkpoints; restart.rs)
//! │       └── not admitted: cut Δt and retry; fail after the stage's max_step_cuts
//! └── finish: the recorders' findings, figures, summary.json
//! ```
//!
//! A restarted run (`--restart`) sets up as usual, then takes the particles, time, step, stage,
//! step control and recorders' states from the checkpoint ([`crate::state`]) and continues in that
//! stage.

/// The run between steps ([`Moment::between`]) of a `Simulation`, borrowing only the fields it
/// reads, so that the recorders can be borrowed mutably beside it.
macro_rules! moment_between {
    ($sim:expr) => {
        crate::recorders::Moment::between(
            &$sim.model,
            $sim.coll,
            $sim.system.space().owners(),
            ($sim.t, $sim.step),
            &$sim.nodes,
        )
    };
}

mod balance;
mod control;
mod journal;
mod restart;
mod setup;
mod step;

use crate::assembly::{BlockCheck, NodeBlock, StepDim, System};
use crate::case::{Case, Stage};
use crate::io::RunOutput;
use crate::kernels::{MAX_NODES, MAX_NODES_3D};
use crate::layout::{Dim, MAX_DOF, MAX_DOF_3D};
use crate::model::{Active, Model};
use crate::parallel::Collective;
use crate::recorders::{Moment, Recorder, Sink};
use crate::state::Checkpoint;
use crate::summary::Summary;
use crate::verification::CaseChecks;
use control::StepControl;
use journal::Journal;
use std::path::PathBuf;
use std::time::Instant;

/// What a run is asked to do.
pub struct RunRequest<'a> {
    /// The validated case.
    pub case: &'a Case,
    /// How the case was named on the command line.
    pub case_label: String,
    /// The `--set` overrides, as given.
    pub overrides: Vec<String>,
    /// Output directory.
    pub out_dir: PathBuf,
    /// No progress lines.
    pub quiet: bool,
    /// The run's ranks.
    pub coll: &'a Collective,
    /// Write `checkpoint.h5` every this many steps (0: never).
    pub checkpoint_every: usize,
    /// Repartition when the load imbalance passes this ratio (see [`crate::distribution`]).
    pub balance_threshold: f64,
    /// Continue from this checkpoint (its path as given, and its content).
    pub restart: Option<(String, Checkpoint)>,
    /// Set by `main`'s SIGINT/SIGTERM handler: stop after the current step.
    pub interrupt: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
}

/// Why a run stopped early.
#[derive(Debug, Clone)]
pub enum RunError {
    /// Bad input discovered while setting up or on the first solve (e.g. an unused PETSc option).
    Input(String),
    /// The run could not continue (e.g. a step that does not converge after the allowed cuts).
    Failed(String),
    /// SIGINT or SIGTERM: the run stopped after a complete step, with its fields and a checkpoint.
    Interrupted(String),
}

impl RunError {
    /// The message.
    pub fn message(&self) -> &str {
        match self {
            RunError::Input(m) | RunError::Failed(m) | RunError::Interrupted(m) => m,
        }
    }

    /// The same error with `note` added to its message.
    fn noting(self, note: &str) -> RunError {
        match self {
            RunError::Input(m) => RunError::Input(format!("{m}; {note}")),
            RunError::Failed(m) => RunError::Failed(format!("{m}; {note}")),
            RunError::Interrupted(m) => RunError::Interrupted(format!("{m}; {note}")),
        }
    }
}

/// Refuses a case whose memory ([`crate::model::memory::Estimate`], without a direct solver's
/// factors) does not fit in what the machines running it have available, before anything is
/// allocated: each machine needs its ranks' share. Collective.
fn memory_fits(case: &Case, coll: &Collective) -> Result<(), RunError> {
    use crate::model::memory::{Estimate, BASE_BYTES};
    let e = Estimate::of(case);
    let machine = crate::io::machine_id();
    let here = coll.gather_of(&[machine]).iter().filter(|&&m| m == machine).count() as f64;
    let need = (e.needed - BASE_BYTES) * here / coll.size() as f64 + BASE_BYTES * here;
    let fits = match crate::io::available_memory() {
        Some(free) if need > free => Err(e.refusal(need, free)),
        _ => Ok(()),
    };
    coll.agree(fits).map_err(RunError::Input)
}

/// `result` made the same on every rank: what rank 0 alone writes (history rows, the running
/// summary, the fields' index) can fail there alone, and the other ranks would then wait for it
/// in their next collective call. Collective.
fn on_every_rank<T>(coll: &Collective, result: Result<T, RunError>) -> Result<T, RunError> {
    let agreed = coll.agree(result.as_ref().map(|_| ()).map_err(|e| e.message().to_string()));
    match (result, agreed) {
        (Err(e), _) => Err(e),
        (Ok(_), Err(m)) => Err(RunError::Failed(m)),
        (Ok(v), Ok(())) => Ok(v),
    }
}

/// A failure of the run's machinery (PETSc, MPI, files) while it runs.
fn failed(e: impl ToString) -> RunError {
    RunError::Failed(e.to_string())
}

/// What dimension-generic code needs of the dimension: its step's features ([`StepDim`]) and its
/// verification checks ([`CaseChecks`]).
pub trait Dimension<const D: usize>: StepDim<D> + CaseChecks<D> {}

impl<const D: usize> Dimension<D> for Dim<D> where Dim<D>: StepDim<D> + CaseChecks<D> {}

/// Runs a case and returns its summary (also written to `summary.json`).
pub fn run(req: &RunRequest, out: &mut RunOutput) -> (Summary, Option<RunError>) {
    let start = Instant::now();
    let mut summary = setup::summary_of(req);
    let result = match req.case.dimension() {
        3 => run_in::<3, { MAX_NODES_3D }, { MAX_DOF_3D }>(req, out, &mut summary),
        _ => run_in::<2, { MAX_NODES }, { MAX_DOF }>(req, out, &mut summary),
    };
    // The field files' index lists every output time, also of a failed run.
    let indexed = out.finish_fields();
    let result = result.and_then(|_| indexed.map_err(RunError::Failed));
    journal::settle(&mut summary, req.coll, start);
    let err = result.err();
    summary.settle(err.as_ref().map(|e| (e.message(), matches!(e, RunError::Interrupted(_)))));
    // A run that failed before it began leaves the directory as it was (the error is its record).
    let written = if out.has_begun() { out.write_summary(&summary) } else { Ok(()) };
    match (err, written) {
        (Some(e), Ok(())) => (summary, Some(e)),
        (Some(e), Err(w)) => (summary, Some(e.noting(&format!("summary.json was not updated: {w}")))),
        (None, Err(w)) => (summary, Some(RunError::Failed(w))),
        (None, Ok(())) => (summary, None),
    }
}

/// The run of [`run`] in dimension D: set up, the stages, the end. A failed run still reports
/// what its recorders saw up to the failure (results, tables, metrics of the events it reached);
/// its status stays `failed`.
fn run_in<const D: usize, const M: usize, const N: usize>(
    req: &RunRequest,
    out: &mut RunOutput,
    summary: &mut Summary,
) -> Result<(), RunError>
where
    Dim<D>: Dimension<D>,
{
    memory_fits(req.case, req.coll)?;
    let mut sim = Simulation::<D, M, N>::set_up(req, out, summary)?;
    let stages = sim.run_stages();
    let finished = sim.finish();
    stages.and(finished)
}

/// Runs `steps` steps of the first stage, prepares the next one and compares its assembled tangent
/// with central finite differences of the assembled residual, block by block (one rank, small
/// cases; see `assembly::check`). `flip` negates one (row field, column field) block of the
/// assembled tangent first, to see the check fail. Also returns how many material points have
/// yielded (ε̄ > 0), so that a check of a plastic case can tell that the plastic tangent took part.
/// Nothing is written.
pub fn test_jacobian(
    req: &RunRequest,
    steps: usize,
    flip: Option<(usize, usize)>,
) -> Result<(Vec<BlockCheck>, usize), RunError> {
    setup::refuse_approximate_tangent(req.case)?;
    match req.case.dimension() {
        3 => test_jacobian_in::<3, { MAX_NODES_3D }, { MAX_DOF_3D }>(req, steps, flip),
        _ => test_jacobian_in::<2, { MAX_NODES }, { MAX_DOF }>(req, steps, flip),
    }
}

/// [`test_jacobian`] in dimension D.
fn test_jacobian_in<const D: usize, const M: usize, const N: usize>(
    req: &RunRequest,
    steps: usize,
    flip: Option<(usize, usize)>,
) -> Result<(Vec<BlockCheck>, usize), RunError>
where
    Dim<D>: Dimension<D>,
{
    let mut summary = setup::summary_of(req);
    let mut out = RunOutput::silent();
    let mut sim = Simulation::<D, M, N>::set_up(req, &mut out, &mut summary)?;
    let stage = &req.case.stages[0];
    let (active, _) = sim.begin_stage(0, stage)?;
    for _ in 0..steps {
        sim.advance(&active, stage.dt(), false)?.map_err(RunError::Failed)?;
        sim.t += stage.dt();
    }
    let step =
        sim.system.prepare(&sim.model, &active, (sim.t + stage.dt(), stage.dt()), false, sim.coll).map_err(failed)?;
    let blocks = sim.system.jacobian_check(&step, &sim.model, sim.coll, 0.7, flip).map_err(failed)?;
    Ok((blocks, sim.model.particles.eps_pd.iter().filter(|&&e| e > 0.0).count()))
}

/// A run on a grid of dimension D whose points have at most M stencil nodes of at most N dofs:
/// the same algorithm in two and three dimensions.
struct Simulation<'a, const D: usize, const M: usize, const N: usize> {
    case: &'a Case,
    coll: &'a Collective,
    model: Model<D>,
    system: System<D, M, N>,
    /// The time reached [s] and the steps accepted.
    t: f64,
    step: usize,
    /// What records the run, in the order of its history columns.
    recorders: Vec<Box<dyn Recorder<D>>>,
    /// summary.json, history.csv, the progress display.
    journal: Journal<'a>,
    /// The last step's nodal values on this rank (for the fields).
    nodes: NodeBlock,
    /// The reactions per ghosted dof of the last converged step on this system (for the work of
    /// the next).
    last_reactions: Vec<f64>,
    /// The load balance over the ranks.
    balance: balance::Balance,
    /// Checkpoints and interrupts.
    restart: restart::Restart,
    /// The filled fraction of each moving boundary's nodes when it was first seen, and whether
    /// the run has warned that the material left them.
    grip: Vec<(Option<f64>, bool)>,
    /// Whether the next step is the first of its stage.
    stage_start: bool,
}

/// The outcome of a step that converged and was admitted: its Newton and Krylov iterations and
/// the energy of a dynamic step.
struct Admitted {
    iterations: (usize, usize),
    energy: Option<(f64, [f64; 5])>,
}

impl<const D: usize, const M: usize, const N: usize> Simulation<'_, D, M, N>
where
    Dim<D>: Dimension<D>,
{
    /// The stage loop: every stage in turn (a restarted run from its checkpoint's), until a
    /// recorder asks to stop.
    fn run_stages(&mut self) -> Result<(), RunError> {
        let first = self.restart.resume_stage();
        for (index, stage) in self.case.stages.iter().enumerate().skip(first) {
            if let Some(why) = self.run_stage(index, stage)? {
                self.journal.progress(&format!("stopped at t = {:.6e} s: {why}", self.t));
                self.journal.summary.stopped = Some(why);
                break;
            }
        }
        Ok(())
    }

    /// The step loop of one stage; Some(reason) when a recorder asks the run to stop.
    fn run_stage(&mut self, index: usize, stage: &Stage) -> Result<Option<String>, RunError> {
        let (active, mut control) = self.begin_stage(index, stage)?;
        while !control.finished(self.t) {
            let events: Vec<f64> = self.recorders.iter().flat_map(|r| r.event_times()).collect();
            let dt = control.next(self.t, &events);
            match self.advance(&active, dt, control.ends_stage(self.t, dt))? {
                Ok(admitted) => {
                    self.accept(dt, &mut control, admitted.iterations.0)?;
                    if let Some(why) = self.record(stage, index, &control, dt, admitted)? {
                        return Ok(Some(why));
                    }
                }
                Err(why) => self.cut(stage, &mut control, dt, why)?,
            }
        }
        Ok(None)
    }

    /// One step t → t + dt: the step set-up, the nonlinear solve, the step's forces and the
    /// particle update (`stage_end`: the step, once accepted, ends its stage). `Ok(Err(reason))`:
    /// the step was not admitted (no convergence, or a point would become inadmissible), and
    /// nothing changed.
    fn advance(&mut self, active: &Active, dt: f64, stage_end: bool) -> Result<Result<Admitted, String>, RunError> {
        let step = self.prepare(active, dt)?;
        let (solved, solution) = self.solve(&step)?;
        if !solved.converged {
            return Ok(Err(self.why_not(solved)?));
        }
        let iterations = (solved.newton_iterations, solved.linear_iterations);
        let updated = self.update_particles(&step, &solution, active, (dt, stage_end))?;
        Ok(updated.map(|u| {
            let fields = self.system.layout().fields();
            let scales = (&solved.field_scales[..], &u.field_scales[..]);
            let summary = &mut *self.journal.summary;
            summary.fold_field_residuals(&fields, &solved.field_residuals, scales, &solved.linear_field_residuals);
            Admitted { iterations, energy: u.energy }
        }))
    }

    /// After an admitted step: the time, the loads that follow their faces, the step control,
    /// the points to the ranks that own their cells and the load balance.
    fn accept(&mut self, dt: f64, control: &mut StepControl, newton: usize) -> Result<(), RunError> {
        self.system.accept_increment(dt).map_err(failed)?;
        self.stage_start = false;
        self.migrate_particles()?;
        self.balance_load()?;
        self.t = control.advance(self.t, dt);
        self.model.set_load_increments(self.t, crate::model::LoadsAt::Accepted, self.coll).map_err(failed)?;
        control.accepted(newton);
        self.step += 1;
        self.journal.summary.steps = self.step;
        self.journal.summary.time_s = self.t;
        Ok(())
    }

    /// After a step that was not admitted: Δt cut, or the run fails once the stage's cuts are
    /// spent.
    fn cut(&mut self, stage: &Stage, control: &mut StepControl, dt: f64, why: String) -> Result<(), RunError> {
        self.journal.summary.step_cuts += 1;
        if control.rejected(dt).is_err() {
            return Err(RunError::Failed(format!(
                "stage `{}`: the step from t = {:.6e} s did not converge after {} cuts of Δt (last Δt = {:.3e} s): {why}",
                stage.name, self.t, stage.max_step_cuts, dt
            )));
        }
        self.journal.progress(&format!("  step from t = {:.6e} s cut to Δt = {:.3e} s: {why}", self.t, control.dt));
        Ok(())
    }

    /// The recorders after an accepted step (a history row every `output.history_every` steps and
    /// at the stage's end), the fields and checkpoints; Some(reason) when a recorder asks to stop.
    fn record(
        &mut self,
        stage: &Stage,
        index: usize,
        control: &StepControl,
        dt: f64,
        admitted: Admitted,
    ) -> Result<Option<String>, RunError> {
        let every = self.case.output.history_every;
        let finished = control.finished(self.t);
        let row = self.step.is_multiple_of(every) || finished;
        self.observe(dt, admitted.iterations, admitted.energy, row)?;
        self.journal.step(&stage.name, self.step, self.t, admitted.iterations.0);
        let stopping = self.recorders.iter().find_map(|r| r.stop());
        let interrupted = self.restart.interrupted(self.coll)?;
        if (stopping.is_some() || interrupted) && !row {
            self.observe(dt, admitted.iterations, None, true)?;
        }
        if finished || stopping.is_some() || interrupted {
            self.milestone()?;
        }
        self.checkpoint(index, control, interrupted)?;
        Ok(stopping)
    }

    /// Every recorder's observation of the run now, and the history row when `row`.
    fn observe(
        &mut self,
        dt: f64,
        iterations: (usize, usize),
        energy: Option<(f64, [f64; 5])>,
        row: bool,
    ) -> Result<(), RunError> {
        let t0 = Instant::now();
        let _stage = self.system.phase(crate::assembly::Phase::Output).map_err(failed)?;
        let at = Moment {
            model: &self.model,
            coll: self.coll,
            owners: self.system.space().owners(),
            t: self.t,
            dt,
            step: self.step,
            iterations,
            energy,
            nodes: &self.nodes,
        };
        let recorded = self.journal.with_sink(|sink: &mut Sink| {
            let mut values = Vec::new();
            for r in self.recorders.iter_mut() {
                values.extend(r.record(&at, row, sink)?);
            }
            Ok(values)
        });
        let recorded = recorded.and_then(|(values, warnings)| match row {
            true => self.journal.history_row(&values).map(|_| warnings),
            false => Ok(warnings),
        });
        let warnings = on_every_rank(self.coll, recorded)?;
        self.journal.warn(warnings);
        self.journal.summary.timings.output_s += t0.elapsed().as_secs_f64();
        Ok(())
    }

    /// The recorders at a milestone: the run's start, a stage's end, an early stop, an interrupt.
    fn milestone(&mut self) -> Result<(), RunError> {
        let at = moment_between!(self);
        let recorded = self.journal.with_sink(|sink: &mut Sink| {
            for r in self.recorders.iter_mut() {
                r.milestone(&at, sink)?;
            }
            Ok(())
        });
        let (_, warnings) = on_every_rank(self.coll, recorded)?;
        self.journal.warn(warnings);
        Ok(())
    }

    /// The end of the run (also of a failed one): the recorders' findings and figures.
    fn finish(mut self) -> Result<(), RunError> {
        let t0 = Instant::now();
        if self.journal.summary.solver.is_empty() {
            self.journal.summary.solver = "none (explicit steps only)".into();
        }
        let _stage = self.system.phase(crate::assembly::Phase::Output).map_err(failed)?;
        let at = moment_between!(self);
        let mut figures = Vec::new();
        let recorded = self.journal.with_sink(|sink: &mut Sink| {
            let mut first_error = Ok(());
            for r in self.recorders.iter_mut() {
                let done = r.finish(&at, sink);
                first_error = first_error.and(done);
            }
            figures = std::mem::take(&mut sink.figures);
            first_error
        });
        let (_, warnings) = on_every_rank(self.coll, recorded)?;
        self.journal.warn(warnings);
        self.journal.figures(figures);
        self.journal.summary.timings.output_s += t0.elapsed().as_secs_f64();
        Ok(())
    }
}
