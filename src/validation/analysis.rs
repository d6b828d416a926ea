//! The analysis switches and the stabilisation: what each needs of the formulation, the basis, the
//! kinematics and the stages.

use crate::analysis::StageAnalysis;
use crate::case::{
    AnalysisType, Case, Formulation, Geometry, InternalForce, KinematicsKind, PressureUpdate, ShapeFunctions,
    Stiffness, StressRecovery,
};
use crate::check::Checked;

/// The analysis and stabilisation tables, then what they need of each other and of the stages.
pub(super) fn check(c: &Case) -> Checked {
    c.analysis.check("analysis")?;
    c.stabilisation.check("stabilisation")?;
    let pore_water = c.analysis.formulation == Formulation::TwoPhase;
    if c.analysis.kinematics == KinematicsKind::LinearIncrements {
        linear_increments(c, pore_water)?;
    }
    let st = &c.stabilisation;
    if st.pressure_update == PressureUpdate::ProjectedTotal && !pore_water {
        return Err("key `stabilisation.pressure_update`: `projected_total` needs a two-phase case".into());
    }
    if st.stiffness == Stiffness::DoubleMappingGimp && c.analysis.shape_functions == ShapeFunctions::Linear {
        return Err(
            "key `stabilisation.stiffness`: `double_mapping_gimp` maps with the points' GIMP domains and needs \
                    `analysis.shape_functions = \"gimp\"` or `\"ugimp\"` (a linear basis's stencil does not reach \
                    every cell a domain overlaps)"
                .into(),
        );
    }
    if matches!(c.analysis.shape_functions, ShapeFunctions::Bspline2 | ShapeFunctions::Bspline3) {
        bspline_options(c)?;
    }
    if st.fbar {
        fbar(c)?;
    }
    if st.stress_recovery == StressRecovery::Cmpm && pore_water {
        return Err("key `stabilisation.stress_recovery`: `cmpm` is for one_phase analyses ([001] is one-phase; in \
                    the coupled systems the continuity equation's divergence would no longer be the transpose of \
                    the pressure's force)"
            .into());
    }
    if st.internal_force == InternalForce::Mapped && pore_water {
        return Err("key `stabilisation.internal_force`: `mapped` is for one_phase analyses ([001] is one-phase; \
                    the pore pressure's forces and the continuity equation keep the basis)"
            .into());
    }
    Ok(())
}

/// `linear_increments` is for one-phase cases whose stages are static.
fn linear_increments(c: &Case, pore_water: bool) -> Checked {
    if pore_water {
        return Err("key `analysis.kinematics`: `linear_increments` is for a one_phase analysis (the two-phase \
                    pressure and flow terms are written on the configuration at the step's end)"
            .into());
    }
    match c.stages.iter().find(|s| matches!(s.analysis, AnalysisType::Dynamic | AnalysisType::DynamicExplicit)) {
        Some(s) => Err(format!(
            "key `analysis.kinematics`: `linear_increments` steps are static (stage `{}` is dynamic)",
            s.name
        )),
        None => Ok(()),
    }
}

/// What the B-spline bases do not combine with (yet): B̄'s volumetric operator is built from the
/// bilinear cell-centre gradients, which see only the bilinear part of the splines' nodal values,
/// so the splines' other modes lose their volumetric stiffness (the tapered plate at ν = 0.3 on
/// 4 m cells came out 9.5 % (quadratic) and 19 % (cubic) softer than converged finite elements,
/// GIMP with B̄ 3 % stiffer; [002]'s F̄ projection is the B-splines' answer to locking); [001]'s
/// mapped stiffnesses and CMPM recovery are built on the linear and GIMP cell functions; the weak
/// drainage of a quasi-static stage's free faces evaluates the grid's bilinear functions at the
/// face.
fn bspline_options(c: &Case) -> Checked {
    let name = if c.analysis.shape_functions == ShapeFunctions::Bspline2 { "bspline2" } else { "bspline3" };
    if c.stabilisation.bbar {
        return Err(format!(
            "key `stabilisation.bbar`: B̄'s volumetric strain comes from bilinear cell-centre gradients, which \
             leave the B-splines' (`analysis.shape_functions = \"{name}\"`) other modes without volumetric \
             stiffness (too soft); set `bbar = false`"
        ));
    }
    if c.stabilisation.stiffness != Stiffness::Particle {
        return Err(format!(
            "key `stabilisation.stiffness`: [001]'s mapped stiffnesses are defined on the linear and GIMP cell \
             functions; with `analysis.shape_functions = \"{name}\"` use `particle`"
        ));
    }
    if c.stabilisation.stress_recovery == StressRecovery::Cmpm {
        return Err(format!(
            "key `stabilisation.stress_recovery`: CMPM recovers the strain of the linear and GIMP cell functions; \
             with `analysis.shape_functions = \"{name}\"` use `basis`"
        ));
    }
    match c.stages.iter().find(|s| s.analysis == AnalysisType::QuasiStatic) {
        Some(s) => Err(format!(
            "key `stages.{}.analysis`: a quasi_static stage drains its free faces weakly with the grid's bilinear \
             functions at the face, which B-splines (`analysis.shape_functions = \"{name}\"`) do not provide yet; \
             use `dynamic` (u–p–U) or a GIMP or linear basis",
            s.name
        )),
        None => Ok(()),
    }
}

/// Where [002]'s F̄ projection is built: the implicit stages whose unknowns have an F̄ form (the
/// u and u–p systems, `Layout::with_fbar`, which the stage's analysis says) and one-phase explicit
/// stages, finite strain, plane strain.
fn fbar(c: &Case) -> Checked {
    let implicit = |s: &&crate::case::Stage| s.analysis != AnalysisType::DynamicExplicit;
    if let Some(s) = c.stages.iter().filter(implicit).find(|s| StageAnalysis::of(c, s).layout.jbar.is_none()) {
        return Err(format!(
            "key `stabilisation.fbar`: stage `{}` solves u–p–U, and the F̄ projection is built for the u and u–p \
             systems of implicit stages and for one-phase explicit stages (one more nodal unknown would exceed the \
             five a node carries); run it as quasi_static or static, or without F̄",
            s.name
        ));
    }
    if c.analysis.kinematics == KinematicsKind::LinearIncrements {
        return Err("key `stabilisation.fbar`: F̄ scales the finite-strain increment, and \
                    `analysis.kinematics = \"linear_increments\"` has none; use B̄ for small strains"
            .into());
    }
    if c.analysis.geometry == Geometry::Axisymmetric {
        return Err("key `stabilisation.fbar`: plane strain only (in axial symmetry the projected J would need each \
                    point's hoop stretch, which its in-plane F does not carry); use B̄ (`stabilisation.bbar = true`), \
                    which relieves the locking there in implicit and explicit stages"
            .into());
    }
    Ok(())
}
