//! Stages: their own values, the case's time integration, and what each analysis type needs of
//! the formulation and, for an explicit two-phase stage, of the boundaries.

use crate::case::{AnalysisType, Case, Dof, Explicit, ExplicitPressure, Formulation, Stage};
use crate::check::Checked;

/// Every stage, and the time integration of the case's dynamic stages.
pub(super) fn check(c: &Case) -> Checked {
    for (i, s) in c.stages.iter().enumerate() {
        s.check(&format!("stages[{i}]"))?;
    }
    c.time_integration.check("time_integration")?;
    let pore_water = c.analysis.formulation == Formulation::TwoPhase;
    c.stages.iter().try_for_each(|s| analysis_type(c, s, pore_water))
}

/// What a stage's analysis type needs of the formulation.
fn analysis_type(c: &Case, s: &Stage, pore_water: bool) -> Checked {
    let key = |k: &str| format!("stages.{}.{k}", s.name);
    match s.analysis {
        AnalysisType::QuasiStatic if !pore_water => {
            return Err(format!(
                "key `{}`: a quasi_static stage solves the water's flow and needs `analysis.formulation = \
                 \"two_phase\"`; use `static` for a one-phase case",
                key("analysis")
            ))
        }
        AnalysisType::Static if pore_water && s.drainage.is_none() => {
            return Err(format!(
                "key `{}`: a static stage of a two-phase case needs `drainage = \"drained\"` (the pore pressure is \
                 held) or `\"undrained\"` (no flow)",
                key("drainage")
            ))
        }
        _ => {}
    }
    if s.drainage.is_some() && !(s.analysis == AnalysisType::Static && pore_water) {
        return Err(format!("key `{}`: only a static stage of a two-phase case takes `drainage`", key("drainage")));
    }
    if s.analysis != AnalysisType::DynamicExplicit {
        return Ok(());
    }
    let active = |name: &str| s.boundaries.as_ref().is_none_or(|list| list.iter().any(|n| n == name));
    if let Some(b) = c.boundaries.iter().find(|b| b.force.is_some() && active(&b.name)) {
        return Err(format!(
            "key `boundaries` (`{}`): stage `{}` is explicit, and a rigid body under a `force` has its motion as an \
             unknown of an implicit step's Newton solve; run the stage implicitly (`dynamic`, `static`, \
             `quasi_static`) or leave the boundary out of the stage's `boundaries`",
            b.name, s.name
        ));
    }
    if let Some(b) = c.boundaries.iter().find(|b| !b.impermeable.is_empty() && active(&b.name)) {
        return Err(format!(
            "key `boundaries` (`{}`): stage `{}` is explicit, and an impermeable surface's water follows the solid \
             through the rows of an implicit step's Newton solve; run the stage implicitly or leave the boundary \
             out of the stage's `boundaries`",
            b.name, s.name
        ));
    }
    let e = s.explicit.unwrap_or_default();
    if pore_water {
        explicit_with_pore_water(c, s, &e)
    } else if e.pore_pressure.is_some() {
        Err(format!(
            "key `{}`: a one-phase stage has no pore pressure; leave `pore_pressure` out",
            key("explicit.pore_pressure")
        ))
    } else {
        Ok(())
    }
}

/// The limits of a two-phase `dynamic_explicit` stage (the u–U system, `Layout::UW`): its pore
/// pressure lives at the points, so no boundary can fix it (a surface where the water may leave is
/// drained by itself, one where its normal motion is fixed is impermeable), and the transfers and
/// projections built for the one-phase system (XPIC, F̄) are not built for the water.
fn explicit_with_pore_water(c: &Case, s: &Stage, e: &Explicit) -> Checked {
    if e.xpic_order.is_some() {
        return Err(format!(
            "key `stages.{}.explicit.xpic_order`: XPIC is built for one-phase explicit stages only (the water's \
             velocities would need their own passes); use `flip_blend`",
            s.name
        ));
    }
    if c.stabilisation.fbar {
        return Err(
            "key `stabilisation.fbar`: the F̄ projection is built for one-phase explicit stages only (the pore \
             pressure of a two-phase explicit stage follows the points' own volume changes); use \
             `stabilisation.bbar` for the volumetric smoothing"
                .into(),
        );
    }
    let pointwise = e.pore_pressure != Some(ExplicitPressure::Nodal);
    let active = |name: &str| s.boundaries.as_ref().is_none_or(|list| list.iter().any(|n| n == name));
    match c.boundaries.iter().find(|b| active(&b.name) && b.fix.contains(&Dof::P)) {
        Some(b) if pointwise => Err(format!(
            "key `boundaries` (`{}`): stage `{}` is explicit two-phase and holds its pore pressure point by point \
             (`explicit.pore_pressure = \"pointwise\"`, the default), so `p` cannot be fixed; a surface where the \
             water's motion is free is drained (p = 0) by itself, one that fixes the water's normal motion \
             (`Ux`/`Uy`) is impermeable. Take `p` out of `fix`, leave the boundary out of the stage's `boundaries`, \
             or set `explicit.pore_pressure = \"nodal\"` (the pressure at the nodes, which drained nodes fix)",
            b.name, s.name
        )),
        _ => Ok(()),
    }
}
