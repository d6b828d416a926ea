//! The global system ([`System`]): the grid's nodes on this rank ([`NodeSpace`]), PETSc's SNES
//! with its solution vector, matrix and preconditioner objects, and what a run carries from step to
//! step (the matrix's pattern, the last increment as the next step's predictor). A step is a value
//! ([`Step`]) that the system prepares and solves; the system keeps no step of its own.

use super::callbacks::{AssemblyTime, Callbacks, Workspace};
use super::dim::StepDim;
use super::lowered::PcMatrix;
use super::matrix::Matrix;
use super::pattern::Pattern;
use super::prepare::StepRequest;
use super::pressure::{self, L2Projection};
use super::space::{NodeBlock, NodeSpace};
use super::splits::{self, SchurNeeds, SchurTuning};
use super::step::{Solution, Step};
use super::{explicit, Error, FIELD_TEST_OPTION, FORCE_ATOL, LINE_SEARCH_RETRY, LINE_SEARCH_RETRY_OPTION};
use crate::case::{PressureUpdate, Stiffness};
use crate::distribution::Owners;
use crate::kernels;
use crate::layout::{Dim, Layout};
use crate::model::grid::Grid;
use crate::model::{Active, Model};
use crate::parallel::Collective;
use petsc::ksp::KspOps;
use petsc::mat::MatOps;
use petsc::snes::SolveOutcome;
use petsc::{LogStage, Mat, Snes, StageGuard, VecOps, Vector};
use std::sync::Arc;
use std::time::Instant;

/// The PETSc log stages of a run (shown by `-log_view`).
struct Stages {
    run_setup: LogStage,
    setup: LogStage,
    solve: LogStage,
    assembly: LogStage,
    update: LogStage,
    output: LogStage,
}

/// The phases of a step, for log stages.
#[derive(Debug, Clone, Copy)]
pub enum Phase {
    /// Setting up the run: material points, verification, probes, output.
    Setup,
    /// Mapping to the grid, constraints, loads.
    StepSetup,
    /// The Newton solve (assembly and linear solves).
    NewtonSolve,
    /// Particle update.
    ParticleUpdate,
    /// Writing results.
    Output,
}

/// Outcome of one nonlinear step solve.
#[derive(Debug, Clone)]
pub struct StepSolve {
    /// Whether SNES converged.
    pub converged: bool,
    /// PETSc's reason (`CONVERGED_FNORM_RELATIVE`, `DIVERGED_LINE_SEARCH`, ...).
    pub reason: String,
    /// Newton iterations.
    pub newton_iterations: usize,
    /// Krylov iterations.
    pub linear_iterations: usize,
    /// Residual norms, initial and after each iteration.
    pub residual_history: Vec<f64>,
    /// A domain error raised by the callbacks.
    pub domain_error: Option<String>,
    /// The first material point (on this rank) whose residual was not finite during the solve,
    /// with the quantity that was not.
    pub nonfinite: Option<String>,
    /// Wall time spent in the residual and Jacobian callbacks, and the Jacobians' share of it.
    pub assembly: AssemblyTime,
    /// Wall time of the whole SNES solve [s].
    pub solve_seconds: f64,
    /// The norm of the final Newton residual of each field (`Layout::fields`), in PETSc's scaling.
    pub field_residuals: Vec<f64>,
    /// The norm of each field's force magnitudes at the start of the step (Δd = 0), in PETSc's
    /// scaling (see [`super::points::Points::force_magnitudes`]).
    pub field_scales: Vec<f64>,
    /// The largest relative residual of each field over the step's linear solves (see
    /// `petsc::fields::relative_field_residuals`; empty when not measured).
    pub linear_field_residuals: Vec<f64>,
    /// Whether PETSc's solver ran (false for an explicit step).
    pub solver_used: bool,
    /// Whether full Newton steps failed and the step was solved again with a line search
    /// after they diverged ([`LINE_SEARCH_RETRY`]; `converged` is then the second solve's outcome).
    pub line_search_retry: bool,
    /// Why the direct solver was given more workspace and the step solved again, if it was.
    pub workspace_retry: Option<String>,
}

/// The global system on a grid of dimension D whose points have at most M stencil nodes of at
/// most N dofs each.
pub struct System<
    const D: usize = 2,
    const M: usize = { kernels::MAX_NODES },
    const N: usize = { crate::layout::MAX_DOF },
> {
    pub(super) space: NodeSpace<D>,
    x: Vector,
    x_local: Vector,
    f_local: Vector,
    snes: Snes,
    matrix: Option<Matrix<D>>,
    /// The matrix the preconditioner is built from ([`super::lowered::PC_MATRIX_OPTION`]) and,
    /// when it is not the Jacobian, that matrix.
    pc_matrix: PcMatrix,
    lowered: Option<Matrix<D>>,
    /// The rigid-body modes of the grid, attached to every Jacobian of a system whose unknowns are
    /// all displacements (see [`splits::displacement_near_null_space`]); empty otherwise.
    near_null: Vec<Vector>,
    /// porompm's Schur preconditioner, when the options ask for one (see [`splits`]).
    schur: Option<petsc::SchurUser>,
    /// Its tuning from the options (the u–p–U system's aggregates and fixed-stress share).
    schur_tuning: SchurTuning,
    /// The absolute residual tolerance given in the options (`-snes_atol`), a floor for the
    /// per-step one.
    user_atol: f64,
    /// Whether a step whose full Newton steps failed is solved once more with a line search
    /// ([`LINE_SEARCH_RETRY`]; off with `-porompm_snes_line_search_retry false`).
    retry_with_line_search: bool,
    /// Whether MUMPS's workspace has been enlarged already ([`MUMPS_WORKSPACE_FACTOR`]).
    mumps_enlarged: bool,
    /// The solver of the pressure's L² projection (built on first use).
    l2_projection: Option<L2Projection<D>>,
    /// Steps that reused the previous matrix structure (and hence its symbolic factorisation).
    pub reused_patterns: usize,
    /// The owned part of the last accepted step's Δd and its Δt, the predictor of the next step
    /// when the analysis extrapolates (see [`crate::scheme::Integration::extrapolates`]).
    last_increment: Option<(Vec<f64>, f64)>,
    stages: Stages,
}

/// The global system of a three-dimensional grid.
pub type SolidSystem = System<3, { kernels::MAX_NODES_3D }, { crate::layout::MAX_DOF_3D }>;

impl<const D: usize, const M: usize, const N: usize> System<D, M, N> {
    /// Creates the node space for the grid and dof layout on the run's communicator, and the SNES
    /// with porompm's defaults, then lets the PETSc options database override them. Defaults:
    /// Newton with full steps, relative residual tolerance 1e-6 as in [003] Algorithm 1; sparse LU
    /// by UMFPACK (the fastest of the measured strategies on the verification cases, see
    /// docs/solvers.md) up to [`super::UMFPACK_MAX_GRID_DOFS`], on several ranks each rank on its
    /// own copy of the matrix, and by MUMPS beyond ([`super::default_factor`]).
    ///
    /// `partition` distributes the nodes over the ranks (None: PETSc's even split); see
    /// [`crate::distribution::balanced`]. The Newton iterations allowed per step are
    /// [`super::newton_iterations`] of the case's `stiffness`.
    pub fn new(
        coll: &Collective,
        grid: &Grid<D>,
        layout: Layout,
        partition: Option<&Owners<D>>,
        stiffness: Stiffness,
    ) -> Result<System<D, M, N>, Error> {
        let space = NodeSpace::new(coll, grid, layout, partition)?;
        let comm = space.comm;
        let x = space.dm.create_global_vector()?;
        let x_local = space.dm.create_local_vector()?;
        let f_local = space.dm.create_local_vector()?;
        let mut snes = Snes::new(comm)?;
        snes.set_dm(&space.dm)?;
        snes.set_type("newtonls")?;
        snes.set_line_search("basic")?;
        snes.set_tolerances(Some(1e-50), Some(1e-6), Some(1e-12), Some(super::newton_iterations(stiffness)))?;
        {
            let mut ksp = snes.ksp()?;
            ksp.set_type("preonly")?;
            let mut pc = ksp.pc()?;
            match super::default_factor(comm, grid.node_count() * layout.nd) {
                super::DefaultFactor::Lu(package) => {
                    pc.set_type("lu")?;
                    pc.set_factor_solver_type(package)?;
                }
                super::DefaultFactor::Redundant(package) => {
                    pc.set_type("redundant")?;
                    let mut own = pc.redundant_ksp()?;
                    own.set_type("preonly")?;
                    let mut own_pc = own.pc()?;
                    own_pc.set_type("lu")?;
                    own_pc.set_factor_solver_type(package)?;
                }
            }
        }
        let pc_matrix = PcMatrix::from_options(layout)?;
        pc_matrix.set_default_options(&snes.pc_prefix()?)?;
        snes.set_from_options()?;
        let positions = space.owned_positions(grid);
        let first_dof = x.ownership_range()?.0;
        let schur = splits::define(&mut snes, comm, coll, layout, first_dof, &positions)?;
        let schur_tuning = SchurTuning::from_options()?;
        let near_null = splits::displacement_near_null_space(comm, coll, layout, &positions)?;
        // Every linear solve measured field by field (not under Eisenstat–Walker, whose own
        // post-solve hook it would replace).
        if !snes.uses_eisenstat_walker()? {
            let test = petsc::Options::global().get_bool(FIELD_TEST_OPTION)?.unwrap_or(true);
            snes.monitor_fields(layout.fields().into_iter().map(|(_, c)| c).collect(), test)?;
        }
        let user_atol = snes.tolerances()?.0;
        let retry_with_line_search = petsc::Options::global().get_bool(LINE_SEARCH_RETRY_OPTION)?.unwrap_or(true);
        let stages = Stages {
            run_setup: LogStage::register("porompm: setup")?,
            setup: LogStage::register("porompm: step setup")?,
            solve: LogStage::register("porompm: Newton solve")?,
            assembly: LogStage::register("porompm: assembly")?,
            update: LogStage::register("porompm: particle update")?,
            output: LogStage::register("porompm: output")?,
        };
        Ok(System {
            space,
            x,
            x_local,
            f_local,
            snes,
            matrix: None,
            pc_matrix,
            lowered: None,
            near_null,
            schur,
            schur_tuning,
            user_atol,
            retry_with_line_search,
            mumps_enlarged: false,
            l2_projection: None,
            reused_patterns: 0,
            last_increment: None,
            stages,
        })
    }

    /// The grid's nodes on this rank.
    pub fn space(&self) -> &NodeSpace<D> {
        &self.space
    }

    /// The dof layout.
    pub fn layout(&self) -> Layout {
        self.space.layout
    }

    /// This rank's matrix memory in bytes: the compressed-row storage in PETSc
    /// (`petsc::mat::MatStats`) and the program's side of it (the block pattern and the blocks'
    /// places in the matrix, into which a Jacobian writes its blocks with no buffer of its own), of
    /// the Jacobian and of the preconditioning matrix where it has one of its own; zeros without a
    /// matrix. Not collective.
    pub fn matrix_memory(&self) -> Result<(f64, usize), Error> {
        let (mut petsc, mut own) = (0.0, 0);
        for m in self.matrix.iter().chain(&self.lowered) {
            petsc += m.mat.stats()?.memory_bytes;
            own += m.pattern.heap_bytes() + m.places.heap_bytes();
        }
        Ok((petsc, own))
    }

    /// Enters a log stage until the guard is dropped.
    pub fn phase(&self, p: Phase) -> Result<StageGuard, Error> {
        match p {
            Phase::Setup => self.stages.run_setup.push(),
            Phase::StepSetup => self.stages.setup.push(),
            Phase::NewtonSolve => self.stages.solve.push(),
            Phase::ParticleUpdate => self.stages.update.push(),
            Phase::Output => self.stages.output.push(),
        }
    }

    /// Prepares the step t_n → t_{n+1} = `t_new` of length `dt` with the stage's `active` loads and
    /// boundaries ([`Step::prepare`]); `stage_start` says it is the first of its stage.
    /// Collective; every rank returns the same outcome.
    pub fn prepare(
        &mut self,
        model: &Model<D>,
        active: &Active,
        (t_new, dt): (f64, f64),
        stage_start: bool,
        coll: &Collective,
    ) -> Result<Step<D, M>, String>
    where
        Dim<D>: StepDim<D>,
    {
        let schur = SchurNeeds {
            schur: self.schur.is_some(),
            blocks: self.schur.as_ref().is_some_and(|s| s.has_blocks()),
            tuning: self.schur_tuning,
        };
        let kept = self.matrix.as_ref().map(|m| m.pattern.clone());
        let pc_matrix = (self.pc_matrix, self.lowered.as_ref().map(|m| m.pattern.clone()));
        let request = StepRequest { active, times: (t_new - dt, t_new), kept, pc_matrix, schur, stage_start };
        Step::prepare::<N>(&mut self.space, model, request, coll)
    }

    /// Solves the prepared `step`: an explicit step's nodal update ([`explicit`]), or Newton's
    /// method from Δd = 0, or, when the analysis extrapolates, from the last accepted increment
    /// scaled by Δt / Δt_last; every fixed dof starts at its prescribed increment. Geometrically
    /// linear steps start from Δd = 0: their residual is affine in Δd, so the exact tangent needs
    /// one iteration from anywhere, and one solve with one of [001]'s mapped stiffnesses is then
    /// [001]'s K Δu = ΔF. Full Newton steps that diverge are tried once more from the same start
    /// with a backtracking line search ([`LINE_SEARCH_RETRY`]).
    pub fn solve(
        &mut self,
        step: &Step<D, M>,
        model: &Model<D>,
        coll: &Collective,
    ) -> Result<(StepSolve, Solution), Error> {
        if model.integration.is_explicit() {
            return explicit::update::<D, M, N>(&mut self.space, step, model);
        }
        self.matrix_for(step, coll)?;
        let _stage = self.stages.solve.push()?;
        // A floor under the relative test: FORCE_ATOL of the step's force magnitudes.
        let atol = self.user_atol.max(FORCE_ATOL * step.force_scale);
        self.snes.set_tolerances(Some(atol), None, None, None)?;
        let t0 = Instant::now();
        self.initial_guess(step, model)?;
        let (mut out, mut nonfinite, mut assembly) = self.newton(step, model, coll)?;
        let mut line_search_retry = false;
        if !out.converged
            && super::DIVERGED_BY_FULL_STEPS.contains(&out.reason_text.as_str())
            && self.retry_with_line_search
            && self.snes.type_name()? == "newtonls"
            && self.snes.line_search_type()? == "basic"
        {
            line_search_retry = true;
            self.initial_guess(step, model)?;
            self.snes.set_line_search(LINE_SEARCH_RETRY)?;
            let retry = self.newton(step, model, coll);
            self.snes.set_line_search("basic")?;
            let (second, second_nonfinite, time) = retry?;
            assembly.add(time);
            // A point that was not finite in the first try names the failure only if the second
            // fails too.
            nonfinite = if second.converged { None } else { nonfinite.or(second_nonfinite) };
            out = combined(out, second);
        }
        let mut workspace_retry = None;
        if let Some(before) = out.factorisation.filter(|m| m.workspace_too_small() && !self.mumps_enlarged) {
            let icntl14 = self.enlarge_mumps_workspace(before.icntl14)?;
            workspace_retry = Some(format!("{}; factorised again with ICNTL(14) = {icntl14}", before.cause()));
            self.initial_guess(step, model)?;
            let (second, second_nonfinite, time) = self.newton(step, model, coll)?;
            assembly.add(time);
            nonfinite = if second.converged { None } else { nonfinite.or(second_nonfinite) };
            out = SolveOutcome {
                iterations: out.iterations + second.iterations,
                linear_iterations: out.linear_iterations + second.linear_iterations,
                ..second
            };
        }
        // A factorisation that failed names its cause (and, for MUMPS's workspace, the option).
        if let Some(m) = out.factorisation.filter(|_| !out.converged) {
            out.reason_text = match m.workspace_too_small() {
                true => format!(
                    "{} ({} also with ICNTL(14) = {}; give -mat_mumps_icntl_14 a larger value)",
                    out.reason_text,
                    m.cause(),
                    m.icntl14
                ),
                false => format!("{} ({})", out.reason_text, m.cause()),
            };
        }
        let solve_seconds = t0.elapsed().as_secs_f64();
        self.space.dm.global_to_local(&self.x, &mut self.x_local)?;
        let mut increments = self.x_local.read()?.to_vec();
        for (q, v) in increments.iter_mut().enumerate() {
            *v *= step.unit(q);
        }
        let components = &out.final_residual_components;
        let field_residuals = if components.len() == step.layout.nd {
            let norm = |cs: &[usize]| cs.iter().map(|&c| components[c] * components[c]).sum::<f64>().sqrt();
            step.layout.fields().iter().map(|(_, cs)| norm(cs)).collect()
        } else {
            Vec::new()
        };
        let solve = StepSolve {
            converged: out.converged,
            reason: out.reason_text,
            newton_iterations: out.iterations,
            linear_iterations: out.linear_iterations,
            residual_history: out.residual_history,
            domain_error: out.domain_error,
            nonfinite,
            assembly,
            solve_seconds,
            field_residuals,
            field_scales: step.field_scales.clone(),
            linear_field_residuals: out.linear_field_residuals,
            solver_used: true,
            line_search_retry,
            workspace_retry,
        };
        Ok((solve, Solution { increments, ..Solution::default() }))
    }

    /// The matrices of `step`'s patterns: the last ones while the step shares their patterns, else
    /// new ones (with the near-null space of a displacement system; the Schur preconditioner then
    /// forgets the old matrix's blocks). Before a new matrix is allocated the solver lets go of
    /// the one it replaces and of what its preconditioner built from it, so that the two do not
    /// sit in memory together. Collective.
    fn matrix_for(&mut self, step: &Step<D, M>, coll: &Collective) -> Result<(), Error> {
        let jacobian_kept = self.matrix.as_ref().is_some_and(|m| Arc::ptr_eq(&m.pattern, &step.pattern));
        let lowered_kept = match (&step.lowered, &self.lowered) {
            (Some(lowered), Some(m)) => Arc::ptr_eq(&m.pattern, &lowered.pattern),
            (None, None) => true,
            _ => false,
        };
        if jacobian_kept {
            self.reused_patterns += 1;
            if lowered_kept {
                return Ok(());
            }
        }
        if self.matrix.is_some() {
            match &self.lowered {
                Some(kept) if lowered_kept => self.snes.release_jacobian(&kept.mat)?,
                _ => {
                    self.snes.release_operators()?;
                }
            }
        }
        if !lowered_kept {
            self.lowered = None;
            if let Some(lowered) = &step.lowered {
                self.lowered = Some(self.new_matrix(&lowered.pattern, coll)?);
            }
        }
        if !jacobian_kept {
            self.matrix = None;
            let matrix = self.new_matrix(&step.pattern, coll)?;
            if let Some(schur) = &mut self.schur {
                schur.forget();
            }
            self.matrix = Some(matrix);
        }
        Ok(())
    }

    /// A matrix of `pattern` with the near-null space of a displacement system attached (which
    /// GAMG reads from the matrix it builds its hierarchy from). Collective.
    fn new_matrix(&self, pattern: &Arc<Pattern<D>>, coll: &Collective) -> Result<Matrix<D>, Error> {
        let mut matrix = Matrix::of(pattern, &self.space, coll).map_err(Error::new)?;
        let null = if self.near_null.is_empty() {
            Ok(())
        } else {
            matrix.mat.set_near_null_space(self.space.comm, &self.near_null)
        };
        coll.agree(null.map_err(|e| e.to_string())).map_err(Error::new)?;
        Ok(matrix)
    }

    /// Sets MUMPS's workspace relaxation ICNTL(14) to [`MUMPS_WORKSPACE_FACTOR`] times `icntl14`
    /// (at least 20 %) in the options database, which the next factorisation reads (the failed
    /// one's factors are dropped), and returns the new value.
    fn enlarge_mumps_workspace(&mut self, icntl14: petsc::Int) -> Result<petsc::Int, Error> {
        let enlarged = icntl14.max(20) * MUMPS_WORKSPACE_FACTOR;
        let name = format!("-{}mat_mumps_icntl_14", self.snes.pc_prefix()?);
        petsc::Options::global().set_value(&name, Some(&enlarged.to_string()))?;
        self.mumps_enlarged = true;
        Ok(enlarged)
    }

    /// One SNES solve of `step` from the current iterate: its outcome, the first point whose
    /// residual was not finite, and the callbacks' wall time.
    fn newton(
        &mut self,
        step: &Step<D, M>,
        model: &Model<D>,
        coll: &Collective,
    ) -> Result<(SolveOutcome, Option<String>, AssemblyTime), Error> {
        let System { space, x, x_local, f_local, snes, matrix, lowered, schur, stages, .. } = self;
        let Matrix { mat: jac, places, .. } = matrix.as_mut().ok_or_else(|| Error::new("the step has no matrix"))?;
        let (pmat, pc_places) = match lowered.as_mut() {
            Some(Matrix { mat, places, .. }) => (Some(mat), Some(&*places)),
            None => (None, None),
        };
        let places = (&*places, pc_places);
        let work =
            Workspace { dm: &space.dm, x_local, f_local, stage: &stages.assembly, schur: schur.as_mut(), places, coll };
        let mut callbacks = Callbacks::<D, M, N>::new(model, step, work);
        let out = snes.solve(x, jac, pmat, &mut callbacks)?;
        Ok((out, callbacks.nonfinite.take(), callbacks.time))
    }

    /// Sets PETSc's solution vector to the step's first iterate: the last accepted increment
    /// scaled to the new Δt where the stage extrapolates (static and quasi-static), zero
    /// otherwise, with the prescribed increments at the fixed dofs.
    fn initial_guess(&mut self, step: &Step<D, M>, model: &Model<D>) -> Result<(), Error> {
        let mut x = self.x.write()?;
        match &self.last_increment {
            Some((last, dt_last))
                if model.integration.extrapolates() && !model.linear_increments && last.len() == x.len() =>
            {
                let ratio = step.dt / dt_last;
                for (xi, li) in x.iter_mut().zip(last) {
                    *xi = ratio * li;
                }
            }
            _ => x.fill(0.0),
        }
        for &(o, q) in &step.dofs.owned_fixed {
            x[o] = step.dofs.value[q] / step.unit(q);
        }
        Ok(())
    }

    /// Keeps the increment of the step just accepted (of length `dt`) as the next step's
    /// predictor.
    pub fn accept_increment(&mut self, dt: f64) -> Result<(), Error> {
        self.last_increment = Some((self.x.read()?.to_vec(), dt));
        Ok(())
    }

    /// Forgets the last increment: the next step starts from Δd = 0 (a new stage changes the loads
    /// or the analysis, so the last rate says nothing about the next step).
    pub fn forget_increment(&mut self) {
        self.last_increment = None;
    }

    /// The pore-pressure increments the points take from the converged step: each point's
    /// interpolated increment (`None`), or with `stabilisation.pressure_update = "projected_total"`
    /// the L² projection's ([`L2Projection::increments`]), or with patch recovery the MLSA
    /// patches' ([`pressure::recovered_increments`]). Collective.
    pub fn pressure_increments(
        &mut self,
        step: &Step<D, M>,
        solution: &Solution,
        model: &Model<D>,
    ) -> Result<Option<Vec<f64>>, Error> {
        if step.layout.p.is_none() {
            return Ok(None);
        }
        if model.pressure_update == PressureUpdate::ProjectedTotal {
            let l2 = match &mut self.l2_projection {
                Some(l2) => l2,
                empty => empty.insert(L2Projection::new(&self.space)?),
            };
            return l2.increments(&self.space, step, solution, model).map(Some);
        }
        if model.pore_water && model.patch_recovery {
            let interpolated = |k: usize| step.result::<N>(model, solution, k).interp.dp;
            return Ok(Some(pressure::recovered_increments(&self.space, step, solution, model, interpolated)));
        }
        Ok(None)
    }

    /// This rank's block of nodal values after `step` ([`Step::node_block`]).
    pub fn node_block(&self, step: &Step<D, M>, solution: &Solution, diagnostics: &[[f64; 2]]) -> NodeBlock {
        self.space.node_block(step, solution, diagnostics)
    }

    /// The solver configuration (SNES type and Newton variant, KSP and PC types and the
    /// factorisation package), for the summary, and whether the linear solver iterates (any KSP
    /// but `preonly`).
    pub fn solver(&mut self) -> Result<(String, bool), Error> {
        let snes_type = self.snes.type_name()?;
        let lag = self.snes.lag_jacobian()?;
        let mut ksp = self.snes.ksp()?;
        let ksp_type = ksp.type_name()?;
        let mut pc = ksp.pc()?;
        let pc_type = pc.type_name()?;
        let factor_of = |pc: &petsc::PcRef| -> Result<String, Error> {
            let pc_type = pc.type_name()?;
            Ok(if pc_type == "lu" || pc_type == "cholesky" {
                pc.factor_solver_type()?.map(|s| format!(" ({s})")).unwrap_or_default()
            } else {
                String::new()
            })
        };
        let factor = if pc_type == "redundant" {
            let mut own = pc.redundant_ksp()?;
            let own_type = own.type_name()?;
            let own_pc = own.pc()?;
            format!(" of {own_type} {}{}", own_pc.type_name()?, factor_of(&own_pc)?)
        } else {
            factor_of(&pc)?
        };
        let newton = if lag > 1 || lag == -1 || lag == -2 { "modified Newton (lagged Jacobian)" } else { "Newton" };
        Ok((format!("{snes_type} {newton}; KSP {ksp_type}; PC {pc_type}{factor}"), ksp_type != "preonly"))
    }

    /// The mat-vecs with the whole tangent timed after the linear solves (see `petsc::fields`) and
    /// their total wall time [s] on this rank.
    pub fn timed_matvecs(&self) -> (usize, f64) {
        self.snes.timed_matvecs()
    }

    /// The parts the Jacobian check and the benchmark borrow: the SNES's iterate, the matrix and
    /// the callbacks of `step`.
    pub(super) fn parts<'a>(
        &'a mut self,
        step: &'a Step<D, M>,
        model: &'a Model<D>,
        coll: &'a Collective,
    ) -> Result<(&'a mut Vector, &'a mut Mat, Callbacks<'a, D, M, N>), Error> {
        self.matrix_for(step, coll)?;
        let System { space, x, x_local, f_local, matrix, schur, stages, .. } = self;
        let Matrix { mat: jac, places, .. } = matrix.as_mut().ok_or_else(|| Error::new("the step has no matrix"))?;
        let places = (&*places, None);
        let work =
            Workspace { dm: &space.dm, x_local, f_local, stage: &stages.assembly, schur: schur.as_mut(), places, coll };
        Ok((x, jac, Callbacks::new(model, step, work)))
    }
}

/// The outcome of a step solved twice, the second time with a line search: the second's, with the
/// iterations of both and the first's reason where the second failed too.
/// How many times its workspace relaxation ICNTL(14) MUMPS gets after it ran out of workspace:
/// 20 % (MUMPS's default) becomes 400 %, the value measured to factorise the slumping block at a
/// hydraulic conductivity of 1e-12 m/s, where the default fails.
pub const MUMPS_WORKSPACE_FACTOR: petsc::Int = 20;

fn combined(first: SolveOutcome, second: SolveOutcome) -> SolveOutcome {
    SolveOutcome {
        iterations: first.iterations + second.iterations,
        linear_iterations: first.linear_iterations + second.linear_iterations,
        reason_text: if second.converged {
            second.reason_text.clone()
        } else {
            format!("{} ({} with a line search)", first.reason_text, second.reason_text)
        },
        ..second
    }
}
