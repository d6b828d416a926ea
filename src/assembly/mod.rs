//! The global system: the only application module that talks to PETSc.
//!
//! A DMDA holds the background grid ([`NodeSpace`]: dofs of the layout interlaced per node), so
//! that the distribution of nodes over ranks, ghost nodes and the global numbering come from
//! PETSc. A step is a value ([`Step`]) that [`System::prepare`] builds in one pass (stencils, P2G,
//! dof map, loads, pattern; see [`step`]) and [`System::solve`] hands to PETSc's SNES, whose
//! residual and Jacobian callbacks ([`callbacks`]) run every point's pure kernels of
//! [`crate::kernels`] ([`points`]), map their blocks through the extensions of barely filled nodes
//! ([`stencils`]) and add them into a ghosted vector (summed over ranks by PETSc) and one value
//! array written into the matrix in place ([`matrix`]). The converged step's forces and reactions
//! ([`forces`]), the pressure increments its points take ([`pressure`]) and each point's result
//! ([`Step::result`]) are read from the step and its [`Solution`]. Every decision that leads to a collective is agreed across ranks first
//! (`Collective::agree`).

mod aggregates;
mod bench;
mod callbacks;
mod check;
mod dim;
pub mod dofs;
mod explicit;
mod forces;
mod loads;
mod lowered;
mod matrix;
pub mod pattern;
mod points;
mod prepare;
mod pressure;
mod space;
mod splits;
pub mod stencils;
mod step;
mod stiffness;
mod system;
mod ties;

pub use check::BlockCheck;
pub use dim::StepDim;
pub use forces::StepForces;
pub use pressure::scale as pressure_scale;
pub use space::{node_values, NodeBlock, NodeSpace, NODE_VALUES};
pub use stencils::WELL_FILLED_FRACTION;
pub use step::{Solution, Step};
pub use stiffness::MappedStiffness;
pub use system::{Phase, SolidSystem, StepSolve, System};

use petsc::{Comm, Options};

/// Errors of the global system.
pub type Error = petsc::Error;

/// The PETSc option that turns the field-wise Krylov convergence test off (`false`): by default
/// a Krylov solve converges only when the residual of every field (u, p, U), relative to its own
/// equations' terms, is within `-ksp_rtol` (see `petsc::fields::FieldTest`).
pub const FIELD_TEST_OPTION: &str = "-porompm_ksp_field_test";

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

/// The default linear solver's factorisation ([`default_factor`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DefaultFactor {
    /// One factorisation of the whole (distributed) matrix by the named package (`-pc_type lu`).
    Lu(&'static str),
    /// Each rank factorises its own copy of the whole matrix with the named package
    /// (`-pc_type redundant`, PETSc's way for a system too small to share): on several ranks a
    /// small system's distributed factorisation is its communication. Measured on two ranks,
    /// cases/harmonic_column_zone3.toml (300 unknowns, 8 797 factorisations): MUMPS's
    /// distributed LU took 3.4 ms a factorisation, four times the whole one-rank step.
    Redundant(&'static str),
}

/// The default factorisation: UMFPACK for grids up to [`UMFPACK_MAX_GRID_DOFS`] (on several
/// ranks each rank's own copy, [`DefaultFactor::Redundant`]), MUMPS otherwise.
pub fn default_factor(comm: Comm, grid_dofs: usize) -> DefaultFactor {
    if grid_dofs <= UMFPACK_MAX_GRID_DOFS && petsc::PetscBuild::get().packages.contains(&"suitesparse") {
        if comm.size() == 1 {
            DefaultFactor::Lu("umfpack")
        } else {
            DefaultFactor::Redundant("umfpack")
        }
    } else {
        DefaultFactor::Lu("mumps")
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
