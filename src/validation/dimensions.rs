//! What a case's dimension and geometry allow: what a three-dimensional case may not ask for
//! (line pressures, which are plane by nature) or not yet ([001]'s CMPM and mapped stiffnesses),
//! and the conditions of an axisymmetric one. What they allow of a verification check its
//! parameters say ([`crate::verification::CheckParameters`]).

use crate::case::{Case, Geometry, Load, Stiffness, StressRecovery};
use crate::check::Checked;

/// A plane (or axisymmetric) case's load regions have no extent along z: one given would be
/// ignored (the boundaries' regions are checked with their other z keys).
pub(super) fn plane_regions(c: &Case) -> Checked {
    let with_z = c.loads.iter().position(|l| match l {
        Load::ParticleTraction(t) => t.region.z.is_some(),
        Load::NodalTraction(t) => t.region.z.is_some(),
        _ => false,
    });
    match with_z {
        Some(i) => Err(format!(
            "key `loads[{i}].region.z`: only a three-dimensional case (three entries in `grid.size`) takes a \
             region's extent along z"
        )),
        None => Ok(()),
    }
}

/// A plane or axisymmetric case has no surface to press: its pressures act on lines.
pub(super) fn plane_pressures(c: &Case) -> Checked {
    match c.loads.iter().position(|l| matches!(l, Load::SurfacePressure(_))) {
        Some(i) => Err(format!(
            "key `loads[{i}].kind = \"surface_pressure\"`: a surface pressure acts in a three-dimensional case; a plane \
             or axisymmetric one presses a `line_pressure`"
        )),
        None => Ok(()),
    }
}

/// What a three-dimensional case may not ask for, and the space of its points' identifiers.
pub(super) fn three_dimensional(c: &Case) -> Checked {
    let not_yet =
        |key: &str| Err(format!("key `{key}`: not available in a three-dimensional case yet (docs/dimensions.md)"));
    if c.analysis.geometry == Geometry::Axisymmetric {
        return Err("key `analysis.geometry`: a three-dimensional case has no axial symmetry (give two entries \
                    per grid key for an axisymmetric one)"
            .into());
    }
    if let Some(i) = c.loads.iter().position(|l| matches!(l, Load::LinePressure(_))) {
        return Err(format!(
            "key `loads[{i}].kind = \"line_pressure\"`: a line pressure acts on a plane polyline; a \
             three-dimensional case loads a surface with a `particle_traction` or a `nodal_traction`"
        ));
    }
    if c.stabilisation.stress_recovery == StressRecovery::Cmpm {
        return Err("key `stabilisation.stress_recovery`: [001]'s CMPM recovery is two-dimensional".into());
    }
    if c.stabilisation.stiffness != Stiffness::Particle {
        return not_yet("stabilisation.stiffness");
    }
    // A point's identifier numbers its sub-cell below bit 48 (at most 8 points per cell and
    // direction, `Particles::generate`).
    let sub_cells: f64 = c.grid.cells.iter().map(|&n| 8.0 * n as f64).product();
    if sub_cells >= (1u64 << 48) as f64 {
        return Err(format!(
            "key `grid.cells`: {:?} cells are too many to number the material points of (at most 2^48 / 512 cells)",
            c.grid.cells
        ));
    }
    Ok(())
}

/// The conditions of an axisymmetric case: x is the radius, so the grid starts at r ≥ 0 (the
/// material then lies at r > 0, and nodes on the axis get u_r = 0 from the model's own `axis`
/// boundary, a name no case boundary may take). `tol` [m] is the round-off allowed below r = 0.
pub(super) fn axisymmetry(c: &Case, tol: f64) -> Checked {
    if c.analysis.geometry != Geometry::Axisymmetric {
        return Ok(());
    }
    if c.origin()[0] < -tol {
        return Err(format!(
            "key `grid.origin`: an axisymmetric analysis has x ≡ r ≥ 0, so the grid must start at x ≥ 0 (got {})",
            c.origin()[0]
        ));
    }
    if let Some(b) = c.boundaries.iter().find(|b| b.name == crate::model::AXIS) {
        return Err(format!(
            "key `boundaries`: the name `{}` is taken by the axis of an axisymmetric analysis (u_r = 0 at r = 0, \
             added by the program); rename the boundary",
            b.name
        ));
    }
    Ok(())
}
