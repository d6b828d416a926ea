//! The algorithm on one page.
//!
//! ```text
//! run
//! ├── set up: grid system (DMDA, SNES), material points, verification check, probes, output
//! ├── for each stage:                                   run_stage
//! │   └── until the stage ends:                         (time-step loop)
//! │       ├── Δt ← min(stage Δt after cuts, time to the next event / stage end)
//! │       ├── newton_solve: map to grid, constraints, loads; SNES on the Newmark residual
//! │       ├── if converged: update_particles ([003] Eq. 24, [000] Eq. 11) unless inadmissible
//! │       │   (full Newton steps; if they fail, once more with a line search)
//! │       ├── if not: cut Δt (stage.cut_factor), retry; fail after stage.max_step_cuts cuts in a row
//! │       ├── record_step: probes, check, history.csv
//! │       └── every output.fields_every steps and at the stage end: fields.h5/.xdmf;
//! │           every --checkpoint-every steps: checkpoint.h5
//! └── finish: verification metrics, summary.json
//! ```
//!
//! A restarted run (`--restart`) sets up as usual, then takes the particles, time, step, stage and
//! step control from the checkpoint ([`crate::state`]) and continues in that stage.

use crate::analysis::StageAnalysis;
use crate::assembly::{self, GridSystem, Phase, StepForces};
use crate::case::{Case, Stage};
use crate::diagnostics::{energy, Monitor, Warning};
use crate::io::RunOutput;
use crate::kernels::{Integration, StepResult, MAX_DOF, MAX_DOF_3D, MAX_NODES, MAX_NODES_3D};
use crate::model::loads::IncrementsFrom;
use crate::model::Model;
use crate::parallel::Collective;
use crate::progress::Progress;
use crate::state::{self, Checkpoint};
use crate::verification::{self, Check, Metric};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::Instant;

/// When the loads that follow their faces are set (see `Simulation::set_load_increments`).
#[derive(Clone, Copy)]
enum LoadsAt<'a> {
    /// The run's start.
    Start,
    /// The end of an accepted step.
    Accepted,
    /// A restart, with the checkpoint's sums of increments per load.
    Restart(&'a [f64]),
}

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
}

/// How well one field's equations were solved over a run (see `Summary::field_residuals`).
#[derive(Debug, Clone, Serialize)]
pub struct FieldResidual {
    /// The field: `u` (solid displacement), `p` (pore pressure) or `U` (water displacement).
    pub field: String,
    /// The largest final Newton residual of the field's rows over a converged step, relative to
    /// the norm of the field's force magnitudes in that step (the sum of the absolute values of
    /// the terms of its equations: stress, pressure, inertia, drag, flow, loads). The Newton test
    /// of PETSc sees the fields through one norm; this shows each one.
    pub newton_final_max: f64,
    /// The largest relative residual of the field after a linear solve, ‖(b − A x)_f‖ over the
    /// larger of ‖b_f‖ and the largest block term ‖A_fg x_g‖ (null when not measured, under
    /// Eisenstat–Walker). A Krylov solve stopped at `-ksp_rtol` should leave it near that
    /// tolerance in every field; a direct solve leaves it at round-off.
    pub linear_max: Option<f64>,
}

/// Wall time per phase [s].
#[derive(Debug, Clone, Default, Serialize)]
pub struct Timings {
    /// Setting up (grid, particles, solver).
    pub setup_s: f64,
    /// Mapping to the grid, constraints, loads, matrix creation, every step.
    pub step_setup_s: f64,
    /// Residual and Jacobian assembly (inside the Newton solves).
    pub assembly_s: f64,
    /// Linear solves and the rest of SNES (Newton solve time minus assembly).
    pub linear_solve_s: f64,
    /// Particle updates.
    pub particle_update_s: f64,
    /// Writing results.
    pub output_s: f64,
    /// The mean wall time of one mat-vec with the whole tangent (rank 0), timed after the linear
    /// solves where the field residuals are measured: the unit of a Krylov iteration's cost.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tangent_matvec_s: Option<f64>,
}

/// `summary.json`.
#[derive(Debug, Clone, Serialize)]
pub struct Summary {
    /// "running", "completed" or "failed".
    pub status: String,
    /// Why the run failed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// The case file.
    pub case: String,
    /// `--set` overrides.
    pub overrides: Vec<String>,
    /// porompm version and git revision.
    pub porompm_version: String,
    /// Wall time of the run [s].
    pub wall_time_s: f64,
    /// Simulated time reached [s].
    pub time_s: f64,
    /// Simulated time asked for [s].
    pub end_time_s: f64,
    /// Converged steps.
    pub steps: usize,
    /// Step cuts (retries with smaller Δt).
    pub step_cuts: usize,
    /// Steps whose full Newton steps failed and that were solved again with a line search
    /// (`assembly::LINE_SEARCH_RETRY`), converged or not.
    pub line_search_retries: usize,
    /// Material points that moved to another rank over the run (since the restart, if restarted).
    pub migrated_particles: usize,
    /// Repartitions of the grid over the ranks to balance the material points.
    pub repartitions: usize,
    /// The largest load imbalance at a history row (the busiest rank's points over the mean).
    pub load_imbalance_max: f64,
    /// porompm's own collective operations on rank 0 over the run (reductions, gathers, the
    /// migration and output exchanges; PETSc's own messages are in its `-log_view`).
    pub collectives: crate::parallel::Traffic,
    /// Newton iterations over the run.
    pub snes_iterations: usize,
    /// Krylov iterations over the run.
    pub ksp_iterations: usize,
    /// Steps whose matrix kept the previous step's nonzero structure (so the symbolic
    /// factorisation was reused).
    pub matrix_structure_reuses: usize,
    /// The residual of each field (u, p, U) relative to its own scale, the largest over the
    /// converged steps of the run (since the restart, if restarted).
    pub field_residuals: Vec<FieldResidual>,
    /// Unknowns of the last step (unconstrained dofs).
    pub dofs: usize,
    /// Dofs of the whole grid.
    pub grid_dofs: usize,
    /// Material points.
    pub particles: usize,
    /// MPI ranks.
    pub ranks: usize,
    /// The solver actually used.
    pub solver: String,
    /// PETSc's options database.
    pub petsc_options: Vec<String>,
    /// Wall time per phase.
    pub timings: Timings,
    /// Peak resident memory of the process (rank 0) at the end of the run [MiB]: `VmHWM` of
    /// `/proc/self/status`, absent where the system does not report it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub peak_memory_mib: Option<f64>,
    /// The sum of every rank's peak resident memory [MiB] (equal to `peak_memory_mib` on one rank).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub peak_memory_total_mib: Option<f64>,
    /// Largest checkerboard index of the pore pressures over the output steps (two-phase runs; see
    /// `verification::checkerboard`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub checkerboard_index_max: Option<f64>,
    /// Largest pressure oscillation index over the output steps (two-phase runs; see
    /// `diagnostics::Monitor::row`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pressure_oscillation_index_max: Option<f64>,
    /// Smallest and largest particle pore pressure over the output steps [Pa] (two-phase runs).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pore_pressure_range: Option<[f64; 2]>,
    /// The relative energy imbalance of the dynamic stages at the last history row (see
    /// `diagnostics::energy`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub energy_balance_error: Option<f64>,
    /// Warnings: parameter combinations known to lock or oscillate (before the run) and
    /// diagnostics past their thresholds (during it), each with what to change.
    pub warnings: Vec<Warning>,
    /// The worst relative error of the equilibrium identity ∫σ dV = Σ x ⊗ (F_ext + R − F_inertia)
    /// over the converged steps (see `Simulation::record_equilibrium`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub equilibrium_error: Option<f64>,
    /// Why the run ended before the last stage's end although nothing failed (e.g. a footing
    /// that reached the settlement its check stops at).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stopped: Option<String>,
    /// Metrics against the case's analytical reference.
    pub verification: BTreeMap<String, Metric>,
    /// Quantities computed from the run without a reference to compare with: per probe the final
    /// displacement magnitude `<probe>.displacement` [m], in two-phase runs the excess pore pressure
    /// of largest magnitude (signed) `<probe>.excess_p_peak` and at the end `<probe>.excess_p_final`
    /// [Pa]; and the check's own (e.g. the bearing pressure at given settlements).
    pub results: BTreeMap<String, f64>,
    /// Whether every metric passed (absent without verification).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub verification_passed: Option<bool>,
    /// The checkpoint this run continued from.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub restarted_from: Option<state::RestartInfo>,
}

/// A probe: the particle nearest to a point at t = 0, and what is tracked over the run.
struct Probe {
    name: String,
    id: u64,
    /// Its values after the last step ([`probe_fields`] order).
    last: Vec<f64>,
    /// The excess pore pressure of largest magnitude so far, with its sign.
    excess_extreme: f64,
}

/// Fraction of its first filled fraction below which a moving boundary's nodes have lost their grip
/// on the material (see [`Simulation::check_boundary_grip`]).
const GRIP_FRACTION: f64 = 0.5;

/// A run on a grid of dimension D whose points have at most M stencil nodes of at most N dofs
/// (see [`GridSystem`]): the same algorithm in two and three dimensions.
struct Simulation<'a, const D: usize = 2, const M: usize = { MAX_NODES }, const N: usize = { MAX_DOF }> {
    case: &'a Case,
    model: Model<D>,
    system: GridSystem<D, M, N>,
    check: Option<Box<dyn Check<D>>>,
    probes: Vec<Probe>,
    out: &'a mut RunOutput,
    coll: &'a Collective,
    display: Progress,
    t: f64,
    step: usize,
    summary: &'a mut Summary,
    options_checked: bool,
    /// The filled fraction of each moving boundary's nodes when it was first seen, and whether the
    /// run has warned that the material left them (see [`Simulation::check_boundary_grip`]).
    boundary_grip: Vec<(Option<f64>, bool)>,
    /// When the running summary.json was last rewritten.
    summary_written: Instant,
    last_newton: (usize, usize),
    /// The last converged solve's field residual norms, its fields' scales at the step's start
    /// and its linear solves' worst field residuals, until the step is accepted.
    last_field_residuals: (Vec<f64>, Vec<f64>, Vec<f64>),
    /// The columns and rows of history.csv, kept for the probe figures.
    history: (Vec<String>, Vec<Vec<f64>>),
    /// Where a restarted run continues: the stage's index, its Δt and accepted steps at that Δt.
    resume: Option<(usize, f64, usize)>,
    /// Step of the last field output.
    fields_step: Option<usize>,
    checkpoint_every: usize,
    /// `main`'s SIGINT/SIGTERM flag.
    interrupt: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
    /// Names of the bodies (for messages).
    body_names: Vec<String>,
    /// The last converged step's equilibrium error and boundary reactions.
    equilibrium: (f64, Vec<[f64; D]>),
    /// The stability diagnostics.
    monitor: Monitor,
    /// `--balance-threshold`, and the imbalance after the last attempt to repartition (a new
    /// attempt waits until the imbalance has grown by [`crate::distribution::BALANCE_GAIN`]).
    balance: (f64, Option<f64>),
}

/// Runs a case and returns its summary (also written to `summary.json`).
pub fn run(req: &RunRequest, out: &mut RunOutput) -> (Summary, Option<RunError>) {
    let start = Instant::now();
    let mut summary = Summary::new(req);
    let result = out.write_summary(&summary).map_err(RunError::Input).and_then(|_| match req.case.dimension() {
        3 => run_in::<3, { MAX_NODES_3D }, { MAX_DOF_3D }>(req, out, &mut summary),
        _ => run_in::<2, { MAX_NODES }, { MAX_DOF }>(req, out, &mut summary),
    });
    // The field files' index lists every output time, also of a failed run.
    let indexed = out.finish_fields();
    let result = result.and_then(|_| indexed.map_err(RunError::Failed));
    summary.wall_time_s = start.elapsed().as_secs_f64();
    summary.peak_memory_mib = crate::io::peak_memory_mib();
    // Collective: every rank reaches this point (a failed run's error was agreed by all ranks).
    summary.peak_memory_total_mib = match summary.peak_memory_mib {
        Some(m) => req.coll.sum(&[m]).ok().map(|v| v[0]),
        None => None,
    };
    summary.petsc_options = assembly::petsc_options().unwrap_or_default();
    summary.collectives = req.coll.traffic();
    let err = result.err();
    match &err {
        None => summary.status = "completed".into(),
        Some(RunError::Interrupted(m)) => {
            summary.status = "interrupted".into();
            summary.error = Some(m.clone());
            if summary.verification_passed.is_some() {
                summary.verification_passed = Some(false);
            }
        }
        Some(e) => {
            summary.status = "failed".into();
            summary.error = Some(e.message().to_string());
            // Metrics of a failed run are partial: they never count as a pass.
            if summary.verification_passed.is_some() {
                summary.verification_passed = Some(false);
            }
        }
    }
    let written = out.write_summary(&summary);
    match (err, written) {
        (Some(e), _) => (summary, Some(e)),
        (None, Err(w)) => (summary, Some(RunError::Failed(w))),
        (None, Ok(())) => (summary, None),
    }
}

/// The run of [`run`] in dimension D: set up, the stages, the end.
fn run_in<const D: usize, const M: usize, const N: usize>(
    req: &RunRequest,
    out: &mut RunOutput,
    summary: &mut Summary,
) -> Result<(), RunError> {
    let mut sim = Simulation::<D, M, N>::set_up(req, out, summary)?;
    let stages = sim.run_stages(&req.case.stages);
    match stages {
        Ok(()) => sim.finish(),
        Err(e) => {
            // A failed run still reports what its probes and check saw up to the failure
            // (results, tables, metrics of the events it reached); its status stays `failed`.
            let _ = sim.finish();
            Err(e)
        }
    }
}

impl Summary {
    fn new(req: &RunRequest) -> Summary {
        Summary {
            status: "running".into(),
            error: None,
            case: req.case_label.clone(),
            overrides: req.overrides.clone(),
            porompm_version: crate::VERSION.into(),
            wall_time_s: 0.0,
            time_s: 0.0,
            end_time_s: req.case.end_time(),
            steps: 0,
            step_cuts: 0,
            line_search_retries: 0,
            migrated_particles: 0,
            repartitions: 0,
            load_imbalance_max: 1.0,
            collectives: Default::default(),
            snes_iterations: 0,
            ksp_iterations: 0,
            matrix_structure_reuses: 0,
            field_residuals: Vec::new(),
            dofs: 0,
            grid_dofs: 0,
            particles: 0,
            ranks: req.coll.size(),
            solver: String::new(),
            petsc_options: assembly::petsc_options().unwrap_or_default(),
            timings: Timings::default(),
            peak_memory_mib: None,
            peak_memory_total_mib: None,
            checkerboard_index_max: None,
            pressure_oscillation_index_max: None,
            pore_pressure_range: None,
            energy_balance_error: None,
            warnings: Vec::new(),
            equilibrium_error: None,
            stopped: None,
            verification: BTreeMap::new(),
            results: BTreeMap::new(),
            verification_passed: None,
            restarted_from: None,
        }
    }
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
) -> Result<(Vec<assembly::BlockCheck>, usize), RunError> {
    let stiffness = req.case.stabilisation.stiffness;
    if req.case.jacobian_stiffness() != crate::case::Stiffness::Particle {
        return Err(RunError::Input(format!(
            "key `stabilisation.stiffness`: test-jacobian checks the exact tangent, and `{}` replaces its material \
             block by [001]'s approximate stiffness (Newton then converges linearly, by design); check the case \
             with `--set stabilisation.stiffness=particle`",
            stiffness.name()
        )));
    }
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
) -> Result<(Vec<assembly::BlockCheck>, usize), RunError> {
    let mut summary = Summary::new(req);
    let mut out = RunOutput::silent();
    let mut sim = Simulation::<D, M, N>::set_up(req, &mut out, &mut summary)?;
    let stage = &req.case.stages[0];
    let active = sim.model.active(stage);
    sim.begin_stage(stage)?;
    for _ in 0..steps {
        sim.newton_solve(&active, stage.dt())?.map_err(RunError::Failed)?;
        sim.update_particles(&active, stage.dt())?.map_err(RunError::Failed)?;
        sim.t += stage.dt();
    }
    let names = sim.body_names.clone();
    sim.system
        .prepare_step(&sim.model, &active, sim.t + stage.dt(), stage.dt(), req.coll, &names)
        .map_err(RunError::Failed)?;
    let blocks = sim.system.jacobian_check(&sim.model, 0.7, flip).map_err(|e| RunError::Failed(e.to_string()))?;
    Ok((blocks, sim.model.particles.eps_pd.iter().filter(|&&e| e > 0.0).count()))
}

impl<'a, const D: usize, const M: usize, const N: usize> Simulation<'a, D, M, N> {
    fn set_up(
        req: &RunRequest<'a>,
        out: &'a mut RunOutput,
        summary: &'a mut Summary,
    ) -> Result<Simulation<'a, D, M, N>, RunError> {
        let t0 = Instant::now();
        let case = req.case;
        let coll = req.coll;
        let input = |e: String| RunError::Input(e);
        let first = req.restart.as_ref().map_or(0, |(_, cp)| cp.stage as usize).min(case.stages.len() - 1);
        let layout = StageAnalysis::of(case, &case.stages[first]).layout.in_dim(D);
        let system =
            GridSystem::<D, M, N>::new(coll, &crate::model::grid_of(case), layout, None, case.jacobian_stiffness())
                .map_err(|e| input(e.to_string()))?;
        let setup_stage = system.phase(Phase::Setup).map_err(|e| input(e.to_string()))?;
        let model = Model::<D>::of_case(case, |c| system.owns_cell_in(c));
        let n_boundaries = model.boundaries.len();
        let check = verification::for_case_in(case, &model, coll).map_err(|e| input(format!("verification: {e}")))?;
        let probes = find_probes(case, &model, coll).map_err(input)?;
        summary.particles = coll.sum(&[model.particles.len() as f64]).map_err(input)?[0] as usize;
        summary.grid_dofs = system.total_dofs();
        let mut columns: Vec<String> =
            ["time", "step", "dt", "newton_iterations", "linear_iterations"].map(String::from).to_vec();
        for p in &probes {
            columns.extend(probe_fields(model.two_phase, D).iter().map(|f| format!("{}.{f}", p.name)));
        }
        let dynamic = case.stages.iter().any(|s| s.analysis == crate::case::AnalysisType::Dynamic);
        let monitor = Monitor::new(model.two_phase, dynamic);
        columns.extend(monitor.columns());
        columns.push("load_imbalance".into());
        columns.push("equilibrium_error".into());
        const AXES: [&str; 3] = ["x", "y", "z"];
        for b in &model.boundaries {
            columns.extend(AXES[..D].iter().map(|a| format!("{}.reaction_{a}", b.name)));
        }
        for b in model.boundaries.iter().filter(|b| b.motion.is_some()) {
            columns.extend(AXES[..D].iter().map(|a| format!("{}.displacement_{a}", b.name)));
        }
        if let Some(c) = &check {
            columns.extend(c.columns());
        }
        out.start_history(&columns).map_err(input)?;
        if case.output.fields_every > 0 {
            out.start_fields(crate::fields::grid_geometry(&model), coll.communicator()).map_err(input)?;
        }
        drop(setup_stage);
        summary.timings.setup_s = t0.elapsed().as_secs_f64();
        let mut sim = Simulation {
            case,
            model,
            system,
            check,
            probes,
            out,
            coll,
            display: Progress::new(!req.quiet && coll.rank() == 0, coll.rank() == 0, case.end_time()),
            t: 0.0,
            step: 0,
            summary,
            options_checked: false,
            boundary_grip: Vec::new(),
            summary_written: Instant::now(),
            last_newton: (0, 0),
            last_field_residuals: Default::default(),
            history: (columns, Vec::new()),
            resume: None,
            fields_step: None,
            checkpoint_every: req.checkpoint_every,
            interrupt: req.interrupt.clone(),
            body_names: case.bodies.iter().map(|b| b.name.clone()).collect(),
            equilibrium: (0.0, vec![[0.0; D]; n_boundaries]),
            monitor,
            balance: (req.balance_threshold, None),
        };
        let warnings = crate::diagnostics::physics::warnings(case, &sim.model);
        sim.warn(warnings);
        if let Some((label, cp)) = &req.restart {
            sim.restore(label, cp)?;
        } else {
            sim.set_load_increments(LoadsAt::Start)?;
        }
        sim.record_step(0.0)?;
        sim.write_fields()?;
        Ok(sim)
    }

    /// The stage loop: every stage in turn, until the check asks to stop.
    fn run_stages(&mut self, stages: &[Stage]) -> Result<(), RunError> {
        // A restarted run continues in the stage of its checkpoint.
        let first = self.resume.map_or(0, |r| r.0);
        for stage in &stages[first..] {
            self.run_stage(stage)?;
            if let Some(why) = self.check.as_ref().and_then(|c| c.stop()) {
                self.progress(&format!("stopped at t = {:.6e} s: {why}", self.t));
                self.summary.stopped = Some(why);
                break;
            }
        }
        Ok(())
    }

    /// The time-step loop of one stage.
    fn run_stage(&mut self, stage: &Stage) -> Result<(), RunError> {
        let active = self.model.active(stage);
        let analysis = self.begin_stage(stage)?;
        let mut control = StepControl::new(stage, self.stage_end(stage), analysis.dt_limit);
        let stage_index = self.case.stages.iter().position(|s| std::ptr::eq(s, stage)).unwrap_or(0);
        if let Some((_, dt, successes)) = self.resume.take() {
            control.dt = dt;
            control.successes = successes;
        }
        self.progress(&format!(
            "stage `{}` ({}): t = {:.6e} → {:.6e} s, Δt = {:.3e} s",
            stage.name,
            analysis.describe(),
            self.t,
            control.t_end,
            control.dt
        ));
        while !control.finished(self.t) {
            let events = self.check.as_ref().map(|c| c.event_times()).unwrap_or_default();
            let dt = control.next(self.t, &events);
            let outcome = self.newton_solve(&active, dt)?;
            let admitted = match outcome {
                Ok(()) => {
                    let nodes_checked = self.check.as_ref().is_some_and(|c| c.needs_nodes());
                    let diagnostics = self.case.output.fields_every > 0 || nodes_checked;
                    let forces =
                        self.system.step_forces(&self.model, self.coll, diagnostics).map_err(RunError::Failed)?;
                    if let (Some(c), true) = (self.check.as_mut(), nodes_checked) {
                        let block = self.system.owned_node_block();
                        c.observe_nodes(&block, &self.model, self.coll).map_err(RunError::Failed)?;
                    }
                    if let Some(c) = self.check.as_mut() {
                        c.observe_reactions(&forces.reactions);
                    }
                    let before = forces.at_start.then(|| self.stress_integral(&forces));
                    let updated = self.update_particles(&active, dt)?;
                    if updated.is_ok() {
                        self.record_equilibrium(&forces, before)?;
                        self.record_field_residuals(&forces.field_scales);
                    }
                    updated
                }
                Err(why) => Err(why),
            };
            match admitted {
                Ok(()) => {
                    self.system.accept_increment(dt).map_err(|e| RunError::Failed(e.to_string()))?;
                    self.migrate_particles()?;
                    self.balance_load()?;
                    self.t = control.advance(self.t, dt);
                    self.set_load_increments(LoadsAt::Accepted)?;
                    control.accepted(self.last_newton.0);
                    self.step += 1;
                    self.summary.steps = self.step;
                    self.summary.time_s = self.t;
                    if self.step.is_multiple_of(self.case.output.history_every) || control.finished(self.t) {
                        self.record_step(dt)?;
                    } else {
                        self.observe_only(dt)?;
                    }
                    self.display.step(&stage.name, self.step, self.t, self.last_newton.0);
                    let every = self.case.output.fields_every;
                    let stopping = self.check.as_ref().is_some_and(|c| c.stop().is_some());
                    if every > 0 && (self.step.is_multiple_of(every) || control.finished(self.t) || stopping) {
                        self.write_fields()?;
                    }
                    if self.checkpoint_every > 0 && self.step.is_multiple_of(self.checkpoint_every) {
                        self.write_checkpoint(stage_index, &control)?;
                    }
                    self.stop_if_interrupted(stage_index, &control)?;
                    if stopping {
                        if !control.finished(self.t) && !self.step.is_multiple_of(self.case.output.history_every) {
                            self.record_step(dt)?;
                        }
                        return Ok(());
                    }
                }
                Err(why) => {
                    self.summary.step_cuts += 1;
                    if control.rejected(dt).is_err() {
                        return Err(RunError::Failed(format!(
                            "stage `{}`: the step from t = {:.6e} s did not converge after {} cuts of Δt (last Δt = {:.3e} s): {why}",
                            stage.name, self.t, stage.max_step_cuts, dt
                        )));
                    }
                    self.progress(&format!("  step from t = {:.6e} s cut to Δt = {:.3e} s: {why}", self.t, control.dt));
                }
            }
        }
        Ok(())
    }

    /// Sets the stage's analysis type up: its time treatment and its materials' strengths on the
    /// model and, when its unknowns per node differ from the last stage's, a new grid system
    /// (DMDA, matrix, SNES) for them.
    fn begin_stage(&mut self, stage: &Stage) -> Result<StageAnalysis, RunError> {
        let analysis = StageAnalysis::of(self.case, stage);
        self.model.integration = analysis.integration;
        self.model.take_stage_materials(self.case, stage);
        self.system.forget_increment();
        let layout = analysis.layout.in_dim(D);
        if self.system.layout() != layout {
            let grid = crate::model::grid_of(self.case);
            let reused = self.system.reused_patterns;
            let owners = self.system.owners().clone();
            self.system = GridSystem::new(self.coll, &grid, layout, Some(&owners), self.case.jacobian_stiffness())
                .map_err(|e| RunError::Failed(e.to_string()))?;
            self.system.reused_patterns = reused;
            self.summary.grid_dofs = self.system.total_dofs();
        }
        Ok(analysis)
    }

    /// One Newton solve of the step t → t + dt. `Ok(Err(reason))` means it did not converge.
    fn newton_solve(&mut self, active: &crate::model::Active, dt: f64) -> Result<Result<(), String>, RunError> {
        let t0 = Instant::now();
        {
            let _stage = self.system.phase(Phase::StepSetup).map_err(|e| RunError::Failed(e.to_string()))?;
            self.system
                .prepare_step(&self.model, active, self.t + dt, dt, self.coll, &self.body_names)
                .map_err(RunError::Failed)?;
        }
        self.summary.timings.step_setup_s += t0.elapsed().as_secs_f64();
        self.summary.dofs = self.system.free_dofs();
        self.summary.matrix_structure_reuses = self.system.reused_patterns;
        let solve = self
            .system
            .solve(&self.model)
            .map_err(|e| RunError::Failed(format!("Newton solve at t = {:.6e} s: {e}", self.t)))?;
        self.summary.timings.assembly_s += solve.assembly_seconds;
        self.summary.timings.linear_solve_s += solve.solve_seconds - solve.assembly_seconds;
        let (count, seconds) = assembly::timed_matvecs(&self.system);
        if count > 0 {
            self.summary.timings.tangent_matvec_s = Some(seconds / count as f64);
        }
        self.summary.snes_iterations += solve.newton_iterations;
        self.summary.ksp_iterations += solve.linear_iterations;
        self.last_newton = (solve.newton_iterations, solve.linear_iterations);
        self.check_boundary_grip();
        if !self.options_checked && solve.solver_used {
            self.options_checked = true;
            self.summary.solver = assembly::describe_solver(&mut self.system).unwrap_or_default();
            let iterative = assembly::is_iterative(&mut self.system).map_err(|e| RunError::Failed(e.to_string()))?;
            if iterative && self.system.layout().p.is_some() && self.model.pressure_projection.is_none() {
                self.warn(vec![Warning {
                    kind: "iterative_unstabilised".into(),
                    message: format!(
                        "the Krylov solver ({}) runs an equal-order two-phase case without pressure projection: its \
                         checkerboard pressure modes are nearly singular for the pressure block's preconditioner, whose \
                         iterations may then grow with the grid (docs/solvers.md, \"Which strategy for which case\"); \
                         set stabilisation.pressure_projection = 1.0 or use a direct strategy",
                        self.summary.solver
                    ),
                    time_s: None,
                    value: None,
                    threshold: None,
                }]);
            }
            let unused = assembly::unused_petsc_options().map_err(|e| RunError::Failed(e.to_string()))?;
            if !unused.is_empty() {
                return Err(RunError::Input(format!(
                    "PETSc option(s) not used by any solver object: {} (misspelt, or not applicable to this solver)",
                    unused.join(", ")
                )));
            }
        }
        self.summary.line_search_retries += usize::from(solve.line_search_retry);
        if solve.converged && solve.line_search_retry {
            self.progress(&format!(
                "  step from t = {:.6e} s: full Newton steps failed, solved with a line search ({})",
                self.t,
                assembly::LINE_SEARCH_RETRY
            ));
        }
        if solve.converged {
            self.last_field_residuals = (solve.field_residuals, solve.field_scales, solve.linear_field_residuals);
            Ok(Ok(()))
        } else {
            let mut why = match solve.domain_error {
                Some(d) => format!("{} ({d})", solve.reason),
                None => solve.reason,
            };
            // Name the first material point whose residual was not finite during the solve (the
            // lowest rank's, agreed by all ranks), so that a NaN or Inf says where it appeared.
            if let Err(where_) = self.coll.agree(solve.nonfinite.map_or(Ok(()), Err)) {
                why = format!("{why}; {where_}");
            }
            Ok(Err(why))
        }
    }

    /// Folds the field residuals of the step just accepted into the summary's maxima (by field
    /// name: a stage may change the system). A field's final Newton residual is measured against
    /// the larger of its equation magnitudes at the step's start and at its converged state.
    fn record_field_residuals(&mut self, end_scales: &[f64]) {
        let (norms, start_scales, linear) = std::mem::take(&mut self.last_field_residuals);
        for (i, (name, _)) in self.system.layout().fields().iter().enumerate() {
            let all = &mut self.summary.field_residuals;
            let r = match all.iter().position(|r| r.field == *name) {
                Some(k) => &mut all[k],
                None => {
                    all.push(FieldResidual { field: name.to_string(), newton_final_max: 0.0, linear_max: None });
                    all.last_mut().expect("just pushed")
                }
            };
            let scale = start_scales.get(i).copied().unwrap_or(0.0).max(end_scales.get(i).copied().unwrap_or(0.0));
            if let Some(&n) = norms.get(i) {
                if scale > 0.0 {
                    r.newton_final_max = r.newton_final_max.max(n / scale);
                }
            }
            if let Some(&l) = linear.get(i) {
                r.linear_max = Some(r.linear_max.unwrap_or(0.0).max(l));
            }
        }
    }

    /// The particle update of a converged step; `Ok(Err(..))` if a particle would become
    /// inadmissible (the step is then cut), in which case no particle is changed.
    fn update_particles(&mut self, active: &crate::model::Active, dt: f64) -> Result<Result<(), String>, RunError> {
        let t0 = Instant::now();
        let _stage = self.system.phase(Phase::ParticleUpdate).map_err(|e| RunError::Failed(e.to_string()))?;
        let n = self.model.particles.len();
        let results: Vec<StepResult<D>> = (0..n).map(|k| self.system.step_result(&self.model, k)).collect();
        let bad = results.iter().enumerate().find_map(|(k, r)| self.model.check_step(k, r).err());
        if self.coll.any(bad.is_some()).map_err(RunError::Failed)? {
            return Ok(Err(bad
                .map(|e| e.0)
                .unwrap_or_else(|| "a material point on another rank became inadmissible".into())));
        }
        // The projected or recovered pore pressures.
        let recovered = match (self.model.pressure_update, self.system.layout().p.is_some()) {
            (crate::case::PressureUpdate::ProjectedTotal, true) => Some(
                self.system.projected_pressure_increments(&self.model).map_err(|e| RunError::Failed(e.to_string()))?,
            ),
            (_, true) if self.model.two_phase && self.model.patch_recovery => {
                Some(self.system.recovered_pressure_increments(&self.model))
            }
            _ => None,
        };
        // The energy terms of a dynamic step need the particles' state at t_n.
        let dynamic = matches!(self.model.integration, Integration::Dynamic { .. });
        let before: Vec<_> = if dynamic {
            let body_acc = self.model.body_accelerations(active, self.t + dt);
            let ps = &self.model.particles;
            (0..n).map(|k| (self.model.particle_input(k, &body_acc), ps.vel[k], ps.vel_w[k])).collect()
        } else {
            Vec::new()
        };
        let mut terms = [0.0; 5];
        for (k, r) in results.iter().enumerate() {
            let dp = recovered.as_ref().map_or(r.interp.dp, |v| v[k]);
            self.model.update_particle(k, r, dp, dt).map_err(|e| RunError::Failed(e.0))?;
            if let Some((input, v, vw)) = before.get(k) {
                let ps = &self.model.particles;
                let e = energy::particle_step(input, r, dp, ps.volume[k]);
                let k_old = energy::kinetic(input.mass, input.water_mass, *v, *vw);
                let k_new = energy::kinetic(ps.mass[k], self.model.water_mass(k), ps.vel[k], ps.vel_w[k]);
                let d = if input.water_mass > 0.0 { energy::darcy(input.drag, dt, r) } else { 0.0 };
                terms[0] += e.body;
                terms[1] += e.internal;
                terms[2] += k_new - k_old;
                terms[3] += d;
                terms[4] += k_new;
            }
        }
        if dynamic {
            self.monitor.ledger.add_particles(terms[0], terms[1], terms[2], terms[3], terms[4]);
        }
        self.summary.timings.particle_update_s += t0.elapsed().as_secs_f64();
        Ok(Ok(()))
    }

    /// Moves the material points whose centre left this rank's cells to their new owner
    /// ([`crate::distribution::migrate`]); counted in summary.json.
    fn migrate_particles(&mut self) -> Result<(), RunError> {
        if self.coll.size() == 1 {
            return Ok(());
        }
        let t0 = Instant::now();
        let sent = crate::distribution::migrate(&mut self.model, self.case, self.system.owners(), self.coll);
        self.summary.migrated_particles += self.coll.sum_count(sent as u64) as usize;
        self.summary.timings.particle_update_s += t0.elapsed().as_secs_f64();
        Ok(())
    }

    /// The busiest rank's material points over the mean (1 on one rank); collective.
    fn load_imbalance(&self) -> Result<f64, RunError> {
        if self.coll.size() == 1 {
            return Ok(1.0);
        }
        let counts = self.coll.gather(&[self.model.particles.len() as f64]).map_err(RunError::Failed)?;
        Ok(crate::distribution::imbalance(&counts))
    }

    /// Repartitions the grid over the ranks when the load imbalance passes the threshold and a
    /// better distribution exists ([`crate::distribution::balanced`]): a new grid system on the new
    /// distribution, and the points moved to their new owners. Counted in summary.json.
    fn balance_load(&mut self) -> Result<(), RunError> {
        let (threshold, last) = self.balance;
        if self.coll.size() == 1 || !threshold.is_finite() {
            return Ok(());
        }
        let now = self.load_imbalance()?;
        if now <= threshold || last.is_some_and(|l| now < l * crate::distribution::BALANCE_GAIN) {
            return Ok(());
        }
        let t0 = Instant::now();
        let grid = &self.model.grid;
        let mut hist = vec![0.0; grid.cells.iter().product()];
        for x in &self.model.particles.x {
            // The cell that decides the point's owner (`Owners::rank_of`), x fastest.
            hist[grid.cell_number(grid.nearest(*x))] += 1.0;
        }
        let hist = self.coll.sum(&hist).map_err(RunError::Failed)?;
        let proposal = crate::distribution::balanced(&hist, grid.cells, self.coll.size(), assembly::STENCIL_WIDTH);
        let Some((owners, predicted)) = proposal.filter(|(_, p)| *p * crate::distribution::BALANCE_GAIN <= now) else {
            self.balance.1 = Some(now);
            return Ok(());
        };
        let owners = &owners;
        let reused = self.system.reused_patterns;
        let layout = self.system.layout();
        // The last step's nodal values, for the field output of this step on the new distribution.
        let carried = self.system.global_node_values(self.coll).map_err(RunError::Failed)?;
        self.system =
            GridSystem::new(self.coll, &self.model.grid, layout, Some(owners), self.case.jacobian_stiffness())
                .map_err(|e| RunError::Failed(e.to_string()))?;
        self.system.reused_patterns = reused;
        self.system.carry_node_values(carried);
        self.summary.timings.particle_update_s += t0.elapsed().as_secs_f64();
        self.migrate_particles()?;
        self.summary.repartitions += 1;
        self.balance.1 = Some(predicted);
        self.progress(&format!(
            "  t = {:.6e} s: load imbalance {now:.2} > {threshold}: grid repartitioned, imbalance now {predicted:.2}",
            self.t
        ));
        Ok(())
    }

    /// This rank's share of ∫σ dV (total stress, current configuration; in axial symmetry with
    /// the hoop stress's share about `forces.origin`), the left side of the equilibrium identity,
    /// row by row (D × D entries).
    fn stress_integral(&self, forces: &StepForces<D>) -> Vec<f64> {
        let ps = &self.model.particles;
        let axisymmetric = self.model.geometry.axisymmetric();
        let mut local = vec![0.0; D * D];
        for k in 0..ps.len() {
            let s = ps.stress[k];
            let p = if self.model.two_phase { ps.p[k] } else { 0.0 };
            let v = ps.volume[k];
            // The stress tensor [xx, xy, xz; yx, yy, yz; zx, zy, zz] from [xx, yy, xy, zz, yz, zx].
            let t = [[s[0] - p, s[2], s[5]], [s[2], s[1] - p, s[4]], [s[5], s[4], s[3] - p]];
            for a in 0..D {
                for b in 0..D {
                    local[a * D + b] += t[a][b] * v;
                }
            }
            if axisymmetric {
                local[0] += (s[3] - p) * v;
                local[2] += (ps.x[k][1] - forces.origin[1]) * (s[3] - p) * v / ps.x[k][0];
            }
        }
        local
    }

    /// The equilibrium identity of the converged step ([`StepForces`]): the volume integral of the
    /// total Cauchy stress over the updated material points, ∫σ dV = Σ_p (σ' − p m) V_p, against the
    /// first moment of the external forces, the reactions and the inertia forces about the same
    /// point, Σ_i x_i ⊗ (F_ext + R − F_inertia)_i on the nodes at t_{n+1}. The relative error (in the
    /// Frobenius norm, against the largest of the moments) is kept for the history row and its
    /// worst for summary.json, with the boundaries' reactions. In axial symmetry the moments are
    /// taken about the axis (r = 0) and the hoop stress takes part: Σ r_i f_r,i = ∫(σ_rr + σ_θθ) dV
    /// and Σ (y_i − y_o) f_r,i = ∫(σ_ry + (y − y_o) σ_θθ / r) dV (virtual displacements r e_r and
    /// (y − y_o) e_r), exact for the planar weights without B̄ and up to the discretisation of
    /// the hoop operator otherwise. An explicit step's forces are those of its start
    /// (`StepForces::at_start`): `before` is then ∫σ dV of the points before their update, and the
    /// identity holds at t_n on x_n with the lumped inertia of the nodal update.
    fn record_equilibrium(&mut self, forces: &StepForces<D>, before: Option<Vec<f64>>) -> Result<(), RunError> {
        let lhs = match before {
            Some(l) => l,
            None => self.stress_integral(forces),
        };
        let lhs = self.coll.sum(&lhs).map_err(RunError::Failed)?;
        if matches!(self.model.integration, Integration::Dynamic { .. }) {
            self.monitor.ledger.external += forces.work;
        }
        let m = &forces.moment;
        let diff: Vec<f64> = (0..D * D).map(|e| lhs[e] - m[e / D][e % D]).collect();
        let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
        let scale = norm(&lhs).max(forces.scale);
        let error = if scale > 0.0 { norm(&diff) / scale } else { 0.0 };
        self.equilibrium = (error, forces.reactions.clone());
        let worst =
            self.summary.equilibrium_error.map_or(error, |w: f64| if error.is_nan() { error } else { w.max(error) });
        self.summary.equilibrium_error = Some(worst);
        Ok(())
    }

    /// Probes, check and one row of history.csv.
    fn record_step(&mut self, dt: f64) -> Result<(), RunError> {
        let t0 = Instant::now();
        let _stage = self.system.phase(Phase::Output).map_err(|e| RunError::Failed(e.to_string()))?;
        let mut row = vec![self.t, self.step as f64, dt, self.last_newton.0 as f64, self.last_newton.1 as f64];
        row.extend(update_probes(&self.model, &mut self.probes, self.coll).map_err(RunError::Failed)?);
        let (values, warnings) =
            self.monitor.row(&self.model, self.system.owners(), self.coll, self.t).map_err(RunError::Failed)?;
        row.extend(values);
        let imbalance = self.load_imbalance()?;
        self.summary.load_imbalance_max = self.summary.load_imbalance_max.max(imbalance);
        row.push(imbalance);
        self.worst_to_summary();
        self.warn(warnings);
        row.push(self.equilibrium.0);
        for r in &self.equilibrium.1 {
            row.extend(r);
        }
        for m in self.model.boundaries.iter().filter_map(|b| b.motion.as_ref()) {
            row.extend(m.displacement_at(self.t));
        }
        if let Some(c) = self.check.as_mut() {
            row.extend(c.observe(self.t, dt, &self.model, self.coll).map_err(RunError::Failed)?);
        }
        self.out.history_row(&row).map_err(RunError::Failed)?;
        if self.out.is_writer() {
            self.history.1.push(row);
        }
        self.summary.timings.output_s += t0.elapsed().as_secs_f64();
        Ok(())
    }

    /// The check's observation on steps without a history row.
    fn observe_only(&mut self, dt: f64) -> Result<(), RunError> {
        update_probes(&self.model, &mut self.probes, self.coll).map_err(RunError::Failed)?;
        if let Some(c) = self.check.as_mut() {
            c.observe(self.t, dt, &self.model, self.coll).map_err(RunError::Failed)?;
        }
        Ok(())
    }

    /// Results of the probes, metrics, results and tables of the check, and the figures.
    fn finish(mut self) -> Result<(), RunError> {
        let t0 = Instant::now();
        if self.summary.solver.is_empty() && !self.options_checked {
            self.summary.solver = "none (explicit steps only)".into();
        }
        let warnings = self.monitor.finish(self.t);
        self.warn(warnings);
        let _stage = self.system.phase(Phase::Output).map_err(|e| RunError::Failed(e.to_string()))?;
        for pr in &self.probes {
            if pr.last.len() >= 2 * D {
                // |u| from the displacement's D components (after the position's D).
                let u = pr.last[D..2 * D].iter().fold(0.0f64, |m, c| m.hypot(*c));
                self.summary.results.insert(format!("{}.displacement", pr.name), u);
            }
            if self.model.two_phase {
                self.summary.results.insert(format!("{}.excess_p_peak", pr.name), pr.excess_extreme);
                if let Some(&e) = pr.last.last() {
                    self.summary.results.insert(format!("{}.excess_p_final", pr.name), e);
                }
            }
        }
        if let Some(c) = self.check.as_mut() {
            // The results after `finish` (which may complete them), also when it fails.
            let finished = c.finish(&self.model, self.coll);
            self.summary.results.extend(c.results());
            let (metrics, tables) = finished.map_err(RunError::Failed)?;
            self.summary.verification_passed = Some(metrics.iter().all(|m| m.1.pass));
            for t in &tables {
                self.out.write_table(&t.name, &t.header, &t.rows).map_err(RunError::Failed)?;
            }
            self.summary.verification = metrics.into_iter().collect();
        }
        if self.out.is_writer() {
            let mut figures = self.check.as_ref().map(|c| c.figures()).unwrap_or_default();
            figures.extend(crate::plot::probe_histories(&self.history.0, &self.history.1, PROBE_FIGURES));
            if let Err(e) = self.out.write_figures(&figures) {
                eprintln!("warning: the plots were not drawn: {e}");
            }
        }
        self.summary.timings.output_s += t0.elapsed().as_secs_f64();
        Ok(())
    }

    fn stage_end(&self, stage: &Stage) -> f64 {
        let mut end = 0.0;
        for s in &self.case.stages {
            end += s.duration;
            if std::ptr::eq(s, stage) {
                break;
            }
        }
        end
    }

    /// Warns (once per boundary) when the material has moved away from the grid nodes that carry a
    /// boundary's prescribed motion: their mean filled fraction at the step's start has fallen
    /// below half of what it was when the boundary was first seen. A boundary on grid nodes stays
    /// where the grid is; past that point its motion reaches only the points at the edge of the
    /// nodes' support (a footing pushed into the ground by more than about half a cell loses its
    /// grip on the soil beneath it, and the load it carries is no longer the footing's).
    fn check_boundary_grip(&mut self) {
        let fill = self.system.boundary_fill().to_vec();
        self.boundary_grip.resize(fill.len(), (None, false));
        let mut warnings = Vec::new();
        for (b, f) in fill.iter().enumerate() {
            let Some(f) = *f else { continue };
            let (first, warned) = &mut self.boundary_grip[b];
            let start = *first.get_or_insert(f);
            if !*warned && start > 0.0 && f < GRIP_FRACTION * start {
                *warned = true;
                warnings.push(Warning {
                    kind: "boundary_detached".into(),
                    message: format!(
                        "boundary `{}` prescribes a motion on grid nodes that the material has moved away from: their \
                         mean filled fraction is {f:.3}, {:.0} % of the {start:.3} it was at first; the motion now \
                         reaches the material only through the points at the edge of the nodes' support, and the \
                         reactions past this time are not those of the boundary the case means (move it by less than \
                         half a cell, or model the pushing body with material points)",
                        self.model.boundaries[b].name,
                        100.0 * f / start
                    ),
                    time_s: Some(self.t),
                    value: Some(f / start),
                    threshold: Some(GRIP_FRACTION),
                });
            }
        }
        self.warn(warnings);
    }

    fn progress(&self, msg: &str) {
        self.display.message(msg);
    }

    /// Gives warnings: in the terminal (rank 0, also with `--quiet`) and in summary.json.
    fn warn(&mut self, warnings: Vec<Warning>) {
        for w in warnings {
            let at = w.time_s.map(|t| format!(" (t = {t:.6e} s)")).unwrap_or_default();
            self.display.warning(&format!("warning [{}]{at}: {}", w.kind, w.message));
            self.summary.warnings.push(w);
        }
    }

    /// The diagnostics' worst values into the summary.
    fn worst_to_summary(&mut self) {
        let w = self.monitor.worst;
        let some = |v: f64| (!v.is_nan()).then_some(v);
        self.summary.checkerboard_index_max = some(w.checkerboard);
        self.summary.pressure_oscillation_index_max = some(w.oscillation);
        self.summary.pore_pressure_range = (!w.p_range[0].is_nan()).then_some(w.p_range);
        self.summary.energy_balance_error = some(w.energy);
    }

    /// One output time of `fields.h5`/`fields.xdmf` (once per step at most).
    fn write_fields(&mut self) -> Result<(), RunError> {
        if self.case.output.fields_every == 0 || self.fields_step == Some(self.step) {
            return Ok(());
        }
        let t0 = Instant::now();
        let nodes = self.system.owned_node_block();
        let frame = crate::fields::frame(&self.model, &nodes, self.coll, self.t);
        self.out.write_fields(&frame).map_err(RunError::Failed)?;
        self.fields_step = Some(self.step);
        self.summary.timings.output_s += t0.elapsed().as_secs_f64();
        Ok(())
    }

    /// Writes `checkpoint.h5` after an accepted step in stage `stage_index`.
    /// After a complete step: if any rank was sent SIGINT or SIGTERM (agreed across ranks), write
    /// the step's history row and fields and a checkpoint to restart from, and stop. Otherwise
    /// keep the running summary's counts up to date (rank 0 rewrites summary.json atomically
    /// at a history row, at most every [`SUMMARY_INTERVAL`]: an explicit stage takes tens of
    /// thousands of steps, and each rewrite is synchronised to disk).
    fn stop_if_interrupted(&mut self, stage_index: usize, control: &StepControl) -> Result<(), RunError> {
        let local = self.interrupt.as_ref().is_some_and(|f| f.load(std::sync::atomic::Ordering::SeqCst));
        if !self.coll.any(local).map_err(RunError::Failed)? {
            if self.step.is_multiple_of(self.case.output.history_every)
                && self.summary_written.elapsed() >= SUMMARY_INTERVAL
            {
                self.out.write_summary(&*self.summary).map_err(RunError::Failed)?;
                self.summary_written = Instant::now();
            }
            return Ok(());
        }
        if !self.step.is_multiple_of(self.case.output.history_every) {
            self.record_step(control.dt)?;
        }
        self.write_fields()?;
        self.write_checkpoint(stage_index, control)?;
        Err(RunError::Interrupted(format!(
            "interrupted (SIGINT or SIGTERM) at t = {:.6e} s after {} complete steps; the fields of the last step and \
             checkpoint.h5 are written: continue with `porompm run ... --restart {}`",
            self.t,
            self.step,
            self.out.path_of("checkpoint.h5")
        )))
    }

    fn write_checkpoint(&mut self, stage_index: usize, control: &StepControl) -> Result<(), RunError> {
        let t0 = Instant::now();
        let local = state::records_of(&self.model.particles);
        let slab = self.coll.sorted_slab(&local, state::record_len(D));
        let check_state = match self.check.as_ref() {
            Some(c) => c.checkpoint_state(&self.model, self.coll).map_err(RunError::Failed)?,
            None => None,
        };
        let s = &self.summary;
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
            diagnostics: self.monitor.state(self.coll).map_err(RunError::Failed)?,
            probe_extremes: self.probes.iter().map(|p| p.excess_extreme).collect(),
            load_totals: self.model.loads.iter().map(|l| l.increments.as_ref().map_or(0.0, |s| s.total)).collect(),
            check_state,
            dim: D,
            particles: slab.values,
            first: slab.offset as u64,
            total: slab.total as u64,
        };
        self.out.write_checkpoint(&cp, self.coll.communicator()).map_err(RunError::Failed)?;
        self.summary.timings.output_s += t0.elapsed().as_secs_f64();
        Ok(())
    }

    /// Sets every load whose increments follow its loaded faces at the current time
    /// ([`crate::model::loads::LoadDef::set_increments`]), at the faces' mean centre over all ranks:
    /// at the run's start, after an accepted step, or from a checkpoint's `load_totals`.
    fn set_load_increments(&mut self, at: LoadsAt) -> Result<(), RunError> {
        // At the start a load that cannot be evaluated is the case's fault.
        let fail = |m: String| match at {
            LoadsAt::Start => RunError::Input(m),
            _ => RunError::Failed(m),
        };
        let model = &mut self.model;
        for li in 0..model.loads.len() {
            // Whether a load has increments is the case's: every rank takes the same branch.
            if model.loads[li].increments.is_none() {
                continue;
            }
            let local = model.loads[li].face_moments(&model.particles, &model.geometry);
            let m = self.coll.sum(&local).map_err(RunError::Failed)?;
            let load = &mut model.loads[li];
            if m[D] <= 0.0 {
                return Err(fail(format!(
                    "load `{}`: no loaded face is left to evaluate its increment_factor at",
                    load.name
                )));
            }
            let from = match at {
                LoadsAt::Start => IncrementsFrom::Start,
                LoadsAt::Accepted => IncrementsFrom::Accepted,
                LoadsAt::Restart(totals) => IncrementsFrom::Checkpoint(totals[li]),
            };
            load.set_increments(self.t, std::array::from_fn(|d| m[d] / m[D]), from).map_err(fail)?;
        }
        Ok(())
    }

    /// Continues from checkpoint `cp` (read from `label`): refuses one of another case, then takes
    /// its particles, time, counters, probe extremes, check state and step control.
    fn restore(&mut self, label: &str, cp: &Checkpoint) -> Result<(), RunError> {
        let refuse = |why: String| RunError::Input(format!("cannot restart from checkpoint {label}: {why}"));
        state::check_case(cp, self.case).map_err(refuse)?;
        // The checkpoint's records and the case's points as generated, each redistributed to the
        // same slabs of ids, must match; then every point goes to the rank owning its cell.
        if cp.total as usize != self.summary.particles {
            return Err(refuse(format!(
                "it holds {} material points but this case has {} (a different case or grid)",
                cp.total, self.summary.particles
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
        crate::distribution::migrate(&mut self.model, self.case, self.system.owners(), self.coll);
        self.model.resolve_targets(self.case);
        self.t = cp.time;
        self.set_load_increments(LoadsAt::Restart(&cp.load_totals))?;
        self.step = cp.step as usize;
        let s = &mut *self.summary;
        s.time_s = cp.time;
        s.steps = self.step;
        [s.step_cuts, s.snes_iterations, s.ksp_iterations, s.matrix_structure_reuses, s.line_search_retries] =
            cp.counters.map(|c| c as usize);
        self.monitor
            .restore_state(&cp.diagnostics, self.coll.rank() == 0)
            .map_err(|e| refuse(format!("diagnostics: {e}")))?;
        self.system.reused_patterns = s.matrix_structure_reuses;
        self.worst_to_summary();
        for (p, &e) in self.probes.iter_mut().zip(&cp.probe_extremes) {
            p.excess_extreme = e;
        }
        let mut note = None;
        if let Some(c) = self.check.as_mut() {
            match &cp.check_state {
                Some(st) => c.restore_state(st, &self.model).map_err(|e| refuse(format!("verification state: {e}")))?,
                None => {
                    note = Some(format!(
                    "the verification check keeps no checkpoint state: its metrics use the run from t = {:.6e} s only",
                    cp.time
                ))
                }
            }
        }
        if let Some(n) = &note {
            self.progress(&format!("restart: {n}"));
        }
        self.summary.restarted_from =
            Some(state::RestartInfo { checkpoint: label.to_string(), time_s: cp.time, step: self.step, note });
        self.resume = Some((cp.stage as usize, cp.dt, cp.successes as usize));
        self.progress(&format!("restarted from {label} at t = {:.6e} s, step {}", cp.time, cp.step));
        Ok(())
    }
}

/// Time-step control within a stage: the Δt of the next try, cuts after a failed try, regrowth
/// after successes, and landing exactly on event times (e.g. the times a verification needs) and
/// on the stage end.
/// Accepted steps after which a cut Δt grows back by one factor.
const GROW_AFTER: usize = 3;
/// Newton iterations up to which a step counts as easy: after [`GROW_AFTER`] accepted steps, the
/// last of them easy, Δt may grow beyond the stage's `dt` up to its `dt_max`.
const EASY_NEWTON: usize = 3;

/// The shortest wall time between two rewrites of the running summary.json.
const SUMMARY_INTERVAL: std::time::Duration = std::time::Duration::from_secs(1);

#[derive(Debug, Clone)]
struct StepControl {
    stage_dt: f64,
    /// The largest Δt after easy steps.
    dt_max: f64,
    dt: f64,
    cuts: usize,
    /// Accepted steps since Δt last changed.
    successes: usize,
    max_cuts: usize,
    factor: f64,
    t_end: f64,
}

impl StepControl {
    /// The control of `stage` up to `t_end`, its steps at most `limit` (an explicit stage's
    /// stable step) as well as its `dt`.
    fn new(stage: &Stage, t_end: f64, limit: Option<f64>) -> StepControl {
        let dt = limit.map_or(stage.dt(), |l| l.min(stage.dt()));
        StepControl {
            stage_dt: dt,
            dt_max: if limit.is_some() { dt } else { stage.dt_max.unwrap_or(dt) },
            dt,
            cuts: 0,
            successes: 0,
            max_cuts: stage.max_step_cuts,
            factor: stage.cut_factor,
            t_end,
        }
    }

    /// Round-off allowance on times.
    fn tiny(&self) -> f64 {
        1e-9 * self.stage_dt
    }

    /// Whether the stage is done at time `t`.
    fn finished(&self, t: f64) -> bool {
        t >= self.t_end - self.tiny()
    }

    /// Δt of the next try from `t`: the current Δt, shortened to land on the first event time
    /// inside the step and on the stage end.
    fn next(&self, t: f64, events: &[f64]) -> f64 {
        let mut next = t + self.dt;
        for &e in events {
            if e > t + self.tiny() && e < next {
                next = e;
            }
        }
        // Do not leave a sliver of less than a millionth of a step before the end.
        if next > self.t_end - 1e-6 * self.dt {
            next = self.t_end;
        }
        next - t
    }

    /// The time after an accepted step (exactly the stage end when it lands there).
    fn advance(&self, t: f64, dt: f64) -> f64 {
        if (self.t_end - (t + dt)).abs() <= self.tiny() {
            self.t_end
        } else {
            t + dt
        }
    }

    /// After an accepted step that took `newton` iterations: reset the cut count, and after
    /// [`GROW_AFTER`] accepted steps at the same Δt let it grow back towards the stage's (growing
    /// after every step would retry the Δt that just failed at once, which costs a full failed
    /// Newton solve each time in a plastic run), and beyond it up to `dt_max` when the last step
    /// was easy.
    fn accepted(&mut self, newton: usize) {
        self.cuts = 0;
        self.successes += 1;
        if self.successes >= GROW_AFTER {
            let cap = if newton <= EASY_NEWTON { self.dt_max } else { self.stage_dt };
            self.dt = self.dt.max((self.dt / self.factor).min(cap));
            self.successes = 0;
        }
    }

    /// After a failed try of length `dt_tried`: cut, or `Err` if the cuts are exhausted.
    fn rejected(&mut self, dt_tried: f64) -> Result<(), ()> {
        self.cuts += 1;
        if self.cuts > self.max_cuts {
            return Err(());
        }
        self.dt = dt_tried * self.factor;
        self.successes = 0;
        Ok(())
    }
}

/// The probe figures: (history.csv field, axis label, scale, file stem).
const PROBE_FIGURES: &[(&str, &str, f64, &str)] = &[
    ("p_excess", "excess pore pressure [kPa]", 1e-3, "excess_pore_pressure"),
    ("uy", "vertical displacement [mm]", 1e3, "vertical_displacement"),
    ("ux", "horizontal displacement [mm]", 1e3, "horizontal_displacement"),
];

/// The history columns of a probe in dimension `dim`: its position, displacement and velocity
/// (D components each), its stresses (the plane's xx, yy, xy; in three dimensions also zz, yz,
/// zx, in `Particles::stress` order), its plastic strain, and in two-phase runs its pore pressure
/// and excess pore pressure (last).
fn probe_fields(two_phase: bool, dim: usize) -> Vec<&'static str> {
    let mut fields = if dim == 3 {
        vec!["x", "y", "z", "ux", "uy", "uz", "vx", "vy", "vz", "sxx", "syy", "sxy", "szz", "syz", "szx", "eps_pd"]
    } else {
        vec!["x", "y", "ux", "uy", "vx", "vy", "sxx", "syy", "sxy", "eps_pd"]
    };
    if two_phase {
        fields.extend(["p", "p_excess"]);
    }
    fields
}

/// The probes of the case: each the point nearest its `point` at t = 0 (the lowest identifier
/// among equally near ones), in any dimension.
fn find_probes<const D: usize>(case: &Case, model: &Model<D>, coll: &Collective) -> Result<Vec<Probe>, String> {
    let ps = &model.particles;
    let mut out = Vec::new();
    for p in &case.probes {
        let local: Vec<f64> = (0..ps.len())
            .flat_map(|k| {
                let distance = (0..D).map(|d| (ps.x0[k][d] - p.point[d]).powi(2)).sum::<f64>().sqrt();
                [distance, ps.id[k] as f64]
            })
            .collect();
        let all = coll.gather(&local)?;
        let best = all
            .chunks(2)
            .min_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])))
            .ok_or(format!("probe `{}`: there are no material points", p.name))?;
        out.push(Probe { name: p.name.clone(), id: best[1] as u64, last: Vec::new(), excess_extreme: 0.0 });
    }
    Ok(out)
}

/// Updates every probe's values and extremes; returns the values of all probes in order.
fn update_probes<const D: usize>(
    model: &Model<D>,
    probes: &mut [Probe],
    coll: &Collective,
) -> Result<Vec<f64>, String> {
    let all = probe_values(model, probes, coll)?;
    let nf = probe_fields(model.two_phase, D).len();
    for (i, pr) in probes.iter_mut().enumerate() {
        pr.last = all[i * nf..(i + 1) * nf].to_vec();
        if model.two_phase {
            let e = pr.last[nf - 1];
            if e.abs() > pr.excess_extreme.abs() {
                pr.excess_extreme = e;
            }
        }
    }
    Ok(all)
}

fn probe_values<const D: usize>(model: &Model<D>, probes: &[Probe], coll: &Collective) -> Result<Vec<f64>, String> {
    let ps = &model.particles;
    let nf = probe_fields(model.two_phase, D).len();
    // The plane's xx, yy, xy; in three dimensions all six ([xx, yy, xy, zz, yz, zx]).
    let stresses = if D == 3 { 6 } else { 3 };
    let mut local = vec![0.0; probes.len() * nf];
    for (i, pr) in probes.iter().enumerate() {
        if let Some(k) = (0..ps.len()).find(|&k| ps.id[k] == pr.id) {
            let mut v = Vec::with_capacity(nf);
            v.extend(ps.x[k].iter().chain(&ps.disp[k]).chain(&ps.vel[k]).chain(&ps.stress[k][..stresses]));
            v.push(ps.eps_pd[k]);
            if model.two_phase {
                v.extend([ps.p[k], ps.p[k] - ps.p0[k]]);
            }
            local[i * nf..(i + 1) * nf].copy_from_slice(&v);
        }
    }
    coll.sum(&local)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stage(dt: f64, cuts: usize) -> Stage {
        Stage {
            name: "s".into(),
            duration: 1.0,
            dt: Some(dt),
            boundaries: None,
            loads: None,
            max_step_cuts: cuts,
            cut_factor: 0.5,
            time_integration: None,
            analysis: Default::default(),
            theta: None,
            drainage: None,
            dt_max: None,
            explicit: None,
            strength_reduction: None,
        }
    }

    #[test]
    fn an_explicit_stage_keeps_its_stable_step() {
        // The limit caps the stage's Δt, and easy steps do not grow past it.
        let mut st = stage(0.3, 2);
        st.dt_max = Some(1.0);
        let mut c = StepControl::new(&st, 10.0, Some(0.01));
        assert_eq!(c.next(0.0, &[]), 0.01);
        for _ in 0..20 {
            c.accepted(0);
        }
        assert_eq!(c.next(0.0, &[]), 0.01);
        // A stage Δt below the limit is kept.
        assert_eq!(StepControl::new(&stage(0.003, 2), 1.0, Some(0.01)).next(0.0, &[]), 0.003);
    }

    #[test]
    fn steps_land_on_events_and_on_the_stage_end() {
        let c = StepControl::new(&stage(0.3, 2), 1.0, None);
        assert_eq!(c.next(0.0, &[]), 0.3);
        assert!((c.next(0.0, &[0.1, 0.5]) - 0.1).abs() < 1e-15);
        // An event at the current time is not a target.
        assert!((c.next(0.1, &[0.1]) - 0.3).abs() < 1e-15);
        // The last step is shortened to end exactly at the stage end.
        assert!((c.next(0.9, &[]) - 0.1).abs() < 1e-15);
        assert_eq!(c.advance(0.9, 0.1), 1.0);
        assert!(c.finished(1.0 - 1e-12) && !c.finished(0.99));
    }

    #[test]
    fn failed_steps_are_cut_then_grow_back_and_the_cuts_are_limited() {
        let mut c = StepControl::new(&stage(0.2, 2), 1.0, None);
        assert!(c.rejected(0.2).is_ok());
        assert!((c.next(0.0, &[]) - 0.1).abs() < 1e-15);
        assert!(c.rejected(0.1).is_ok());
        assert!((c.next(0.0, &[]) - 0.05).abs() < 1e-15);
        // A third failure in a row exceeds max_step_cuts = 2.
        assert!(c.clone().rejected(0.05).is_err());
        // Success resets the count; every GROW_AFTER successes double Δt back, never above the
        // stage's.
        c.accepted(1);
        assert!((c.dt - 0.05).abs() < 1e-15 && c.cuts == 0);
        for _ in 1..GROW_AFTER {
            c.accepted(1);
        }
        assert!((c.dt - 0.1).abs() < 1e-15);
        for _ in 0..3 * GROW_AFTER {
            c.accepted(1);
        }
        assert_eq!(c.dt, 0.2);
    }

    #[test]
    fn easy_steps_grow_up_to_dt_max_and_hard_ones_do_not() {
        let mut st = stage(0.1, 2);
        st.dt_max = Some(0.4);
        let mut c = StepControl::new(&st, 10.0, None);
        for _ in 0..GROW_AFTER {
            c.accepted(EASY_NEWTON + 1);
        }
        assert_eq!(c.dt, 0.1, "a hard step does not grow beyond the stage's dt");
        for _ in 0..GROW_AFTER {
            c.accepted(EASY_NEWTON);
        }
        assert!((c.dt - 0.2).abs() < 1e-15);
        for _ in 0..4 * GROW_AFTER {
            c.accepted(1);
        }
        assert!((c.dt - 0.4).abs() < 1e-15, "capped at dt_max");
        // A hard step at a grown Δt keeps it (it converged); a failure cuts it.
        for _ in 0..GROW_AFTER {
            c.accepted(10);
        }
        assert!((c.dt - 0.4).abs() < 1e-15);
    }
}
