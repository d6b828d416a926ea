//! The preconditioning matrix of a one-phase solid on the grid's multilinear functions
//! (`-porompm_pc_matrix multilinear`, [`PC_MATRIX_OPTION`]; the per-point blocks are
//! [`crate::kernels::lowered`]'s): the Krylov method multiplies by the exact Jacobian, and the
//! preconditioner (algebraic multigrid above all) is built from a matrix that couples each node with
//! its 3^D neighbours only, instead of the Jacobian's (2r + 1)^D of a basis of support radius r.
//!
//! Its pattern holds the pairs of each point's cell corners, the diagonal block of every node of a
//! point's stencil that is no point's corner on any rank, and of every owned node; it is kept from
//! step to step while it covers them, as the Jacobian's is ([`super::pattern`]). Nodes whose
//! motion is extended from well-filled masters (their dofs fixed) take nothing, as fixed dofs do:
//! a preconditioner may leave out what such a node passes on to its masters.

use super::pattern::Pattern;
use super::space::NodeSpace;
use super::step::{Lowered, Step};
use crate::layout::Layout;
use crate::model::Model;
use crate::parallel::Collective;
use std::sync::Arc;

/// The PETSc option that chooses the matrix the preconditioner is built from: `jacobian` (the
/// default: the Jacobian itself) or `multilinear` (this module's, one-phase solids in static
/// stages).
pub const PC_MATRIX_OPTION: &str = "-porompm_pc_matrix";

/// Which matrix the preconditioner is built from ([`PC_MATRIX_OPTION`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PcMatrix {
    /// The Jacobian.
    #[default]
    Jacobian,
    /// Each point's stiffness on its cell's multilinear functions ([`crate::kernels::lowered`]).
    Multilinear,
}

impl PcMatrix {
    /// The choice of the options database for a system of `layout`; an unknown value, or
    /// `multilinear` for a system that is not a one-phase solid's displacements, is an error that
    /// says so.
    pub fn from_options(layout: Layout) -> Result<PcMatrix, petsc::Error> {
        let choice = match petsc::Options::global().get_string(PC_MATRIX_OPTION)?.as_deref() {
            None | Some("jacobian") => PcMatrix::Jacobian,
            Some("multilinear") => PcMatrix::Multilinear,
            Some(other) => {
                return Err(petsc::Error::new(format!(
                    "{PC_MATRIX_OPTION} {other}: the preconditioning matrix is `jacobian` (the default) or \
                     `multilinear`"
                )))
            }
        };
        let solid = layout.p.is_none() && layout.w.is_none() && layout.jbar.is_none();
        if choice == PcMatrix::Multilinear && !solid {
            return Err(petsc::Error::new(format!(
                "{PC_MATRIX_OPTION} multilinear builds the preconditioner of a one-phase solid's displacements only; \
                 this system has {} unknowns per node (drop the option for it)",
                layout.nd
            )));
        }
        Ok(choice)
    }

    /// The options this choice sets before the solver reads its own, under the preconditioner's
    /// options prefix `pc_prefix`: with a multilinear matrix the preconditioner works on that
    /// matrix alone (`-pc_use_amat false`, PETSc's default outside multigrid). PETSc 3.18's
    /// multigrid computes its finest level's residual with the operator it met at its first
    /// application and keeps it while its hierarchy is reused, which it is while the
    /// preconditioning matrix keeps its pattern: with the Jacobian as that operator, the residual
    /// would come from a Jacobian of an earlier step, held in memory beside the current one.
    /// `-pc_use_amat true` is refused for that reason. Collective (the options database).
    pub fn set_default_options(self, pc_prefix: &str) -> Result<(), petsc::Error> {
        if self != PcMatrix::Multilinear {
            return Ok(());
        }
        let name = format!("-{pc_prefix}pc_use_amat");
        let options = petsc::Options::global();
        match options.get_bool(&name)? {
            Some(true) => Err(petsc::Error::new(format!(
                "{name} true with {PC_MATRIX_OPTION} multilinear: the multigrid would compute its residual with the \
                 first Jacobian it met and keep it from step to step while its hierarchy is reused (PETSc 3.18); \
                 drop the option (the preconditioner then works on the multilinear matrix alone)"
            ))),
            Some(false) => Ok(()),
            None => options.set_value(&name, Some("false")),
        }
    }
}

/// The multilinear preconditioning matrix's side of `step` ([`Lowered`]): its pattern kept (`old`)
/// if every rank finds every pair in it, else a new one. Collective.
pub(super) fn prepare<const D: usize, const M: usize>(
    step: &Step<D, M>,
    model: &Model<D>,
    space: &mut NodeSpace<D>,
    old: Option<Arc<Pattern<D>>>,
    coll: &Collective,
) -> Result<Lowered<D>, String> {
    if step.scheme.a0 * step.scheme.w_inertia != 0.0 || model.geometry.axisymmetric() {
        return Err(format!(
            "{PC_MATRIX_OPTION} multilinear takes static stages in plane strain and three dimensions: \
             its matrix has no inertia and no hoop terms (drop the option for this case)"
        ));
    }
    let ps = &model.particles;
    let c = 1usize << D;
    let mut corners = Vec::with_capacity(step.stencils.len() * c);
    for k in 0..step.stencils.len() {
        let x = ps.x[k];
        let cell = model.grid.cell_containing(x).ok_or_else(|| {
            format!("material point {k} at {x:?} m is outside the grid: it has no cell for {PC_MATRIX_OPTION}")
        })?;
        for corner in 0..c {
            let n: [usize; D] = std::array::from_fn(|d| cell[d] + (corner >> d & 1));
            let l = space.ghost.local(n).ok_or_else(|| {
                format!("material point {k}: a corner of its cell is not among this rank's ghosted nodes")
            })?;
            corners.push(l as u32);
        }
    }
    let nd = step.dofs.nd;
    let mut cornered = vec![0.0; space.ghost.len() * nd];
    for &l in &corners {
        cornered[l as usize * nd] = 1.0;
    }
    space.sum_over_ranks(&mut cornered).map_err(|e| e.to_string())?;
    let lone: Vec<bool> = cornered.iter().step_by(nd).map(|&x| x == 0.0).collect();
    // The cells' corner lists, and the stencil nodes of every point that are no point's corner.
    let cells = || corners.chunks_exact(c);
    let lone_nodes =
        || (0..step.stencils.len()).flat_map(|k| step.stencils.get(k).0.iter().copied().filter(|&a| lone[a as usize]));
    let covers = old.as_ref().is_some_and(|p| {
        !p.is_empty()
            && cells().all(|cs| cs.iter().all(|&a| cs.iter().all(|&b| p.block(a, b).is_some())))
            && lone_nodes().all(|a| p.block(a, a).is_some())
    });
    let keep = old.is_some() && !coll.any(!covers)?;
    let pattern = match old {
        Some(old) if keep => old,
        _ => Arc::new(Pattern::of_groups(cells(), lone_nodes(), &space.owned_nodes, space.ghost.count)),
    };
    let fixed_diagonals = pattern.fixed_diagonals(&step.dofs.owned_fixed, nd)?;
    Ok(Lowered { corners, lone, pattern, fixed_diagonals })
}
