//! What a step does in one dimension only: [001]'s CMPM strain recovery, its double-mapped
//! internal force and its mapped stiffnesses are built on the plane's cells (validation keeps them
//! out of three-dimensional cases). [`StepDim`] is implemented for [`Dim<2>`] and [`Dim<3>`], and
//! the dimension-generic step reaches it through a `where Dim<D>: StepDim<D>` bound.

use super::dofs::DofMap;
use super::stencils::{self, Stencils};
use super::stiffness::{self, MappedStiffness};
use crate::case::{InternalForce, StressRecovery};
use crate::layout::Dim;
use crate::model::Model;
use crate::parallel::Collective;
use petsc::GhostedRange;

/// The parts of a step that depend on the grid's dimension.
pub trait StepDim<const D: usize> {
    /// The operators of the points' strain and internal force where the case asks for [001]'s
    /// CMPM recovery (`stabilisation.stress_recovery = "cmpm"`) or its double mapping
    /// (`stabilisation.internal_force = "mapped"`, with `stress_recovery = "mapped"` its
    /// transpose for the strain), set in `st` before any term of the step is evaluated.
    /// Collective.
    fn recover_strain(
        st: &mut Stencils<D>,
        model: &Model<D>,
        ghost: &GhostedRange<D>,
        dofs: &DofMap,
        coll: &Collective,
    ) -> Result<(), String>;

    /// The mapped material stiffness of [001] (`stabilisation.stiffness`; empty for `particle`).
    /// Collective.
    fn mapped_stiffness(
        model: &Model<D>,
        ghost: &GhostedRange<D>,
        st: &Stencils<D>,
        coll: &Collective,
    ) -> Result<MappedStiffness, String>;
}

impl StepDim<2> for Dim<2> {
    fn recover_strain(
        st: &mut Stencils,
        model: &Model,
        ghost: &GhostedRange,
        dofs: &DofMap,
        coll: &Collective,
    ) -> Result<(), String> {
        if model.stress_recovery == StressRecovery::Cmpm {
            coll.agree(stencils::cmpm_patches(st, model, ghost, dofs))?;
        }
        if model.internal_force == InternalForce::Mapped {
            coll.agree(stiffness::mapped_forces(model, ghost, st))?;
            if model.stress_recovery == StressRecovery::Mapped {
                // The strain's operators are the forces' (validation: no CMPM patches here).
                st.strain = st.forces.clone();
            }
        }
        Ok(())
    }

    fn mapped_stiffness(
        model: &Model,
        ghost: &GhostedRange,
        st: &Stencils,
        coll: &Collective,
    ) -> Result<MappedStiffness, String> {
        coll.agree(MappedStiffness::prepare(model, ghost, st))
    }
}

/// Three dimensions: the points' own operators and the exact material stiffness.
impl StepDim<3> for Dim<3> {
    fn recover_strain(
        _: &mut Stencils<3>,
        _: &Model<3>,
        _: &GhostedRange<3>,
        _: &DofMap,
        _: &Collective,
    ) -> Result<(), String> {
        Ok(())
    }

    fn mapped_stiffness(
        _: &Model<3>,
        _: &GhostedRange<3>,
        _: &Stencils<3>,
        _: &Collective,
    ) -> Result<MappedStiffness, String> {
        Ok(MappedStiffness::default())
    }
}
