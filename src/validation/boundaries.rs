//! Boundaries: what of them belongs to three dimensions only, that a region or a mesh's boundary
//! holds grid nodes, and
//! that a motion has a component per dimension and moves only what the boundary fixes. In a
//! one_phase analysis the water-phase components (p, Ux, Uy) have no dofs and are ignored, so that
//! one case file can switch formulation with `--set analysis.formulation`.

use super::grid::{grid_lines_in, Bounds};
use crate::case::{Boundary, Case, Dof};
use crate::check::Checked;

/// Every boundary.
pub(super) fn check(c: &Case) -> Checked {
    let dim = c.dimension();
    for (i, b) in c.boundaries.iter().enumerate() {
        let key = format!("boundaries[{i}]");
        b.check(&key)?;
        dimension(&key, b, dim)?;
        if let Some(r) = &b.region {
            // A region between grid lines fixes nothing: the body it was meant to hold would move
            // freely (a clamp at x = 0 on a grid whose lines miss x = 0). A box holds a node if
            // some grid line of each direction crosses it (`Region::holds_node`, one axis at a time).
            let Bounds { lo, h, .. } = Bounds::of(c);
            if !(0..2).all(|d| grid_lines_in(c, r, d, 1e-9 * h[d]) > 0) {
                return Err(format!(
                    "key `{key}.region`: holds no grid node (the grid lines lie at x = {} + i·{}, y = {} + j·{} m); \
                     move the region onto them or change the grid",
                    lo[0], h[0], lo[1], h[1]
                ));
            }
        }
        if let Some(m) = &b.mesh {
            mesh_nodes(c, &format!("{key}.mesh"), m)?;
        }
        motion(&key, b, dim)?;
        if let Some(x) = &b.force_point {
            if x.len() != dim {
                return Err(format!(
                    "key `{key}.force_point`: {dim} coordinates in a case of {dim} dimensions, got {}",
                    x.len()
                ));
            }
            if c.analysis.geometry == crate::case::Geometry::Axisymmetric {
                return Err(format!(
                    "key `{key}.force_point`: a rigid body in axial symmetry is a ring or a disc on the axis, which \
                     moves along the axis and does not rotate; leave the point out"
                ));
            }
        }
    }
    Ok(())
}

/// A boundary's mesh curves or faces hold at least one grid node (a mesh whose boundary misses the
/// grid's lines would fix nothing).
fn mesh_nodes(c: &Case, key: &str, m: &crate::case::MeshBoundary) -> Checked {
    let count = if c.dimension() == 3 {
        crate::model::loads::mesh_nodes(&crate::model::grid_of::<3>(c), m).len()
    } else {
        crate::model::loads::mesh_nodes(&crate::model::grid_of::<2>(c), m).len()
    };
    if count == 0 {
        let Bounds { lo, h, .. } = Bounds::of(c);
        return Err(format!(
            "key `{key}`: its {} hold no grid node (the grid lines lie at x = {} + i·{}, y = {} + j·{} m); put \
             the mesh's boundary on them or change the grid",
            if c.dimension() == 3 { "faces" } else { "lines" },
            lo[0],
            h[0],
            lo[1],
            h[1]
        ));
    }
    Ok(())
}

/// What of a boundary belongs to three dimensions only (z sides, `uz`/`Uz`, a region's z range, a
/// surface's z faces), and the z ranges of a three-dimensional one.
fn dimension(key: &str, b: &Boundary, dim: usize) -> Checked {
    let surface_region = b.surface.as_ref().and_then(|sf| sf.region);
    if dim == 2 {
        let z_parts = [
            (b.side.is_some_and(|s| s.axis() == 2), "side"),
            (b.fix.iter().any(|d| matches!(d, Dof::Uz | Dof::WUz)), "fix"),
            (b.impermeable.contains(&Dof::WUz), "impermeable"),
            (b.region.is_some_and(|r| r.z.is_some()), "region.z"),
            (b.surface.as_ref().is_some_and(|sf| sf.faces.iter().any(|f| f.axis() == 2)), "surface.faces"),
            (surface_region.is_some_and(|r| r.z.is_some()), "surface.region.z"),
        ];
        return match z_parts.iter().find(|(bad, _)| *bad) {
            Some((_, part)) => Err(format!(
                "key `{key}.{part}`: z (a `z_min`/`z_max` side or face, `uz`/`Uz`, a region's `z`) belongs to \
                 three-dimensional cases only"
            )),
            None => Ok(()),
        };
    }
    for (r, part) in [(b.region, "region.z"), (surface_region, "surface.region.z")] {
        if let Some([z0, z1]) = r.and_then(|r| r.z) {
            if !(z0.is_finite() && z1.is_finite() && z0 <= z1) {
                return Err(format!("key `{key}.{part}`: needs finite z_min ≤ z_max, got [{z0}, {z1}]"));
            }
        }
    }
    Ok(())
}

/// A motion's shape: a velocity gradient of D rows of D entries about a centre of D coordinates,
/// moving every displacement component; a displacement or velocity of D finite components, each
/// non-zero one moving a component the boundary fixes.
fn motion(key: &str, b: &Boundary, dim: usize) -> Checked {
    let moved = [Dof::Ux, Dof::Uy, Dof::Uz];
    if let Some(l) = &b.velocity_gradient {
        if l.len() != dim || l.iter().any(|row| row.len() != dim) {
            return Err(format!(
                "key `{key}.velocity_gradient`: {dim} rows of {dim} entries (∂v_i/∂x_j) in a case of {dim} \
                 dimensions, got {:?}",
                l.iter().map(Vec::len).collect::<Vec<_>>()
            ));
        }
        if !moved[..dim].iter().all(|d| b.fix.contains(d)) {
            return Err(format!(
                "key `{key}.velocity_gradient`: moves every displacement component, so `fix` must list {}",
                moved[..dim].iter().map(|d| format!("`{d}`")).collect::<Vec<_>>().join(", ")
            ));
        }
    }
    if let Some(cn) = b.center.as_ref().filter(|cn| cn.len() != dim || cn.iter().any(|v| !v.is_finite())) {
        return Err(format!("key `{key}.center`: {dim} finite coordinates in a case of {dim} dimensions, got {cn:?}"));
    }
    let (field, vector) = match (&b.displacement, &b.velocity, &b.force) {
        (Some(d), _, _) => ("displacement", d),
        (None, Some(v), _) => ("velocity", v),
        (None, None, Some(f)) => ("force", f),
        (None, None, None) => return Ok(()),
    };
    if vector.len() != dim {
        return Err(format!(
            "key `{key}.{field}`: {dim} components in a case of {dim} dimensions, got {}",
            vector.len()
        ));
    }
    if vector.iter().any(|v| !v.is_finite()) {
        return Err(format!("key `{key}.{field}`: must be finite"));
    }
    for (c, dof) in moved.into_iter().enumerate().take(dim) {
        if vector[c] != 0.0 && !b.fix.contains(&dof) {
            return Err(format!("key `{key}.{field}`: component {c} moves `{dof}`, which `fix` does not list"));
        }
    }
    if b.force.is_some() {
        if !moved[..dim].iter().any(|d| b.fix.contains(d)) {
            return Err(format!(
                "key `{key}.fix`: a rigid body under a `force` moves by the displacement components it lists; list \
                 at least one of {}",
                moved[..dim].iter().map(|d| format!("`{d}`")).collect::<Vec<_>>().join(", ")
            ));
        }
        // The water moves with a rigid body where it is tied: its component needs the solid's.
        let water = [(Dof::WUx, Dof::Ux), (Dof::WUy, Dof::Uy), (Dof::WUz, Dof::Uz)];
        if let Some((w, u)) = water.into_iter().find(|(w, u)| b.fix.contains(w) && !b.fix.contains(u)) {
            return Err(format!(
                "key `{key}.fix`: a rigid body's water component `{w}` moves with its solid one; list `{u}` too"
            ));
        }
    }
    Ok(())
}
