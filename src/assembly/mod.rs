//! The global system: the only application module that talks to PETSc.
//!
//! A DMDA holds the background grid (dofs of the layout interlaced per node), so that the
//! distribution of nodes over ranks, ghost nodes and the global numbering come from PETSc. Every
//! step ([`GridSystem::prepare_step`]) runs the same named steps, whatever the analysis:
//! 1. `stencils_on_xn` ([`stencils::build`]): each particle's stencil (nodes, S, ∇S, ∇̄S) on x_n,
//!    once per step; a support reaching past the grid is an error;
//! 2. `project`: masses, momenta, mass-weighted accelerations, porosities and filled fractions
//!    mapped to the nodes ([003] Eq. 19) and summed over ranks;
//! 3. `dof_map` ([`dofs::build`]): the dof map — free dofs, dofs fixed by the active boundaries
//!    (with their prescribed increments) and the dofs of nodes the material barely fills; then the
//!    grid-edge check and [`stencils::extend`]: each particle's effective stencil, extending the
//!    motion of barely filled nodes from well-filled ones (see [`stencils`]);
//! 4. `step_data`: the threads' bands, the Newmark predictors and porosity gradients, the
//!    pressure-projection blocks and the external forces at t_{n+1}, with the check that every
//!    applied force reaches a node that carries it, the generalized-α history and the force scale;
//! 5. `matrix_pattern` ([`pattern`]): the COO pattern of the matrix, kept while it holds every
//!    pair the particles need.
//!
//! The analysis type enters only through the layout (which fields a node carries) and the
//! [`kernels::Scheme`] of the step.
//!
//! [`GridSystem::solve`] then runs PETSc SNES with residual and Jacobian callbacks
//! ([`callbacks`]) that loop over particles, call the pure kernels of [`crate::kernels`], map their
//! blocks through the extensions and add them to a local vector (summed over ranks by PETSc) and to
//! one COO value array. Every decision that leads to a collective is agreed across ranks first
//! ([`Collective::agree`]).

mod aggregates;
mod bench;
mod callbacks;
mod check;
pub mod dofs;
mod explicit;
pub mod pattern;
mod splits;
pub mod stencils;
mod stiffness;

pub use check::BlockCheck;
pub use stencils::WELL_FILLED_FRACTION;

use crate::kernels::{self, Layout, StepResult};
use crate::model::loads::{face_point, LoadTarget};
use crate::model::shape;
use crate::model::{Active, Model};
use crate::parallel::Collective;
use callbacks::Assembler;
use dofs::DofMap;
use mpi::raw::AsRaw;
use pattern::Pattern;
use petsc::ksp::KspOps;
use petsc::mat::MatOps;
use petsc::snes::SolveOutcome;
use petsc::{Comm, DmDa, GhostedRange, Ksp, LogStage, Mat, Options, Snes, StageGuard, VecOps, Vector};
use std::time::Instant;
use stencils::{Crossing, Stencils};

/// Errors of the global system.
pub type Error = petsc::Error;

/// A cell of the pressure projection: its 2^D corner nodes (ghosted numbers, x fastest) and the
/// C × C block S of `kernels::pressure_projection`, row by row.
#[derive(Debug, Clone, Default)]
struct ProjectionCell {
    nodes: Vec<u32>,
    s: Vec<f64>,
}

/// Per-step data shared by the callbacks (points of dimension D with at most M nodes).
#[derive(Debug, Default)]
struct StepData<const D: usize = 2, const M: usize = { kernels::MAX_NODES }> {
    nm: Option<kernels::Scheme>,
    /// The step's Δt [s].
    dt: f64,
    layout: Option<Layout>,
    /// Body acceleration at t_{n+1} per body.
    body_acc: Vec<[f64; D]>,
    stencils: Stencils<D>,
    dofs: DofMap,
    /// External nodal forces at t_{n+1} (tractions) per ghosted dof, on the nodes that carry them.
    fext: Vec<f64>,
    /// The same at t_n (for the generalized-α history and the work of the step).
    fext_old: Vec<f64>,
    /// The generalized-α history per ghosted dof: α_m M a_n + α_f (forces at t_n) − α_f f_ext,n
    /// (empty for a scheme without one).
    history: Vec<f64>,
    /// Δd at convergence, per ghosted dof (extended motion is not stored here).
    solution: Vec<f64>,
    /// Porosity gradient at each particle at t_n (two-phase).
    grad_n: Vec<[f64; D]>,
    /// v_u, a_u, v_w, a_w at t_n at each particle, from the nodal projections.
    smooth: Vec<[[f64; D]; 4]>,
    /// The norm of the step's force magnitudes over the free dofs (see
    /// `Assembler::force_magnitudes`), summed over ranks [N per m].
    force_scale: f64,
    /// Pressure-projection cells (see [`ProjectionCell`]).
    projection: Vec<ProjectionCell>,
    /// The matrix pattern (kept from step to step while it covers the particles' pairs).
    pattern: Pattern<D>,
    /// The bands of node rows the threads assemble (see [`callbacks::Band`]).
    bands: Vec<callbacks::Band>,
    /// The pattern block of every corner pair (a, b) of each pressure-projection cell, C a + b for
    /// its C corners.
    projection_blocks: Vec<Vec<u32>>,
    /// (diagonal block, component) of every owned fixed dof.
    fixed_diagonals: Vec<(u32, usize)>,
    /// The pressure unknown's scale s [Pa/m] (see [`pressure_scale`]): PETSc sees Δp / s, and the
    /// continuity rows multiplied by s; 0 until the step is prepared.
    p_scale: f64,
    /// The norm of the force magnitudes of each field (`Layout::fields`) over its free dofs, in
    /// PETSc's scaling: the scale of the field's residual.
    field_scales: Vec<f64>,
    /// The diagonal the fixed-stress Schur preconditioner adds to A_pp, per owned pressure row
    /// (see [`GridSystem::fixed_stress_diagonal`]; empty without that preconditioner).
    fixed_stress: Vec<f64>,
    /// The free-surface aggregates of the u–p–U system's Schur preconditioner, as positions in
    /// this rank's rows of the `u` split (see [`aggregates`]; empty without it).
    schur_groups: Vec<Vec<usize>>,
    /// The drained faces imposed weakly (see [`GridSystem::drained_faces`]) and the particle of
    /// each, in increasing order.
    faces: Vec<kernels::DrainedFace<D, M>>,
    face_owner: Vec<usize>,
    /// The material stiffness of the Newton matrix (`stabilisation.stiffness`).
    stiffness: stiffness::MappedStiffness,
    /// An explicit step: the terms of its start (σ_n on x_n and the body force of t_{n+1}, without
    /// the loads; see [`explicit`]), this rank's shares per ghosted dof; `None` otherwise.
    start_terms: Option<StartTerms>,
    /// An explicit step: the lumped inertia m_i a_i of its nodal update plus the local damping
    /// force and, two-phase, the drag on the phase, per ghosted dof (summed over ranks), for the
    /// equilibrium identity; empty otherwise.
    explicit_inertia: Vec<f64>,
    /// The F̄ projection of each particle's step (`stabilisation.fbar`, explicit steps;
    /// [`explicit`]): the scale c_p of its increment, the scale s_p of its total deformation and
    /// its projected J̄_p^{n+1}; empty otherwise.
    fbar_scale: Vec<[f64; 3]>,
    /// An explicit XPIC step: the nodal field w − v^n its points' velocities take (see
    /// [`explicit`]), per ghosted dof; empty otherwise.
    xpic_correction: Vec<f64>,
    /// An explicit step: the nodal velocities v_i^n of its grid update, per ghosted dof (the
    /// lumped momentum over the lumped mass, zero where a boundary holds the component still),
    /// from which the FLIP update takes Σ S_ip v_i^n (see [`explicit`]); empty otherwise.
    start_velocity: Vec<f64>,
    /// A two-phase explicit step with the nodal pore pressure: whether each ghosted node is
    /// drained (a boundary fixes `p` there, or the material barely fills it; see [`explicit`]);
    /// empty otherwise.
    drained: Vec<bool>,
    /// A two-phase explicit step with the nodal pore pressure: each point's Δp, Σ_i S_ip Δp_i
    /// (see [`explicit`]); empty otherwise (a point-wise pressure is the point's own).
    pressure_increment: Vec<f64>,
}

/// The nodal terms of an explicit step's start, this rank's shares per ghosted dof (see
/// `Assembler::nodal_terms` at Δd = 0): one pass over the points gives the force that accelerates
/// the nodes and the step's equilibrium identity.
#[derive(Debug, Default)]
struct StartTerms {
    /// The residual without the external loads: f_int(σ_n) minus the body force.
    all: Vec<f64>,
    /// `all` minus the internal forces: the body force's share.
    inertia: Vec<f64>,
    /// Σ of the absolute values of the points' blocks plus the absolute external loads.
    magnitude: Vec<f64>,
}

impl<const D: usize, const M: usize> StepData<D, M> {
    /// The drained faces of particle `k` (usually none).
    fn faces_of(&self, k: usize) -> &[kernels::DrainedFace<D, M>] {
        let lo = self.face_owner.partition_point(|&o| o < k);
        let hi = lo + self.face_owner[lo..].partition_point(|&o| o == k);
        &self.faces[lo..hi]
    }

    /// The physical increment of ghosted dof `q` per unit of its PETSc unknown: s for a pressure
    /// dof, 1 for the others.
    fn unit(&self, q: usize) -> f64 {
        match self.layout.and_then(|l| l.p) {
            Some(p) if q % self.dofs.nd == p => self.p_scale,
            _ => 1.0,
        }
    }
}

/// Values per node of a two-dimensional [`NodeBlock`]: whether it is well filled, the step's
/// increments of ux, uy, p, Ux, Uy (0 where the layout has none), K_mag and F^int_mag.
pub const NODE_VALUES: usize = node_values(2);

/// Values per node of a [`NodeBlock`] in `d` dimensions: the well-filled flag, the increments of
/// the full two-phase layout (ux, uy, [uz,] p, Ux, Uy[, Uz]), K_mag and F^int_mag.
pub const fn node_values(d: usize) -> usize {
    2 * d + 4
}

/// The nodes a rank owns: the box of grid nodes `start .. start + count` (i, j, k; k = 0 and one
/// layer in two dimensions) and [`node_values`] values per node, x fastest (see
/// [`GridSystem::owned_node_block`]).
#[derive(Debug, Clone, Default)]
pub struct NodeBlock {
    /// The first owned node (i, j, k).
    pub start: [usize; 3],
    /// The owned nodes along x, y and z.
    pub count: [usize; 3],
    /// The values, node by node.
    pub values: Vec<f64>,
}

/// The scale s of the pressure unknowns [Pa/m]: the largest constrained modulus of the skeleton
/// over the smallest cell size, M/h. PETSc solves for Δp / s, and the continuity rows are
/// multiplied by s (a symmetric diagonal scaling, so a symmetric tangent stays symmetric). A
/// momentum row's entries are of order M (stiffness) and its coupling to the pressure of order h,
/// so after scaling the coupling block is of order M as well, and a volume imbalance δV of a
/// continuity row weighs s δV, as much as the force M δV / h it would take to close it. Without
/// it the continuity rows are 1e-9…1e-20 of the momentum rows, and Newton's residual norm (and
/// its absolute tolerance) cannot see an unsolved pressure equation: a quasi-static step that
/// starts from the extrapolated increment was accepted with no iteration while its pore pressure
/// drifted by 0.1 % of the load per step (Terzaghi, Δt = 0.1 s).
pub fn pressure_scale<const D: usize>(model: &Model<D>) -> f64 {
    let m = model.materials.iter().map(|m| m.model.elastic().constrained_modulus()).fold(0.0, f64::max);
    let h = model.grid.h_min();
    if m > 0.0 && h > 0.0 {
        m / h
    } else {
        1.0
    }
}

/// The share c of the solid's fixed-stress term in the Schur preconditioner of the u–p–U system
/// (see `GridSystem::fixed_stress_diagonal`) for a step of `dt`: c = min(1, Cr / 108), Cr =
/// c_p Δt / h the Courant number of the fastest drained compression wave, c_p = √(M / ρ) with the
/// drained constrained modulus M and the mixture's density ρ = (1 − n) ρ_s + n ρ_w, h the smallest
/// cell size. Fitted on the spectra of the slumping block's tangents (docs/solvers.md): the best
/// shares 0.0625 at Δt = 4 ms and 0.25 at 16 ms on 64 × 48 cells (Cr = 6.7 and 27) lie on it, and
/// at 1 ms (Cr = 1.7; best share 0) it adds 0.016.
fn fixed_stress_share<const D: usize>(model: &Model<D>, dt: f64) -> f64 {
    let cp = model
        .materials
        .iter()
        .map(|m| {
            let rho = (1.0 - m.porosity) * m.solid_density + m.porosity * m.water_density;
            (m.model.elastic().constrained_modulus() / rho).sqrt()
        })
        .fold(0.0, f64::max);
    (cp * dt / model.grid.h_min() / FIXED_STRESS_COURANT).min(1.0)
}

/// The Courant number at which [`fixed_stress_share`] reaches 1.
const FIXED_STRESS_COURANT: f64 = 108.0;

/// The PETSc option that turns the field-wise Krylov convergence test off (`false`): by default
/// a Krylov solve converges only when the residual of every field (u, p, U), relative to its own
/// equations' terms, is within `-ksp_rtol` (see `petsc::fields::FieldTest`).
pub const FIELD_TEST_OPTION: &str = "-porompm_ksp_field_test";

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
    /// Wall time spent in the residual and Jacobian callbacks [s].
    pub assembly_seconds: f64,
    /// Wall time of the whole SNES solve [s].
    pub solve_seconds: f64,
    /// The norm of the final Newton residual of each field (`Layout::fields`), in PETSc's scaling.
    pub field_residuals: Vec<f64>,
    /// The norm of each field's force magnitudes at the start of the step (Δd = 0), in PETSc's
    /// scaling (see `Assembler::force_magnitudes`).
    pub field_scales: Vec<f64>,
    /// The largest relative residual of each field over the step's linear solves (see
    /// `petsc::fields::relative_field_residuals`; empty when not measured).
    pub linear_field_residuals: Vec<f64>,
    /// Whether PETSc's solver ran (false for an explicit step).
    pub solver_used: bool,
    /// Whether full Newton steps failed and the step was solved again with a line search
    /// after they diverged ([`LINE_SEARCH_RETRY`]; `converged` is then the second solve's outcome).
    pub line_search_retry: bool,
}

/// The line search of a step's second try when full Newton steps (porompm's default, `basic`)
/// failed, before the driver cuts Δt: PETSc's backtracking (cubic) search, which shortens a Newton
/// step that would raise the residual norm. Full steps stay the default: they converge
/// quadratically on every shipped case and leave its answers as they are; a failed step costs one
/// more solve. Measured on the static strip footing (`cases/footing_fbar.toml` as an implicit
/// static stage, B/20): at d/B ≈ 0.014 a node beside the footing that the heave had barely reached
/// (1 % filled) took unknowns of its own, full Newton steps diverged whatever the cut of Δt, and
/// the line search carried every step to d/B = 0.021. A case that sets its own line search
/// (`-snes_linesearch_type`) is left as it is; [`LINE_SEARCH_RETRY_OPTION`] turns the retry off.
/// Only a divergence is retried ([`DIVERGED_BY_FULL_STEPS`]): a step that ran out of iterations
/// (`DIVERGED_MAX_IT`) is better served by a shorter Δt (on `cases/slope_sand.toml`, retrying
/// those too took 27 % more wall time and 37 % more Newton iterations).
pub const LINE_SEARCH_RETRY: &str = "bt";

/// The SNES outcomes of full Newton steps that [`LINE_SEARCH_RETRY`] retries: the residual norm
/// grew past the divergence tolerance, or became NaN, or left the residual's domain.
pub const DIVERGED_BY_FULL_STEPS: [&str; 3] = ["DIVERGED_DTOL", "DIVERGED_FNORM_NAN", "DIVERGED_FUNCTION_DOMAIN"];

/// The PETSc option that turns the line-search retry of failed steps off (`false`; see
/// [`LINE_SEARCH_RETRY`]).
pub const LINE_SEARCH_RETRY_OPTION: &str = "-porompm_snes_line_search_retry";

/// The forces of a converged step, summed over ranks, for the equilibrium identity and the
/// boundaries' reactions.
#[derive(Debug, Clone)]
pub struct StepForces<const D: usize = 2> {
    /// Σ_i x'_i ⊗ (F_ext,i + R_i − F_inertia,i) over the nodes, with x' = x + Δu the nodes' positions
    /// at t_{n+1} relative to `origin` (rows a, columns b: x_a F_b).
    pub moment: [[f64; D]; D],
    /// The largest of the moments of the external forces, the reactions and the inertia forces
    /// (Frobenius norms), which scales the identity's error.
    pub scale: f64,
    /// The reference point of the moments [m].
    pub origin: [f64; D],
    /// The reaction of each boundary (index into `Model::boundaries`) on the material: the force
    /// the fixed dofs of both phases exert [N per m in two dimensions, N in three].
    pub reactions: Vec<[f64; D]>,
    /// The work of the external forces and the reactions over the step, Σ_i F̄_i · Δd_i over the
    /// displacement dofs of both phases, with F̄ the mean of the forces at t_n and t_{n+1}
    /// (trapezoidal; the reactions at t_n are the last step's, none after a new grid system) [J per m].
    pub work: f64,
    /// The norm of each field's equation magnitudes at the converged state (Σ over particles of
    /// their absolute residual blocks plus the absolute loads, over the free dofs, in PETSc's
    /// scaling): with the magnitudes at the step's start, the scale of the field's final
    /// residual (a step that starts at rest has no continuity terms before it moves).
    pub field_scales: Vec<f64>,
    /// Whether the forces are those of the step's start (an explicit step: σ_n on x_n), so that
    /// ∫σ dV must be taken before the particle update; otherwise at the converged state.
    pub at_start: bool,
}

impl<const D: usize> Default for StepForces<D> {
    fn default() -> Self {
        StepForces {
            moment: [[0.0; D]; D],
            scale: 0.0,
            origin: [0.0; D],
            reactions: Vec::new(),
            work: 0.0,
            field_scales: Vec::new(),
            at_start: false,
        }
    }
}

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

/// The DMDA grid, the solver and the per-step state of the global system, on a grid of dimension
/// D whose points have at most M stencil nodes of at most N dofs (two-dimensional by default;
/// [`SolidSystem`] in three dimensions).
pub struct GridSystem<
    const D: usize = 2,
    const M: usize = { kernels::MAX_NODES },
    const N: usize = { kernels::MAX_DOF },
> {
    comm: Comm,
    dm: DmDa<D>,
    layout: Layout,
    ghost: GhostedRange<D>,
    owned_start: [usize; D],
    owned_count: [usize; D],
    /// Ghosted indices of the owned nodes, x fastest.
    owned_nodes: Vec<u32>,
    /// Which rank owns which cells (the DMDA's ownership ranges).
    owners: crate::distribution::Owners<D>,
    /// Global index of every ghosted dof.
    l2g: Vec<i32>,
    x: Vector,
    x_local: Vector,
    f_local: Vector,
    work_local: Vector,
    work_global: Vector,
    snes: Snes,
    jac: Option<Mat>,
    /// The rigid-body modes of the grid, attached to every Jacobian of a system whose unknowns are
    /// all displacements (see [`splits::displacement_near_null_space`]); empty otherwise.
    near_null: Vec<Vector>,
    /// The mean filled fraction of each moving boundary's nodes at the current step's start.
    boundary_fill: Vec<Option<f64>>,
    /// porompm's Schur preconditioner, when the options ask for one (see [`splits`]).
    schur: Option<petsc::SchurUser>,
    /// Its tuning from the options (the u–p–U system's aggregates and fixed-stress share).
    schur_tuning: splits::SchurTuning,
    /// The reactions per ghosted dof of the last converged step (for the work of the next).
    last_reactions: Vec<f64>,
    /// K_mag and F^int_mag ([001] Eqs. 25–26) per owned node of the last step whose forces were
    /// asked for them (see [`GridSystem::step_forces`]).
    node_diagnostics: Vec<[f64; 2]>,
    /// The nodal values of the last step of a system this one replaced, over the whole grid (see
    /// [`GridSystem::carry_node_values`]).
    carried: Vec<f64>,
    /// The absolute residual tolerance given in the options (`-snes_atol`), a floor for the
    /// per-step one.
    user_atol: f64,
    /// Whether a step whose full Newton steps failed is solved once more with a line search
    /// ([`LINE_SEARCH_RETRY`]; off with `-porompm_snes_line_search_retry false`).
    retry_with_line_search: bool,
    /// The one-field DMDA and CG solver of the pressure's L² projection (built on first use).
    l2_projection: Option<(DmDa<D>, Ksp)>,
    /// Steps that reused the previous matrix structure (and hence its symbolic factorisation).
    pub reused_patterns: usize,
    /// The owned part of the last accepted step's Δd and its Δt, the predictor of the next step
    /// when the analysis extrapolates (see [`kernels::Integration::extrapolates`]).
    last_increment: Option<(Vec<f64>, f64)>,
    step: StepData<D, M>,
    stages: Stages,
}

/// The global system of a three-dimensional grid.
pub type SolidSystem = GridSystem<3, { kernels::MAX_NODES_3D }, { kernels::MAX_DOF_3D }>;

/// The absolute residual tolerance of a step relative to the norm of its force magnitudes: the
/// round-off of a residual summed from forces of that size is about 1e-16 of it per dof, so 1e-10
/// stops a step that starts in equilibrium (a body come to rest) well above the round-off, while
/// still resolving the equilibrium to a ten-billionth of the forces involved.
pub const FORCE_ATOL: f64 = 1e-10;

/// Ghost width in nodes: a GIMP particle of a cell reaches at most one cell beyond it, and with B̄
/// a barely filled cell takes its volumetric strain from a neighbour (`stencils::CellRoots`), so a
/// particle's stencil reaches at most two cells beyond its own: node e + 3 for a particle in cell
/// e. Three rows of ghost nodes cover every node a rank's particles touch, and the nodes its
/// barely filled nodes are extended from (they lie towards the particle). (Two were once used: the
/// footing near a slope on three ranks reached past them at a B̄ root.)
pub const STENCIL_WIDTH: usize = 3;

/// Nitsche's penalty γ of the drained faces (γ/h with h the smaller grid spacing; see
/// [`kernels::flow::drained_face`]). Measured on the quasi-static large-strain column (Δt = 1e-3 s,
/// no patch recovery), settlement error at 10 / 20 / 40 cells: γ = 0.25 lets the top pressures
/// drift until the run fails at 20 and 40 cells (γ = 0 at 40 cells likewise); γ = 1: 1.61 / 1.02 /
/// 0.72 %; γ = 4: 0.83 / 0.57 / 0.46 %; γ = 16: 0.43 / 0.31 / 0.21 %, but the pressure-oscillation
/// index at 10 cells rises from 0.11 (γ ≤ 4) to 0.16 (0.19 at γ = 64): γ = 4 gains the accuracy
/// without the wiggles.
pub const NITSCHE_PENALTY: f64 = 4.0;

impl<const D: usize, const M: usize, const N: usize> GridSystem<D, M, N> {
    /// Creates the DMDA for the grid and dof layout on the run's communicator, and the SNES with
    /// porompm's defaults, then lets the PETSc options database override them. Defaults: Newton with
    /// full steps, relative residual tolerance 1e-6 as in [003] Algorithm 1; sparse LU by UMFPACK on
    /// one rank (the fastest of the measured strategies on the verification cases, see
    /// docs/solvers.md) up to [`UMFPACK_MAX_GRID_DOFS`], and by MUMPS beyond and on several ranks
    /// (UMFPACK is sequential).
    ///
    /// `partition` distributes the nodes over the ranks (None: PETSc's even split); see
    /// [`crate::distribution::balanced`]. The Newton iterations allowed per step are
    /// [`newton_iterations`] of the case's `stiffness`.
    pub fn new(
        coll: &Collective,
        grid: &crate::model::grid::Grid<D>,
        layout: Layout,
        partition: Option<&crate::distribution::Owners<D>>,
        stiffness: crate::case::Stiffness,
    ) -> Result<GridSystem<D, M, N>, Error> {
        if layout.dim != D {
            return Err(Error::new(format!(
                "a grid system of dimension {D} was given a layout of dimension {} (`Layout::in_dim`)",
                layout.dim
            )));
        }
        let comm = Comm::from_raw(coll.communicator().as_raw());
        let names = layout.field_names();
        let counts = partition.map(|o| o.counts_in());
        let ranges = counts.as_ref().map(|c| std::array::from_fn(|d| &c[d][..]));
        let dm = DmDa::new_partitioned(comm, grid.nodes(), STENCIL_WIDTH, names, ranges).map_err(|e| {
            if e.message.contains("smaller than stencil width") {
                Error {
                    message: format!(
                        "the grid of {} nodes cannot be split over {} ranks: each rank needs at least \
                         {STENCIL_WIDTH} node layers along every direction the grid is split in (the \
                         ghost width a GIMP point's support needs); run on fewer ranks or refine the grid \
                         (PETSc: {})",
                        grid.nodes().map(|n| n.to_string()).join(" × "),
                        coll.size(),
                        e.message
                    ),
                    ..e
                }
            } else {
                e
            }
        })?;
        let info = *dm.info();
        let x = dm.create_global_vector()?;
        let x_local = dm.create_local_vector()?;
        let f_local = dm.create_local_vector()?;
        let work_local = dm.create_local_vector()?;
        let work_global = dm.create_global_vector()?;
        let l2g: Vec<i32> = dm.local_to_global().to_vec();
        if l2g.len() != info.ghosted.len() * layout.nd {
            return Err(Error::new(format!(
                "the DMDA's local-to-global map has {} entries for {} ghosted dofs",
                l2g.len(),
                info.ghosted.len() * layout.nd
            )));
        }
        let ranges = dm.ownership()?;
        let owners = crate::distribution::Owners::from_counts(std::array::from_fn(|d| &ranges[d][..]));
        // The owned block, x fastest, as global node indices.
        let owned_block = GhostedRange { start: info.owned_start, count: info.owned_count, dof: 1 };
        let owned: Vec<[usize; D]> = (0..owned_block.len()).map(|o| owned_block.indices(o)).collect();
        let owned_nodes: Vec<u32> =
            owned.iter().map(|&n| info.ghosted.local(n).expect("owned nodes are ghosted") as u32).collect();
        let mut snes = Snes::new(comm)?;
        snes.set_dm(&dm)?;
        snes.set_type("newtonls")?;
        snes.set_line_search("basic")?;
        snes.set_tolerances(Some(1e-50), Some(1e-6), Some(1e-12), Some(newton_iterations(stiffness)))?;
        {
            let mut ksp = snes.ksp()?;
            ksp.set_type("preonly")?;
            let mut pc = ksp.pc()?;
            pc.set_type("lu")?;
            let grid_dofs = grid.node_count() * layout.nd;
            pc.set_factor_solver_type(default_factor_package(comm, grid_dofs))?;
        }
        snes.set_from_options()?;
        let positions: Vec<[f64; D]> = owned.iter().map(|&n| grid.position(n)).collect();
        let first_dof = x.ownership_range()?.0;
        let schur = splits::define(&mut snes, comm, coll, layout, first_dof, &positions)?;
        let schur_tuning = splits::SchurTuning::from_options()?;
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
        Ok(GridSystem {
            comm,
            dm,
            layout,
            ghost: info.ghosted,
            owned_start: info.owned_start,
            owned_count: info.owned_count,
            owned_nodes,
            owners,
            l2g,
            x,
            x_local,
            f_local,
            work_local,
            work_global,
            snes,
            jac: None,
            schur,
            schur_tuning,
            near_null,
            boundary_fill: Vec::new(),
            user_atol,
            retry_with_line_search,
            last_reactions: Vec::new(),
            node_diagnostics: Vec::new(),
            carried: Vec::new(),
            reused_patterns: 0,
            last_increment: None,
            l2_projection: None,
            step: StepData::default(),
            stages,
        })
    }

    /// Which rank owns which cells (the DMDA's ownership ranges).
    pub fn owners(&self) -> &crate::distribution::Owners<D> {
        &self.owners
    }

    /// Whether this rank owns the node with indices `n`, and with it the cell whose lowest corner
    /// it is.
    pub fn owns_cell_in(&self, n: [usize; D]) -> bool {
        (0..D).all(|d| n[d] >= self.owned_start[d] && n[d] < self.owned_start[d] + self.owned_count[d])
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

    /// Unknowns of the last prepared step (free dofs over all ranks).
    pub fn free_dofs(&self) -> usize {
        self.step.dofs.free_dofs
    }

    /// Total dofs of the grid (all nodes × dofs per node).
    pub fn total_dofs(&self) -> usize {
        self.dm.info().nodes.iter().product::<usize>() * self.layout.nd
    }

    /// The dof layout.
    pub fn layout(&self) -> Layout {
        self.layout
    }

    /// Sums a ghosted per-dof array over ranks: afterwards every ghost holds the global total.
    fn sum_over_ranks(&mut self, data: &mut [f64]) -> Result<(), Error> {
        self.work_local.write()?.copy_from_slice(data);
        self.work_global.set_all(0.0)?;
        self.dm.local_to_global_add(&self.work_local, &mut self.work_global)?;
        self.dm.global_to_local(&self.work_global, &mut self.work_local)?;
        data.copy_from_slice(&self.work_local.read()?);
        Ok(())
    }

    /// The motion components of the layout (u, and U if there is water).
    fn motion(&self) -> Vec<usize> {
        let mut m: Vec<usize> = (0..D).collect();
        if let Some(w) = self.layout.w {
            m.extend(w..w + D);
        }
        m
    }

    /// Prepares the step t_n → t_{n+1} = `t_new` of length `dt` with the stage's `active` loads and
    /// boundaries (see the module documentation), in the named steps every analysis type shares.
    /// Collective; every rank returns the same outcome.
    pub fn prepare_step(
        &mut self,
        model: &Model<D>,
        active: &Active,
        t_new: f64,
        dt: f64,
        coll: &Collective,
        body_names: &[String],
    ) -> Result<(), String> {
        // The last step's maps go first, so that the new ones do not sit beside them.
        let old_pattern = std::mem::take(&mut self.step).pattern;
        self.carried = Vec::new();
        let (mut st, crossings) = self.stencils_on_xn(model, coll)?;
        let nodal = self.project(model, &st).map_err(|e| e.to_string())?;
        let weak = self.drains_weakly(model, dt);
        let dofs = self.dof_map(model, active, (t_new - dt, t_new), &nodal, weak, coll)?;
        coll.agree(stencils::check_edges(model, &st, &crossings, &dofs, &self.ghost, t_new - dt, body_names))?;
        self.boundary_fill = self.moving_boundary_fill(model, &dofs, &nodal.phi, coll)?;
        if model.stress_recovery == crate::case::StressRecovery::Cmpm {
            // [001]'s CMPM (plane only: validation keeps it out of three-dimensional cases).
            if let (Some(plane), Some(st), Some(ghost)) =
                (model.as_plane(), crate::model::plane_mut::<_, Stencils>(&mut st), crate::model::plane(&self.ghost))
            {
                coll.agree(stencils::cmpm_patches(st, plane, ghost, &dofs))?;
            }
        }
        if model.internal_force == crate::case::InternalForce::Mapped {
            // [001]'s double-mapped internal force (plane, one-phase: validation), before any term
            // of the step is evaluated.
            if let (Some(plane), Some(st), Some(ghost)) =
                (model.as_plane(), crate::model::plane_mut::<_, Stencils>(&mut st), crate::model::plane(&self.ghost))
            {
                coll.agree(stiffness::mapped_forces(plane, ghost, st))?;
                if model.stress_recovery == crate::case::StressRecovery::Mapped {
                    // The strain's operators are the forces' (validation: no CMPM patches here).
                    st.strain = st.forces.clone();
                }
            }
        }
        stencils::extend(&mut st, model, &self.ghost, &dofs, &self.motion());
        self.step_data(model, active, (t_new - dt, t_new), st, dofs, &nodal, coll)?;
        self.step.fixed_stress = self.fixed_stress_diagonal(model, dt).map_err(|e| e.to_string())?;
        if self.schur.as_ref().is_some_and(|s| s.has_blocks()) {
            let (nodes, p) = (std::array::from_fn(|d| model.grid.cells[d] + 1), self.layout.p.expect("a Schur split"));
            self.step.schur_groups = aggregates::surface_groups(
                &self.ghost,
                nodes,
                &self.owned_nodes,
                &self.step.dofs,
                p,
                self.schur_tuning.strip,
            );
        }
        if weak {
            (self.step.face_owner, self.step.faces) = self.drained_faces(model, active).into_iter().unzip();
        }
        if let Some((plane, system)) = model.as_plane().zip(self.as_plane_mut()) {
            system.plane_step(plane, coll)?;
        }
        if let kernels::Integration::Explicit { pointwise_pressure: false, .. } = model.integration {
            if self.layout.w.is_some() {
                self.step.drained = self.drained_nodes(model, active).map_err(|e| e.to_string())?;
            }
        }
        if model.integration.is_explicit() {
            // An explicit step solves nothing: no matrix.
            self.step.pattern = old_pattern;
            return Ok(());
        }
        self.matrix_pattern(old_pattern, coll)
    }

    /// The system itself when it is two-dimensional (see [`Model::as_plane`]).
    fn as_plane_mut(&mut self) -> Option<&mut GridSystem> {
        crate::model::plane_mut(self)
    }

    /// [`Self::as_plane_mut`], shared.
    fn as_plane_ref(&self) -> Option<&GridSystem> {
        crate::model::plane(self)
    }

    /// Which ghosted nodes are drained in a two-phase explicit step with the nodal pore pressure
    /// (see [`explicit`]), in any dimension: a side or region boundary of the stage fixes `p`
    /// there, a moving surface that fixes `p` reaches it (marks summed over the ranks, a
    /// collective every rank takes when a moving surface is active), or the material barely fills
    /// it (the drained value of implicit stages' barely filled nodes).
    fn drained_nodes(&mut self, model: &Model<D>, active: &Active) -> Result<Vec<bool>, Error> {
        let nd = self.layout.nd;
        let p = crate::model::dof_index_in::<D>(crate::case::Dof::P).expect("p has a place in every dimension");
        let mut marks = Vec::new();
        // Whether a boundary is a moving surface is the case's: every rank takes the same branch.
        if active.boundaries.iter().any(|&b| model.boundaries[b].surface.is_some()) {
            marks = vec![0.0; self.ghost.len() * nd];
            for l in self.surface_drained_nodes(model, active) {
                marks[l * nd] = 1.0;
            }
            self.sum_over_ranks(&mut marks)?;
        }
        Ok((0..self.ghost.len())
            .map(|l| {
                marks.get(l * nd).is_some_and(|&m| m > 0.0)
                    || !self.step.dofs.well[l]
                    || model.fixing_boundaries(active, self.ghost.indices(l))[p].is_some()
            })
            .collect())
    }

    /// Step 4: the diagonal d of porompm's Schur preconditioners (see [`splits`]), per owned
    /// pressure row in the `p` split's order, in PETSc's scaling (s the pressure scale); 0 on fixed
    /// pressures, whose rows stay the unit diagonal. Empty without such a preconditioner.
    ///
    /// * u–p: Sp = A_pp + diag(d), d_i = −s² Σ_k N_i(x_k) V_k / K_dr,k, the lumped pressure mass of
    ///   the points over their skeleton's drained bulk modulus (λ + μ in plane strain, λ + 2μ/3 in
    ///   three dimensions). It is the volume change of the fixed-stress split, β = α²/K_dr with
    ///   Biot's α = 1 (incompressible grains, as the continuity equation assumes), with the sign of
    ///   A_pp's storage term.
    /// * u–p–U: Sp = A_pp − A_pu B⁻¹ A_up + diag(d), d_i = −c s² Σ_k (1 − n_k)² N_i(x_k) V_k /
    ///   K_dr,k: the share c ([`fixed_stress_share`]) of the solid's part of that term.
    ///   B⁻¹'s diagonal captures the inertia, which dominates the long waves; the skeleton's
    ///   compressibility dominates the waves shorter than the distance a compression wave crosses
    ///   in a step, a share that grows with the step's Courant number.
    fn fixed_stress_diagonal(&mut self, model: &Model<D>, dt: f64) -> Result<Vec<f64>, Error> {
        let (Some(p), true) = (self.layout.p, self.schur.is_some()) else { return Ok(Vec::new()) };
        let dynamic = self.layout.w.is_some();
        let share =
            if dynamic { self.schur_tuning.share.unwrap_or_else(|| fixed_stress_share(model, dt)) } else { 1.0 };
        let nd = self.layout.nd;
        let mut mass = vec![0.0; self.ghost.len() * nd];
        let (st, ps) = (&self.step.stencils, &model.particles);
        for k in 0..st.len() {
            let elastic = model.materials[ps.material[k] as usize].model.elastic();
            let drained = if D == 3 { elastic.bulk_modulus() } else { elastic.plane_bulk_modulus() };
            let solid = if dynamic { (1.0 - ps.porosity[k]).powi(2) } else { 1.0 };
            let (nodes, basis) = st.get(k);
            for (&node, nb) in nodes.iter().zip(basis) {
                mass[node as usize * nd + p] += nb.s * ps.volume[k] * solid / drained;
            }
        }
        self.sum_over_ranks(&mut mass)?;
        let s2 = self.step.p_scale * self.step.p_scale;
        let fixed = &self.step.dofs.fixed;
        Ok(self
            .owned_nodes
            .iter()
            .map(|&a| a as usize * nd + p)
            .map(|q| if fixed[q] { 0.0 } else { -share * s2 * mass[q] })
            .collect())
    }

    /// Step 1: the stencils on x_n (B̄'s cells first: which cells the material fills, summed over
    /// ranks), and the particles whose support crosses a side of the grid.
    fn stencils_on_xn(&mut self, model: &Model<D>, coll: &Collective) -> Result<(Stencils<D>, Vec<Crossing>), String> {
        let nd = self.layout.nd;
        let roots = if model.bbar {
            let mut phi = vec![0.0; self.ghost.len() * nd];
            for (l, f) in stencils::cell_fractions(model, &self.ghost).into_iter().enumerate() {
                phi[l * nd] = f;
            }
            self.sum_over_ranks(&mut phi).map_err(|e| e.to_string())?;
            let per_cell: Vec<f64> = (0..self.ghost.len()).map(|l| phi[l * nd]).collect();
            stencils::CellRoots::new(&self.ghost, model.grid.cells, &per_cell)
        } else {
            stencils::CellRoots::identity()
        };
        coll.agree(stencils::build_in::<D, M>(model, &self.ghost, &roots))
    }

    /// Whether a step of `dt` imposes the drained moving surfaces weakly, on the particles' faces
    /// ([`kernels::flow::drained_face`]): the u–p system with Darcy flow, whose drainage is an
    /// essential condition. The u–p–U system drains through its water's motion (p = 0 is natural
    /// there) and keeps the pressure fixed at the nodes beyond the surface, as a system without
    /// flow does.
    fn drains_weakly(&self, model: &Model<D>, dt: f64) -> bool {
        let flow = self.layout.p.is_some() && self.layout.w.is_none();
        flow && kernels::Scheme::of(&model.integration, dt, flow).flow_dt > 0.0
    }

    /// Step 3: the dof map of the step `(t_n, t_{n+1})`. Moving surfaces: per surface boundary, the
    /// dofs any rank's particles fix, summed over ranks; a dof takes the first such boundary in
    /// case order. With `weak_drainage` the surfaces fix no pressure (see [`Self::drains_weakly`]).
    fn dof_map(
        &mut self,
        model: &Model<D>,
        active: &Active,
        times: (f64, f64),
        nodal: &Nodal,
        weak_drainage: bool,
        coll: &Collective,
    ) -> Result<DofMap, String> {
        let nd = self.layout.nd;
        let fixes = model.surface_fixes(active, weak_drainage);
        let mut surface = vec![0.0; self.ghost.len() * nd];
        for &bi in active.boundaries.iter().filter(|&&b| model.boundaries[b].surface.is_some()) {
            let mut marks = vec![0.0; self.ghost.len() * nd];
            for (n, _, comps) in fixes.iter().filter(|f| f.1 == bi) {
                if let Some(l) = self.ghost.local(n.map(|v| v as usize)) {
                    for c in (0..nd).filter(|&c| self.layout.canonical(c).is_some_and(|k| comps[k])) {
                        marks[l * nd + c] = 1.0;
                    }
                }
            }
            self.sum_over_ranks(&mut marks).map_err(|e| e.to_string())?;
            for (s, m) in surface.iter_mut().zip(&marks) {
                if *s == 0.0 && *m > 0.0 {
                    *s = (bi + 1) as f64;
                }
            }
        }
        let mut dofs = dofs::build(
            model,
            active,
            times,
            &self.ghost,
            self.owned_start,
            self.owned_count,
            nd,
            &nodal.phi,
            &surface,
            WELL_FILLED_FRACTION,
            self.layout,
        );
        dofs.free_dofs = coll.sum_count(dofs.free_dofs as u64) as usize;
        Ok(dofs)
    }

    /// The mean filled fraction φ of the nodes of each boundary that prescribes a motion (None for
    /// the others, and for a boundary without nodes): how much material the nodes that carry the
    /// motion reach at the step's start (collective). A boundary on grid nodes stays where the grid
    /// is, while the material it pushes moves on: once the material has moved by about half a cell,
    /// the nodes reach only the points at the edge of their support, and the motion no longer acts
    /// on the material as the boundary means it to (the driver warns, see
    /// `Simulation::check_boundary_grip`).
    fn moving_boundary_fill(
        &self,
        model: &Model<D>,
        dofs: &DofMap,
        phi: &[f64],
        coll: &Collective,
    ) -> Result<Vec<Option<f64>>, String> {
        let nb = model.boundaries.len();
        let moving: Vec<bool> = model
            .boundaries
            .iter()
            .map(|b| b.motion.as_ref().is_some_and(|m| m.gradient.is_some() || m.vector.iter().any(|&v| v != 0.0)))
            .collect();
        if !moving.contains(&true) {
            // No boundary moves (every rank has the same boundaries): nothing to reduce.
            return Ok(vec![None; nb]);
        }
        let nd = self.layout.nd;
        let mut local = vec![0.0; 2 * nb];
        for &a in &self.owned_nodes {
            let l = a as usize;
            for c in 0..nd {
                let b = dofs.boundary[l * nd + c] as usize;
                // Each boundary once per node: at its first fixed component.
                let first = (0..c).all(|e| dofs.boundary[l * nd + e] as usize != b);
                if b < nb && moving[b] && first {
                    local[2 * b] += phi[l];
                    local[2 * b + 1] += 1.0;
                }
            }
        }
        let s = coll.sum(&local)?;
        Ok((0..nb).map(|b| (moving[b] && s[2 * b + 1] > 0.0).then(|| s[2 * b] / s[2 * b + 1])).collect())
    }

    /// The mean filled fraction of the nodes of each boundary that prescribes a motion, at the
    /// start of the current step (see [`GridSystem::moving_boundary_fill`]).
    pub fn boundary_fill(&self) -> &[Option<f64>] {
        &self.boundary_fill
    }

    /// Step 4: the data the callbacks use (`self.step`), from the effective stencils `st` and the dof map: the
    /// threads' bands, the predictors, porosity gradients, pressure-projection blocks, external
    /// loads (checked against what the nodes carry), the generalized-α history and the force
    /// scale of the Newton floor.
    #[allow(clippy::too_many_arguments)]
    fn step_data(
        &mut self,
        model: &Model<D>,
        active: &Active,
        (t_old, t_new): (f64, f64),
        st: Stencils<D>,
        dofs: DofMap,
        nodal: &Nodal,
        coll: &Collective,
    ) -> Result<(), String> {
        let bands = callbacks::bands(&st, self.ghost.count, coll.threads());
        let (smooth, grad_n) = self.predictors(model, &st, &dofs, nodal);
        let projection = self.projection_cells(model);
        let (fext, applied) = coll.agree(self.external_forces(model, active, t_new, &dofs))?;
        let flow = self.layout.p.is_some() && self.layout.w.is_none();
        let nm = kernels::Scheme::of(&model.integration, t_new - t_old, flow);
        let fext_old = coll.agree(self.external_forces(model, active, t_old, &dofs))?.0;
        self.step = StepData {
            nm: Some(nm),
            dt: t_new - t_old,
            layout: Some(self.layout),
            body_acc: model.body_accelerations(active, t_new),
            stencils: st,
            bands,
            dofs,
            fext,
            solution: Vec::new(),
            grad_n,
            smooth,
            projection,
            p_scale: pressure_scale(model),
            ..StepData::default()
        };
        self.check_loads(&applied, t_new, coll)?;
        if model.linear_increments {
            // A geometrically linear step solves for the increments alone ([001]'s K Δu = ΔF):
            // the residual of the step's start on x_n is taken off (validation keeps these stages
            // static or quasi-static, which have no generalized-α history).
            let body_acc_old = model.body_accelerations(active, t_old);
            self.step.history = self.with_assembler(model, |asm| asm.start_out_of_balance(&body_acc_old, &fext_old));
        } else if nm.history().is_some() {
            let body_acc_old = model.body_accelerations(active, t_old);
            self.step.history = self.with_assembler(model, |asm| asm.history(&body_acc_old, &fext_old));
        }
        self.step.fext_old = fext_old;
        self.step.force_scale = if model.integration.is_explicit() {
            // An explicit step's forces are those of its start: one pass gives them and their
            // magnitudes (the scale of each field's equation).
            let ng = self.step.fext.len();
            let mut terms = StartTerms { all: vec![0.0; ng], inertia: vec![0.0; ng], magnitude: vec![0.0; ng] };
            let xl = vec![0.0; ng];
            self.with_assembler(model, |asm| {
                asm.nodal_terms(&xl, &mut terms.all, &mut terms.inertia, &mut terms.magnitude)
            });
            let mut mags = terms.magnitude.clone();
            self.step.start_terms = Some(terms);
            self.force_scale_of(&mut mags, coll)?
        } else {
            let mut mags = self.with_assembler(model, |asm| asm.force_magnitudes());
            self.force_scale_of(&mut mags, coll)?
        };
        Ok(())
    }

    /// Step 5: the matrix pattern, kept (`old`) if every rank finds every pair in it, and where the
    /// pressure-projection cells and the fixed dofs' diagonals lie in it.
    fn matrix_pattern(&mut self, old: Pattern<D>, coll: &Collective) -> Result<(), String> {
        let nd = self.layout.nd;
        let kept = !old.is_empty() && old.covers(&self.step.stencils);
        let pattern = if coll.any(!kept)? {
            let groups: Vec<Vec<u32>> = self.step.projection.iter().map(|c| c.nodes.clone()).collect();
            let p = Pattern::build_in(&self.step.stencils, &self.owned_nodes, &groups, self.ghost.count);
            let (rows, cols) = p.coo(nd, &self.l2g);
            let made = self.dm.create_matrix_coo(&rows, &cols).and_then(|mut jac| {
                if !self.near_null.is_empty() {
                    jac.set_near_null_space(self.comm, &self.near_null)?;
                }
                Ok(jac)
            });
            self.jac = Some(coll.agree(made.map_err(|e| e.to_string()))?);
            if let Some(schur) = &mut self.schur {
                schur.forget();
            }
            p
        } else {
            self.reused_patterns += 1;
            old
        };
        let projection_blocks: Option<Vec<Vec<u32>>> = self
            .step
            .projection
            .iter()
            .map(|cell| {
                let pattern = &pattern;
                cell.nodes.iter().flat_map(|&na| cell.nodes.iter().map(move |&nc| pattern.block(na, nc))).collect()
            })
            .collect();
        self.step.projection_blocks =
            projection_blocks.ok_or("a pressure-projection cell's nodes are not coupled by any particle")?;
        self.step.fixed_diagonals = self
            .step
            .dofs
            .owned_fixed
            .iter()
            .map(|&(_, q)| {
                (pattern.block((q / nd) as u32, (q / nd) as u32).expect("owned diagonal blocks are listed"), q % nd)
            })
            .collect();
        self.step.pattern = pattern;
        Ok(())
    }

    /// Step 2: nodal masses, momenta and mass-weighted accelerations ([003] Eq. 19), mass-weighted
    /// porosities and filled fractions, summed over ranks.
    fn project(&mut self, model: &Model<D>, st: &Stencils<D>) -> Result<Nodal, Error> {
        let nd = self.layout.nd;
        let ng = self.ghost.len() * nd;
        let ps = &model.particles;
        // A cell's area (its volume in three dimensions).
        let cell_area: f64 = model.grid.h.iter().product();
        let (mut mass, mut mom, mut acc) = (vec![0.0; ng], vec![0.0; ng], vec![0.0; ng]);
        let (mut phi, mut porosity) = (vec![0.0; ng], vec![0.0; ng]);
        for k in 0..st.len() {
            let (nodes, basis) = st.get(k);
            let mw = model.water_mass(k);
            for (&node, nb) in nodes.iter().zip(basis) {
                let b = node as usize * nd;
                let s = nb.s;
                phi[b] += s * model.area(k) / cell_area;
                porosity[b] += s * ps.mass[k] * ps.porosity[k];
                for c in 0..D {
                    mass[b + c] += s * ps.mass[k];
                    mom[b + c] += s * ps.mass[k] * ps.vel[k][c];
                    acc[b + c] += s * ps.mass[k] * ps.acc[k][c];
                    if let Some(w) = self.layout.w {
                        mass[b + w + c] += s * mw;
                        mom[b + w + c] += s * mw * ps.vel_w[k][c];
                        acc[b + w + c] += s * mw * ps.acc_w[k][c];
                    }
                }
            }
        }
        for v in [&mut mass, &mut mom, &mut acc, &mut phi, &mut porosity] {
            self.sum_over_ranks(v)?;
        }
        let n = self.ghost.len();
        Ok(Nodal {
            phi: (0..n).map(|l| phi[l * nd]).collect(),
            porosity: (0..n).map(|l| if mass[l * nd] > 0.0 { porosity[l * nd] / mass[l * nd] } else { 0.0 }).collect(),
            mass,
            mom,
            acc,
        })
    }

    /// Step 4: the Newmark predictors' velocities and accelerations at t_n interpolated to each
    /// particle from the nodal projections ([003] Eq. 19b–c; the predictors of [003] Eq. 21 formed
    /// on the nodes and interpolated are the predictors of these values, being linear in v and a),
    /// and the porosity gradient at each particle (two-phase). A component held still by a boundary
    /// has zero velocity and acceleration; an extended node takes its masters'.
    fn predictors(
        &self,
        model: &Model<D>,
        st: &Stencils<D>,
        dofs: &DofMap,
        nodal: &Nodal,
    ) -> (Vec<[[f64; D]; 4]>, Vec<[f64; D]>) {
        let value = |l: usize, c: usize, of: &[f64]| start_value(model, dofs, l * dofs.nd + c, &nodal.mass, of);
        // (dof, slot of its velocity in the output, component): the solid's, then the water's.
        let mut comps: Vec<(usize, usize, usize)> = (0..D).map(|c| (c, 0, c)).collect();
        if let Some(w) = self.layout.w {
            comps.extend((0..D).map(|c| (w + c, 2, c)));
        }
        let two_phase = self.layout.w.is_some();
        let mut smooth = Vec::with_capacity(st.len());
        let mut grad_n = Vec::with_capacity(if two_phase { st.len() } else { 0 });
        for k in 0..st.len() {
            let (nodes, basis) = st.get(k);
            let eff = st.effective(k);
            let ext = st.extensions(k);
            let mut out = [[0.0; D]; 4];
            let mut g = [0.0; D];
            for (slot, (&node, nb)) in nodes.iter().zip(basis).enumerate() {
                let e = ext.iter().find(|e| e.slot as usize == slot);
                let of_masters = |f: &dyn Fn(usize) -> f64| -> f64 {
                    let e = e.expect("extended");
                    (0..e.n as usize).map(|m| e.masters[m].1 * f(eff[e.masters[m].0 as usize] as usize)).sum()
                };
                for &(c, s, comp) in &comps {
                    let extended = e.is_some_and(|e| e.mask & (1 << c) != 0);
                    let (v, a) = if extended {
                        (of_masters(&|l| value(l, c, &nodal.mom)), of_masters(&|l| value(l, c, &nodal.acc)))
                    } else {
                        (value(node as usize, c, &nodal.mom), value(node as usize, c, &nodal.acc))
                    };
                    out[s][comp] += nb.s * v;
                    out[s + 1][comp] += nb.s * a;
                }
                if two_phase {
                    let n =
                        if e.is_some() { of_masters(&|l| nodal.porosity[l]) } else { nodal.porosity[node as usize] };
                    for (gd, nbd) in g.iter_mut().zip(nb.g) {
                        *gd += nbd * n;
                    }
                }
            }
            smooth.push(out);
            if two_phase {
                grad_n.push(g);
            }
        }
        (smooth, grad_n)
    }

    /// Pore-pressure increments that make each particle's pressure the interpolation of the total
    /// nodal field, p_{n+1} = Σ S_i (P_i + Δp_i) (`stabilisation.pressure_update =
    /// "projected_total"`). P is the consistent L² projection of the particles' pressures p_n onto
    /// the nodal functions: M P = b with M_ij = Σ_p V_p S_ip S_jp and b_i = Σ_p V_p S_ip p_p, solved
    /// by CG with Jacobi (options prefix `pressure_projection_`, relative tolerance 1e-12). A
    /// pressure field the nodes represent comes back unchanged (no smoothing, unlike a lumped
    /// projection), and what they cannot represent is dropped instead of accumulating on the
    /// particles. Nodes no particle reaches get P = 0 (a regularisation of 1e-12 of a cell's area
    /// on every diagonal). Collective; in any dimension.
    pub fn projected_pressure_increments(&mut self, model: &Model<D>) -> Result<Vec<f64>, Error> {
        let nd = self.layout.nd;
        let pc = self.layout.p.expect("a pressure");
        if self.l2_projection.is_none() {
            // The same distribution of the nodes as the system's DMDA.
            let counts = self.owners.counts_in();
            let ranges: [&[usize]; D] = std::array::from_fn(|d| &counts[d][..]);
            let dm = DmDa::new_partitioned(self.comm, self.dm.info().nodes, STENCIL_WIDTH, &["p"], Some(ranges))?;
            let mut ksp = Ksp::new(self.comm)?;
            ksp.set_prefix("pressure_projection_")?;
            ksp.set_type("cg")?;
            ksp.pc()?.set_type("jacobi")?;
            ksp.set_tolerances(Some(1e-12), Some(0.0), Some(10_000))?;
            ksp.set_from_options()?;
            self.l2_projection = Some((dm, ksp));
        }
        let (dm1, ksp) = self.l2_projection.as_mut().expect("built above");
        let pattern = &self.step.pattern;
        let (rows, cols) = pattern.coo(1, dm1.local_to_global());
        let mut mat = dm1.create_matrix_coo(&rows, &cols)?;
        let mut values = vec![0.0; pattern.len()];
        let ng = self.ghost.len();
        let mut b = vec![0.0; ng];
        let ps = &model.particles;
        let st = &self.step.stencils;
        for k in 0..st.len() {
            let (nodes, basis) = st.get(k);
            for (&a, ba) in nodes.iter().zip(basis).filter(|(_, nb)| nb.s != 0.0) {
                let w = ps.volume[k] * ba.s;
                b[a as usize] += w * ps.p[k];
                let ia = pattern.indices(a);
                for (&c, bc) in nodes.iter().zip(basis).filter(|(_, nb)| nb.s != 0.0) {
                    values[pattern.block_of(a, ia, c, pattern.indices(c)) as usize] += w * bc.s;
                }
            }
        }
        let eps = model.grid.h.iter().fold(1e-12, |e, h| e * h);
        for &a in &self.owned_nodes {
            values[pattern.block(a, a).expect("owned diagonal blocks are listed") as usize] += eps;
        }
        mat.set_values_coo(&values, false)?;
        let mut b_local = dm1.create_local_vector()?;
        b_local.write()?.copy_from_slice(&b);
        let mut b_global = dm1.create_global_vector()?;
        b_global.set_all(0.0)?;
        dm1.local_to_global_add(&b_local, &mut b_global)?;
        let mut p_global = dm1.create_global_vector()?;
        ksp.set_operators(&mat, &mat)?;
        let out = ksp.solve(&b_global, &mut p_global)?;
        if out.reason <= 0 {
            return Err(Error::new(format!(
                "the L² projection of the pore pressure (stabilisation.pressure_update = \"projected_total\") did not \
                 converge: {} after {} CG iterations",
                out.reason_text, out.iterations
            )));
        }
        let mut p_local = dm1.create_local_vector()?;
        dm1.global_to_local(&p_global, &mut p_local)?;
        let total: Vec<f64> = {
            let pl = p_local.read()?;
            (0..ng).map(|l| pl[l] + self.step.solution[l * nd + pc]).collect()
        };
        Ok((0..st.len())
            .map(|k| {
                let (nodes, basis) = st.get(k);
                nodes.iter().zip(basis).map(|(&n, nb)| nb.s * total[n as usize]).sum::<f64>() - ps.p[k]
            })
            .collect())
    }

    /// Pore-pressure increments of the converged step recovered at every particle by MLSA patches
    /// ([003] §3.3; see [`crate::model::patch`]); a particle without any active cell near it keeps the
    /// interpolated increment.
    pub fn recovered_pressure_increments(&self, model: &Model<D>) -> Vec<f64> {
        let nd = self.layout.nd;
        let p = self.layout.p.expect("a pressure");
        let dp: Vec<f64> = (0..self.ghost.len()).map(|l| self.step.solution[l * nd + p]).collect();
        let field = crate::model::patch::PatchField {
            grid: &model.grid,
            start: self.ghost.start,
            count: self.ghost.count,
            dp: &dp,
            active: &self.step.dofs.well,
        };
        (0..model.particles.len())
            .map(|k| field.recover(model.particles.x[k]).unwrap_or_else(|| self.step_result(model, k).interp.dp))
            .collect()
    }

    /// The ghosted nodes a moving surface that fixes `p` reaches (`Model::surface_fixes`), for the
    /// drained nodes of an explicit two-phase step ([`GridSystem::drained_nodes`]).
    fn surface_drained_nodes(&self, model: &Model<D>, active: &Active) -> Vec<usize> {
        let p = crate::model::dof_index_in::<D>(crate::case::Dof::P).expect("p has a place in every dimension");
        model
            .surface_fixes(active, false)
            .into_iter()
            .filter(|(_, _, comps)| comps[p])
            .filter_map(|(n, _, _)| self.ghost.local(n.map(|v| v as usize)))
            .collect()
    }

    /// Step 4: the drained faces of this rank's particles with their geometry and the grid's
    /// multilinear shape functions at the face point, ordered by particle (see
    /// [`kernels::DrainedFace`]). The gradient is the one on the material's side of a grid line
    /// through the face point.
    fn drained_faces(&self, model: &Model<D>, active: &Active) -> Vec<(usize, kernels::DrainedFace<D, M>)> {
        let (g, ps) = (&model.grid, &model.particles);
        let penalty = NITSCHE_PENALTY / g.h_min();
        model
            .drained_faces(active)
            .into_iter()
            .map(|(k, face)| {
                let normal = model.face_normal(k, face);
                let (xf, measure) = face_point(face, ps.x[k], ps.lp[k]);
                let area = measure * model.geometry.measure(xf[0]);
                let inside: [f64; D] = std::array::from_fn(|d| xf[d] - 1e-9 * g.h[d] * normal[d]);
                let mut basis = [(0.0, [0.0; D]); M];
                let (nodes, _) = self.step.stencils.get(k);
                for (b, &node) in basis.iter_mut().zip(nodes) {
                    let n = self.ghost.indices(node as usize);
                    *b = shape::multilinear(g.position(n), xf, inside, g.h);
                }
                let offset = std::array::from_fn(|d| xf[d] - ps.x[k][d]);
                (k, kernels::DrainedFace { offset, normal, area, penalty, basis })
            })
            .collect()
    }

    /// Step 4: the pressure-projection cells, over this rank's particles grouped by the cell
    /// holding their centre (`kernels::pressure_projection` with the cell's 2^D multilinear
    /// functions at the points, weights α/G V); none without a pressure or a projection, and none
    /// for a cell whose corners are not all ghosted.
    fn projection_cells(&self, model: &Model<D>) -> Vec<ProjectionCell> {
        let mut out = Vec::new();
        let (Some(_), Some(alpha)) = (self.layout.p, model.pressure_projection) else { return out };
        let g = &model.grid;
        let ps = &model.particles;
        let mut cells: std::collections::BTreeMap<[usize; D], Vec<usize>> = Default::default();
        for k in 0..ps.len() {
            if let Some(c) = g.cell_containing(ps.x[k]) {
                cells.entry(c).or_default().push(k);
            }
        }
        let corners = 1usize << D;
        // Corner m of a cell: its bit d says whether the corner is the upper node along d.
        let upper = |m: usize, d: usize| (m >> d) & 1 == 1;
        for (c, members) in cells {
            let Some(nodes) = (0..corners)
                .map(|m| {
                    let n: [usize; D] = std::array::from_fn(|d| c[d] + upper(m, d) as usize);
                    self.ghost.local(n).map(|l| l as u32)
                })
                .collect::<Option<Vec<u32>>>()
            else {
                continue;
            };
            let o = g.position(c);
            // The multilinear functions at each point (the unused corners of a plane cell zero).
            let n: Vec<[f64; 8]> = members
                .iter()
                .map(|&k| {
                    let x: [f64; D] = std::array::from_fn(|d| (ps.x[k][d] - o[d]) / g.h[d]);
                    std::array::from_fn(|m| {
                        if m >= corners {
                            return 0.0;
                        }
                        (0..D).fold(1.0, |acc, d| acc * if upper(m, d) { x[d] } else { 1.0 - x[d] })
                    })
                })
                .collect();
            let w: Vec<f64> = members
                .iter()
                .map(|&k| {
                    let shear = model.materials[ps.material[k] as usize].model.elastic().shear_modulus();
                    alpha / shear * ps.volume[k]
                })
                .collect();
            let s = kernels::pressure_projection(&n, &w);
            let s = (0..corners).flat_map(|a| (0..corners).map(move |b| s[a][b])).collect();
            out.push(ProjectionCell { nodes, s });
        }
        out
    }

    /// Step 4: the external forces at t_{n+1} per ghosted dof. A traction's share at a node whose
    /// motion is extended goes to the node's masters (extended towards the loaded particle); a share
    /// that no node can carry stays where it is, and [`GridSystem::check_loads`] reports it.
    /// Returns the nodal forces and, for that check, the total force the loads apply on this rank
    /// (before it is shared out to nodes). The line pressures are plane
    /// ([`GridSystem::plane_load`]).
    fn external_forces(
        &self,
        model: &Model<D>,
        active: &Active,
        t_new: f64,
        dofs: &DofMap,
    ) -> Result<(Vec<f64>, AppliedLoads<D>), String> {
        let nd = self.layout.nd;
        let ps = &model.particles;
        let g = &model.grid;
        let mut fext = vec![0.0; self.ghost.len() * nd];
        let mut applied = AppliedLoads::default();
        let tiny = 1e-9 * g.h.iter().copied().fold(f64::INFINITY, f64::min);
        let is_well = |n: [i64; D]| -> bool {
            n.iter().all(|&v| v >= 0) && self.ghost.local(n.map(|v| v as usize)).is_some_and(|l| dofs.well[l])
        };
        let mut add = |l: usize, force: [f64; D], toward: [f64; D]| {
            for c in 0..D {
                if dofs.well[l] || dofs.boundary_fixed(l, c) {
                    fext[l * nd + c] += force[c];
                    continue;
                }
                let n = self.ghost.indices(l);
                match stencils::extension_in(n, g.position(n), toward, &is_well, tiny, model.basis.is_bspline()) {
                    Some((masters, coefs, count)) => {
                        for m in 0..count {
                            let ml = self.ghost.local(masters[m].map(|v| v as usize)).expect("well");
                            fext[ml * nd + c] += coefs[m] * force[c];
                        }
                    }
                    None => fext[l * nd + c] += force[c],
                }
            }
        };
        for &li in &active.loads {
            let load = &model.loads[li];
            let f = load.factor(t_new);
            if !matches!(load.target, LoadTarget::BodyForce { .. }) {
                applied.names.push(load.name.clone());
            }
            match &load.target {
                LoadTarget::ParticleTraction { particles, face, traction } => {
                    // The traction acts at the centre of the particle's loaded face (force = traction ×
                    // current face measure) with the multilinear weights there (see
                    // shape::face_weights).
                    for &k in particles {
                        let (x, lp) = (ps.x[k], ps.lp[k]);
                        let (point, length) = face_point(*face, x, lp);
                        // The face's area: its length times the ring's 2πr in axial symmetry.
                        let length = length * model.geometry.measure(point[0]);
                        applied.add(std::array::from_fn(|d| traction[d] * f * length));
                        let w: shape::Stencil<D, M> = shape::face_weights_in(model.basis, g, point);
                        for (node, s, _) in w.iter() {
                            let l = self.ghost.local(node.map(|v| v as usize)).ok_or_else(|| {
                                format!(
                                    "the traction `{}` on material point {} acts outside this rank's ghost region",
                                    load.name, ps.id[k]
                                )
                            })?;
                            add(l, std::array::from_fn(|d| s * traction[d] * f * length), x);
                        }
                    }
                }
                LoadTarget::NodalTraction { nodes, traction } => {
                    // Each node's share on the rank owning it (the cell it is the lower corner of).
                    for &(n, measure) in nodes.iter().filter(|(n, _)| self.owns_cell_in(*n)) {
                        let l = self.ghost.local(n).expect("an owned node is ghosted");
                        let x = g.position(n);
                        let measure = measure * model.geometry.measure(x[0]);
                        let force = std::array::from_fn(|d| traction[d] * f * measure);
                        applied.add(force);
                        add(l, force, x);
                    }
                }
                LoadTarget::LinePressure { .. } => {
                    if let (Some(plane), Some(system)) = (model.as_plane(), self.as_plane_ref()) {
                        let (forces, totals) = system.plane_load(plane, li, f);
                        for total in totals {
                            applied.add(std::array::from_fn(|d| total[d]));
                        }
                        for (l, force, toward) in forces {
                            add(l, std::array::from_fn(|d| force[d]), std::array::from_fn(|d| toward[d]));
                        }
                    }
                }
                LoadTarget::BodyForce { .. } => {}
            }
        }
        Ok((fext, applied))
    }

    /// The load accounting of a step: the tractions the case applies at t_{n+1} against the forces
    /// assembled on nodes that carry them (free, or fixed by a boundary, whose reaction then takes
    /// them). A difference beyond round-off means that part of a load would be lost: an error
    /// naming the load.
    fn check_loads(&mut self, applied: &AppliedLoads<D>, t_new: f64, coll: &Collective) -> Result<(), String> {
        let nd = self.layout.nd;
        let (applied, names) = (applied.total, &applied.names);
        if names.is_empty() {
            return Ok(());
        }
        let mut summed = self.step.fext.clone();
        self.sum_over_ranks(&mut summed).map_err(|e| e.to_string())?;
        let mut carried = [0.0; D];
        let mut magnitude = 0.0f64;
        for &a in &self.owned_nodes {
            let l = a as usize;
            for (c, carried_c) in carried.iter_mut().enumerate() {
                let q = l * nd + c;
                magnitude = magnitude.max(summed[q].abs());
                if !self.step.dofs.fixed[q] || self.step.dofs.boundary_fixed(l, c) {
                    *carried_c += summed[q];
                }
            }
        }
        let totals = coll.sum(&[&applied[..], &carried[..]].concat())?;
        let scale = totals[..D].iter().fold(coll.max(&[magnitude])?[0], |m, t| m.max(t.abs()));
        let lost = (0..D).fold(0.0f64, |m, d| m.hypot(totals[d] - totals[D + d]));
        if lost > 1e-9 * scale.max(f64::MIN_POSITIVE) {
            let vector =
                |v: &[f64]| format!("({})", v.iter().map(|x| format!("{x:.6e}")).collect::<Vec<_>>().join(", "));
            let unit = if D == 2 { "N/m" } else { "N" };
            return Err(format!(
                "at t = {t_new:.6e} s the load(s) {} apply {} {unit} but the grid carries {} {unit}: part of the load \
                 acts on nodes the material does not fill",
                names.join(", "),
                vector(&totals[..D]),
                vector(&totals[D..])
            ));
        }
        Ok(())
    }

    /// Solves the prepared step by Newton's method from Δd = 0, or, when the analysis extrapolates,
    /// from the last accepted increment scaled by Δt / Δt_last; every fixed dof starts at its
    /// prescribed increment. Geometrically linear steps start from Δd = 0: their residual is affine
    /// in Δd, so the exact tangent needs one iteration from anywhere, and one solve with one of
    /// [001]'s mapped stiffnesses is then [001]'s K Δu = ΔF.
    pub fn solve(&mut self, model: &Model<D>) -> Result<StepSolve, Error> {
        if model.integration.is_explicit() {
            return self.explicit_update(model);
        }
        let _stage = self.stages.solve.push()?;
        // A floor under the relative test: FORCE_ATOL of the step's force magnitudes.
        let atol = self.user_atol.max(FORCE_ATOL * self.step.force_scale);
        self.snes.set_tolerances(Some(atol), None, None, None)?;
        let mut assembly_seconds = 0.0;
        let t0 = Instant::now();
        self.initial_guess(model)?;
        let (mut out, mut nonfinite) = {
            let (snes, x, jac, mut asm) = self.split(model, &mut assembly_seconds)?;
            let out = snes.solve(x, jac, &mut asm)?;
            (out, asm.nonfinite.take())
        };
        // Full Newton steps that diverged are tried once more from the same start with a
        // backtracking line search, before the driver cuts Δt (see [`LINE_SEARCH_RETRY`]).
        let mut line_search_retry = false;
        if !out.converged
            && DIVERGED_BY_FULL_STEPS.contains(&out.reason_text.as_str())
            && self.retry_with_line_search
            && self.snes.type_name()? == "newtonls"
            && self.snes.line_search_type()? == "basic"
        {
            line_search_retry = true;
            self.initial_guess(model)?;
            self.snes.set_line_search(LINE_SEARCH_RETRY)?;
            let retry = {
                let (snes, x, jac, mut asm) = self.split(model, &mut assembly_seconds)?;
                snes.solve(x, jac, &mut asm).map(|o| (o, asm.nonfinite.take()))
            };
            self.snes.set_line_search("basic")?;
            let (second, second_nonfinite) = retry?;
            // A point that was not finite in the first try names the failure only if the second
            // fails too.
            nonfinite = if second.converged { None } else { nonfinite.or(second_nonfinite) };
            let (first_newton, first_krylov) = (out.iterations, out.linear_iterations);
            out = SolveOutcome {
                iterations: first_newton + second.iterations,
                linear_iterations: first_krylov + second.linear_iterations,
                reason_text: if second.converged {
                    second.reason_text.clone()
                } else {
                    format!("{} ({} with a line search)", out.reason_text, second.reason_text)
                },
                ..second
            };
        }
        let solve_seconds = t0.elapsed().as_secs_f64();
        self.dm.global_to_local(&self.x, &mut self.x_local)?;
        let mut solution = self.x_local.read()?.to_vec();
        for (q, v) in solution.iter_mut().enumerate() {
            *v *= self.step.unit(q);
        }
        self.step.solution = solution;
        let components = &out.final_residual_components;
        let field_residuals = if components.len() == self.layout.nd {
            let norm = |cs: &[usize]| cs.iter().map(|&c| components[c] * components[c]).sum::<f64>().sqrt();
            self.layout.fields().iter().map(|(_, cs)| norm(cs)).collect()
        } else {
            Vec::new()
        };
        Ok(StepSolve {
            converged: out.converged,
            reason: out.reason_text,
            newton_iterations: out.iterations,
            linear_iterations: out.linear_iterations,
            residual_history: out.residual_history,
            domain_error: out.domain_error,
            nonfinite,
            assembly_seconds,
            solve_seconds,
            field_residuals,
            field_scales: self.step.field_scales.clone(),
            linear_field_residuals: out.linear_field_residuals,
            solver_used: true,
            line_search_retry,
        })
    }

    /// Sets PETSc's solution vector to the step's first iterate: the last accepted increment
    /// scaled to the new Δt where the stage extrapolates (static and quasi-static), zero
    /// otherwise, with the prescribed increments at the fixed dofs.
    fn initial_guess(&mut self, model: &Model<D>) -> Result<(), Error> {
        let mut x = self.x.write()?;
        match &self.last_increment {
            Some((last, dt_last))
                if model.integration.extrapolates() && !model.linear_increments && last.len() == x.len() =>
            {
                let ratio = self.step.dt / dt_last;
                for (xi, li) in x.iter_mut().zip(last) {
                    *xi = ratio * li;
                }
            }
            _ => x.fill(0.0),
        }
        for &(o, q) in &self.step.dofs.owned_fixed {
            x[o] = self.step.dofs.value[q] / self.step.unit(q);
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

    /// Splits the system into the SNES, its solution vector and matrix, and the callbacks of the
    /// prepared step (which borrow the rest).
    fn split<'a>(
        &'a mut self,
        model: &'a Model<D>,
        seconds: &'a mut f64,
    ) -> Result<(&'a mut Snes, &'a mut Vector, &'a mut Mat, Assembler<'a, D, M, N>), Error> {
        let GridSystem { dm, x, x_local, f_local, snes, jac, schur, step, stages, .. } = self;
        let jac = jac.as_mut().ok_or_else(|| petsc::Error::new("the step was not prepared"))?;
        let asm =
            Assembler::new(dm, model, step, x_local, f_local, seconds, &stages.assembly).with_schur(schur.as_mut());
        Ok((snes, x, jac, asm))
    }

    /// The forces of the converged step (collective): the moment of the external, reaction and
    /// inertia forces about the grid's centre for the equilibrium identity, and each boundary's
    /// reaction. Under the generalized-α method the balance holds at t_{n+1−α_f}; the "inertia"
    /// is then everything in it but the internal and external forces at t_{n+1} (see
    /// `Assembler::nodal_terms`).
    pub fn step_forces(
        &mut self,
        model: &Model<D>,
        coll: &Collective,
        diagnostics: bool,
    ) -> Result<StepForces<D>, String> {
        let nd = self.layout.nd;
        let ng = self.ghost.len() * nd;
        let (mut all, mut inertia, mut magnitude) = (vec![0.0; ng], vec![0.0; ng], vec![0.0; ng]);
        let (mut stiffness, mut internal) = (vec![0.0; ng], vec![0.0; ng]);
        // An explicit step's forces are those of its start (σ_n on x_n, [`explicit`]): its balance
        // is taken there, against the stress before the particle update (`StepForces::at_start`).
        let at_start = model.integration.is_explicit();
        let xl = if at_start { vec![0.0; ng] } else { self.step.solution.clone() };
        if at_start {
            let start = self.step.start_terms.take().expect("an explicit step's start terms");
            (all, inertia, magnitude) = (start.all, start.inertia, start.magnitude);
        }
        let mut walls = Vec::new();
        self.with_assembler(model, |asm| {
            if !at_start {
                asm.nodal_terms(&xl, &mut all, &mut inertia, &mut magnitude);
            }
            if diagnostics {
                asm.nodal_stiffness_and_force(&xl, &mut stiffness, &mut internal);
            }
            walls = asm.wall_shares(&xl, at_start);
        });
        if diagnostics {
            for v in [&mut stiffness, &mut internal] {
                self.sum_over_ranks(v).map_err(|e| e.to_string())?;
            }
            let mag = |v: &[f64], l: usize| v[l * nd..l * nd + D].iter().fold(0.0, |m: f64, x| m.hypot(*x));
            self.node_diagnostics =
                self.owned_nodes.iter().map(|&a| [mag(&stiffness, a as usize), mag(&internal, a as usize)]).collect();
        }
        let mut fext = self.step.fext.clone();
        let mut fext_old = self.step.fext_old.clone();
        for v in [&mut all, &mut inertia, &mut fext, &mut fext_old, &mut magnitude] {
            self.sum_over_ranks(v).map_err(|e| e.to_string())?;
        }
        // An explicit step's inertia is its lumped nodal update's (already summed over ranks).
        for (i, m) in inertia.iter_mut().zip(&self.step.explicit_inertia) {
            *i += m;
        }
        let field_scales = self.field_norms(&magnitude, coll)?;
        let g = &model.grid;
        let hi = g.extent_max();
        // About the grid's centre; in axial symmetry about the axis (the radial moment of the hoop
        // stress is only defined there).
        let mut origin: [f64; D] = std::array::from_fn(|d| 0.5 * (g.origin[d] + hi[d]));
        if model.geometry.axisymmetric() {
            origin[0] = 0.0;
        }
        let nb = model.boundaries.len();
        // [total moment (D²), external (D²), reaction (D²), inertia (D²), work, reactions per
        // boundary (D nb)]
        let dd = D * D;
        let mut local = vec![0.0; 4 * dd + 1 + D * nb];
        let last = std::mem::take(&mut self.last_reactions);
        let mut reactions = vec![0.0; ng];
        // (dof component, in-plane direction) of the solid and water motion.
        let motion: Vec<(usize, usize)> =
            self.motion().into_iter().map(|c| (c, if c < D { c } else { c - self.layout.w.unwrap_or(0) })).collect();
        for &a in &self.owned_nodes {
            let l = a as usize;
            let p = g.position(self.ghost.indices(l));
            let u = &xl[l * nd..l * nd + D];
            let xr: [f64; D] = std::array::from_fn(|d| p[d] + u[d] - origin[d]);
            for &(c, dir) in &motion {
                let q = l * nd + c;
                let b = self.step.dofs.boundary[q];
                let reaction = if (b as usize) < nb { all[q] - fext[q] } else { 0.0 };
                reactions[q] = reaction;
                let reaction_old = last.get(q).copied().unwrap_or(reaction);
                local[4 * dd] += 0.5 * (fext_old[q] + fext[q] + reaction_old + reaction) * self.step.solution[q];
                book_node_forces(&mut local, nb, b as usize, &xr, dir, [fext[q], reaction, inertia[q]]);
            }
        }
        self.last_reactions = reactions;
        // The held nodes beyond the grid that GIMP supports reach past a wall (this rank's
        // particles'): they do not move, and their share of the particles' forces is the wall's
        // reaction, booked on the boundary that holds the wall node next to them.
        for (w, share) in self.step.stencils.beyond.iter().zip(walls.chunks_exact(2 * nd)) {
            let b = self.step.dofs.boundary[w.wall as usize * nd + w.normal as usize] as usize;
            let xr: [f64; D] = std::array::from_fn(|d| w.at[d] - origin[d]);
            for &(c, dir) in &motion {
                book_node_forces(&mut local, nb, b, &xr, dir, [0.0, share[c], share[c] - share[nd + c]]);
            }
        }
        let s = coll.sum(&local)?;
        let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
        Ok(StepForces {
            moment: std::array::from_fn(|a| std::array::from_fn(|b| s[a * D + b])),
            scale: norm(&s[dd..2 * dd]).max(norm(&s[2 * dd..3 * dd])).max(norm(&s[3 * dd..4 * dd])),
            origin,
            reactions: (0..nb).map(|b| std::array::from_fn(|d| s[4 * dd + 1 + D * b + d])).collect(),
            work: s[4 * dd],
            field_scales,
            at_start,
        })
    }

    /// The norm of each field (`Layout::fields`) of the ghosted, rank-summed dof values `v` over
    /// the free owned dofs, in PETSc's scaling (pressure rows times s) (collective).
    fn field_norms(&self, v: &[f64], coll: &Collective) -> Result<Vec<f64>, String> {
        let nd = self.layout.nd;
        let mut local = vec![0.0; nd];
        for &a in &self.owned_nodes {
            for (c, l) in local.iter_mut().enumerate() {
                let q = a as usize * nd + c;
                if !self.step.dofs.fixed[q] {
                    let m = v[q] * self.step.unit(q);
                    *l += m * m;
                }
            }
        }
        let squares = coll.sum(&local)?;
        Ok(self.layout.fields().iter().map(|(_, cs)| cs.iter().map(|&c| squares[c]).sum::<f64>().sqrt()).collect())
    }

    /// The norm over the free dofs of the prepared step's force magnitudes (collective).
    fn force_scale_of(&mut self, mags: &mut [f64], coll: &Collective) -> Result<f64, String> {
        self.sum_over_ranks(mags).map_err(|e| e.to_string())?;
        self.step.field_scales = self.field_norms(mags, coll)?;
        Ok(self.step.field_scales.iter().map(|x| x * x).sum::<f64>().sqrt())
    }

    /// Runs `f` with the callbacks' view of the prepared step (outside the SNES solve: the nodal
    /// terms, the force magnitudes, the histories of a step's start).
    fn with_assembler<R>(&mut self, model: &Model<D>, f: impl FnOnce(&Assembler<D, M, N>) -> R) -> R {
        let mut seconds = 0.0;
        let GridSystem { dm, x_local, f_local, step, stages, .. } = self;
        f(&Assembler::new(dm, model, step, x_local, f_local, &mut seconds, &stages.assembly))
    }

    /// Σ S_ip u_i at particle `k` of a nodal field `u` per ghosted dof (barely filled nodes
    /// extended from their masters): its solid components (`du`) and water components (`dw`).
    fn interpolated(&self, k: usize, u: &[f64]) -> kernels::Interp<D> {
        let (nodes, basis) = self.step.stencils.get(k);
        let states = callbacks::node_states::<D, M, N>(&self.step, k, u);
        kernels::interpolate(basis, &states[..nodes.len()], &Default::default(), self.layout)
    }

    /// The converged step at particle `k` for the particle update: exactly the point the converged
    /// residual evaluated.
    pub fn step_result(&self, model: &Model<D>, k: usize) -> StepResult<D> {
        let (nodes, basis) = self.step.stencils.get(k);
        let states = callbacks::node_states::<D, M, N>(&self.step, k, &self.step.solution);
        let mut input = callbacks::particle_input(model, &self.step, k);
        // The F̄ projection's scale of an explicit step (only the particle update sees it: the
        // step's forces are those of its start).
        let fbar = self.step.fbar_scale.get(k).copied();
        if let Some([c, s, _]) = fbar {
            input.fbar = c;
            input.fbar_total = s;
        }
        let mat = &model.materials[model.particles.material[k] as usize];
        let strain = self.step.stencils.strain_of(k);
        let pt = kernels::Point::with_recovery(basis, strain, &states[..nodes.len()], &input, &mat.model, self.layout)
            .with_forces(self.step.stencils.forces_of(k))
            .with_faces(self.step.faces_of(k), &states[..nodes.len()]);
        let mut result = StepResult::of(&pt);
        if let Some(f) = fbar {
            result.jbar = Some(f[2]);
        }
        if self.layout.w.is_some() && self.layout.p.is_none() {
            // The u–U system: the nodal pressure's increment, or the point's own.
            result.interp.dp = match self.step.pressure_increment.get(k) {
                Some(&dp) => dp,
                None => kernels::flow::continuity::pointwise_increment(&pt.interp, pt.part),
            };
        }
        if !self.step.start_velocity.is_empty() {
            // An explicit step's FLIP increment Σ S (v_i^{n+1} − v_i^n) takes the v_i^n of its
            // own grid update (the predictors' nodal velocities are those of the raw projection,
            // without the barely filled nodes' shares moved to their masters).
            let v = self.interpolated(k, &self.step.start_velocity);
            result.interp.v_u = v.du;
            result.interp.v_w = v.dw;
        }
        if !self.step.xpic_correction.is_empty() {
            // XPIC: v_p = S v^{n+1} + S (w − v^n), S v^{n+1} = Δu_p/Δt.
            let c = self.interpolated(k, &self.step.xpic_correction).du;
            let dt = self.step.dt;
            result.velocity = Some(std::array::from_fn(|d| result.interp.du[d] / dt + c[d]));
        }
        result
    }

    /// The block of nodes this rank owns and, per node (x fastest), [`node_values`] values: the
    /// active (well-filled) flag (1 or 0) of the last solve, its nodal increments Δd (ux, uy, [uz,]
    /// p, Ux, Uy[, Uz]; zeros beyond the dofs of the layout), K_mag and F^int_mag; the carried
    /// values of a replaced system (or zeros) before the first solve.
    pub fn owned_node_block(&self) -> NodeBlock {
        let nd = self.layout.nd;
        let nv = node_values(D);
        let names = Layout::UPU.in_dim(D).field_names();
        let own = self.layout.field_names();
        let nodes = self.dm.info().nodes;
        let mut values = Vec::with_capacity(self.owned_nodes.len() * nv);
        for (o, &a) in self.owned_nodes.iter().enumerate() {
            let l = a as usize;
            if self.step.solution.is_empty() {
                let n = self.ghost.indices(l);
                let g = crate::model::grid::flat_number(nodes, n) * nv;
                match self.carried.get(g..g + nv) {
                    Some(v) => values.extend(v),
                    None => values.extend(std::iter::repeat_n(0.0, nv)),
                }
                continue;
            }
            values.push(if self.step.dofs.well.get(l).copied().unwrap_or(false) { 1.0 } else { 0.0 });
            for name in names {
                let v = own[..nd].iter().position(|n| n == name).map_or(0.0, |c| self.step.solution[l * nd + c]);
                values.push(v);
            }
            values.extend(self.node_diagnostics.get(o).copied().unwrap_or([0.0; 2]));
        }
        NodeBlock { start: lift3(self.owned_start, 0), count: lift3(self.owned_count, 1), values }
    }

    /// The nodal values of [`Self::owned_node_block`] of every node of the grid (x fastest), summed
    /// over ranks: what a system that replaces this one on another distribution of the nodes
    /// carries over ([`Self::carry_node_values`]; collective).
    pub fn global_node_values(&self, coll: &Collective) -> Result<Vec<f64>, String> {
        let nodes = self.dm.info().nodes;
        let nv = node_values(D);
        let mut all = vec![0.0; nodes.iter().product::<usize>() * nv];
        let block = self.owned_node_block();
        let owned = GhostedRange { start: self.owned_start, count: self.owned_count, dof: 1 };
        for (o, v) in block.values.chunks_exact(nv).enumerate() {
            let n = owned.indices(o);
            let g = crate::model::grid::flat_number(nodes, n) * nv;
            all[g..g + nv].copy_from_slice(v);
        }
        coll.sum(&all)
    }

    /// Takes over the nodal values of the last step of the system this one replaced (from
    /// [`Self::global_node_values`] on the same grid), for the field output until its own first
    /// step.
    pub fn carry_node_values(&mut self, values: Vec<f64>) {
        self.carried = values;
    }
}

/// The parts of the global system that exist only in the plane (validation keeps them out of
/// three-dimensional cases): line pressures and [001]'s mapped stiffnesses.
impl GridSystem {
    /// Whether this rank owns node (i, j), and with it cell (i, j), the cell whose lower-left node
    /// it is.
    pub fn owns_cell(&self, i: usize, j: usize) -> bool {
        self.owns_cell_in([i, j])
    }

    /// The shares of load `li` (a line pressure, plane only) at factor `f`: the forces with the
    /// ghosted node each goes to and the point an extension reaches towards, in the order
    /// [`GridSystem::external_forces`] adds them, and the forces the load applies.
    #[allow(clippy::type_complexity)]
    fn plane_load(&self, model: &Model, li: usize, f: f64) -> (Vec<(usize, [f64; 2], [f64; 2])>, Vec<[f64; 2]>) {
        let g = &model.grid;
        let (mut forces, mut totals) = (Vec::new(), Vec::new());
        match &model.loads[li].target {
            LoadTarget::LinePressure { points, pressure } => {
                // Each Gauss point on the rank owning the cell that holds it.
                for &(point, force) in points {
                    if !g.cell_of(point).is_some_and(|(i, j)| self.owns_cell(i, j)) {
                        continue;
                    }
                    let ring = model.geometry.measure(point[0]);
                    let force = [force[0] * ring, force[1] * ring];
                    totals.push([force[0] * pressure * f, force[1] * pressure * f]);
                    // Shares on unfilled nodes are extended from the material's side.
                    let len = force[0].hypot(force[1]).max(f64::MIN_POSITIVE);
                    let inward = [point[0] + force[0] / len * g.h[0], point[1] + force[1] / len * g.h[1]];
                    for ([i, j], s, _) in shape::face_weights(model.basis, g, point).iter() {
                        let l = self.ghost.node(i as usize, j as usize).expect("an owned cell's nodes are ghosted");
                        forces.push((l, [s * force[0] * pressure * f, s * force[1] * pressure * f], inward));
                    }
                }
            }
            LoadTarget::ParticleTraction { .. } | LoadTarget::NodalTraction { .. } | LoadTarget::BodyForce { .. } => {}
        }
        (forces, totals)
    }

    /// The plane-only part of a step's data (step 4): [001]'s mapped stiffnesses.
    fn plane_step(&mut self, model: &Model, coll: &Collective) -> Result<(), String> {
        self.step.stiffness =
            coll.agree(stiffness::MappedStiffness::prepare(model, &self.ghost, &self.step.stencils))?;
        Ok(())
    }
}

/// A nodal value of a step's start at ghosted dof `q`, the lumped sum `of` over the lumped
/// `mass` (a velocity or an acceleration): zero where a boundary holds the component still (fixed
/// without a prescribed motion) or where no point gives the node mass. The Newmark predictors and
/// an explicit step's FLIP update take their nodal values alike (each from its own lumping).
fn start_value<const D: usize>(model: &Model<D>, dofs: &DofMap, q: usize, mass: &[f64], of: &[f64]) -> f64 {
    let (l, c) = (q / dofs.nd, q % dofs.nd);
    let still = dofs.boundary_fixed(l, c) && model.boundaries[dofs.boundary[q] as usize].motion.is_none();
    if still || mass[q] <= 0.0 {
        0.0
    } else {
        of[q] / mass[q]
    }
}

/// Grid indices of dimension D as three, `fill` for the missing ones.
fn lift3<const D: usize>(n: [usize; D], fill: usize) -> [usize; 3] {
    std::array::from_fn(|d| if d < D { n[d] } else { fill })
}

/// The tractions of a step as the case applies them (before they are shared out to nodes), on
/// this rank, for [`GridSystem::check_loads`].
#[derive(Debug, Clone)]
struct AppliedLoads<const D: usize = 2> {
    /// Total force [N/m in two dimensions, N in three].
    total: [f64; D],
    /// The traction loads that are active.
    names: Vec<String>,
}

impl<const D: usize> Default for AppliedLoads<D> {
    fn default() -> Self {
        AppliedLoads { total: [0.0; D], names: Vec::new() }
    }
}

impl<const D: usize> AppliedLoads<D> {
    fn add(&mut self, force: [f64; D]) {
        for (t, f) in self.total.iter_mut().zip(force) {
            *t += f;
        }
    }
}

/// Nodal projections of a step.
struct Nodal {
    /// Filled fraction per ghosted node.
    phi: Vec<f64>,
    /// Mass-weighted porosity per ghosted node.
    porosity: Vec<f64>,
    /// Per ghosted dof.
    mass: Vec<f64>,
    mom: Vec<f64>,
    acc: Vec<f64>,
}

/// The Newton iterations a step may take (`-snes_max_it` overrides it): 30 with the exact tangent,
/// 300 with one of [001]'s mapped stiffnesses, an approximate Jacobian with which Newton converges
/// linearly (measured on the vertical cut in its softening stage: about 200 iterations a step with
/// DM-G, a contraction of about 0.93 per iteration; docs/stiffness.md).
pub fn newton_iterations(stiffness: crate::case::Stiffness) -> usize {
    if stiffness == crate::case::Stiffness::Particle {
        30
    } else {
        300
    }
}

/// Grid dofs above which the default LU is MUMPS also on one rank. Measured factorisation times
/// (MatLUFactorNum, whole runs): terzaghi (110 grid dofs) UMFPACK 0.086 s vs MUMPS 0.153 s;
/// slumping_block (2 375) 6.30 vs 5.91 s; footing_peer at h = 0.1 (5 406) 2.96 vs 1.97 s and at
/// h = 0.05 (20 806) 15.8 vs 12.2 s. Debian's UMFPACK (32-bit indices) also failed in its numeric
/// factorisation on the slumping block at 1.8e5 grid dofs, where MUMPS factorised it.
pub const UMFPACK_MAX_GRID_DOFS: usize = 2_000;

/// The factorisation package of the default solver: UMFPACK on one rank for grids up to
/// [`UMFPACK_MAX_GRID_DOFS`], MUMPS otherwise.
pub fn default_factor_package(comm: Comm, grid_dofs: usize) -> &'static str {
    if comm.size() == 1
        && grid_dofs <= UMFPACK_MAX_GRID_DOFS
        && petsc::PetscBuild::get().packages.contains(&"suitesparse")
    {
        "umfpack"
    } else {
        "mumps"
    }
}

/// PETSc options that were given but not used by any solver object so far.
pub fn unused_petsc_options() -> Result<Vec<String>, Error> {
    Ok(Options::global().unused()?.iter().map(|o| o.to_string()).collect())
}

/// Every option in PETSc's database, as `-name value` strings.
pub fn petsc_options() -> Result<Vec<String>, Error> {
    Ok(Options::global().all()?.iter().map(|o| o.to_string()).collect())
}

/// The solver configuration (KSP and PC types and the factorisation package), for the summary.
/// The mat-vecs with the whole tangent timed after the linear solves (see `petsc::fields`) and
/// their total wall time [s] on this rank.
pub fn timed_matvecs<const D: usize, const M: usize, const N: usize>(sys: &GridSystem<D, M, N>) -> (usize, f64) {
    sys.snes.timed_matvecs()
}

/// Whether the linear solver iterates (any KSP but `preonly`).
pub fn is_iterative<const D: usize, const M: usize, const N: usize>(
    sys: &mut GridSystem<D, M, N>,
) -> Result<bool, Error> {
    Ok(sys.snes.ksp()?.type_name()? != "preonly")
}

pub fn describe_solver<const D: usize, const M: usize, const N: usize>(
    sys: &mut GridSystem<D, M, N>,
) -> Result<String, Error> {
    let snes_type = sys.snes.type_name()?;
    let lag = sys.snes.lag_jacobian()?;
    let mut ksp = sys.snes.ksp()?;
    let ksp_type = ksp.type_name()?;
    let pc = ksp.pc()?;
    let pc_type = pc.type_name()?;
    let factor = if pc_type == "lu" || pc_type == "cholesky" {
        pc.factor_solver_type()?.map(|s| format!(" ({s})")).unwrap_or_default()
    } else {
        String::new()
    };
    let newton = if lag > 1 || lag == -1 || lag == -2 { "modified Newton (lagged Jacobian)" } else { "Newton" };
    Ok(format!("{snes_type} {newton}; KSP {ksp_type}; PC {pc_type}{factor}"))
}

/// Books one node's forces in direction `dir`, `[external, reaction, inertia]`, at `xr` (its position
/// about the moments' origin) into `step_forces`'s local sums: the first moments of the total
/// (external + reaction − inertia), external, reaction and inertia forces (D² each, in that order)
/// and, for a node held by boundary `boundary` < `nb`, that boundary's reaction (after the work).
fn book_node_forces<const D: usize>(
    local: &mut [f64],
    nb: usize,
    boundary: usize,
    xr: &[f64; D],
    dir: usize,
    [fext, reaction, inertia]: [f64; 3],
) {
    let dd = D * D;
    if boundary < nb {
        local[4 * dd + 1 + D * boundary + dir] += reaction;
    }
    for (row, x) in xr.iter().enumerate() {
        let k = row * D + dir;
        local[k] += x * (fext + reaction - inertia);
        local[dd + k] += x * fext;
        local[2 * dd + k] += x * reaction;
        local[3 * dd + k] += x * inertia;
    }
}
