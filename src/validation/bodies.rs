//! Bodies: their own values, the stress components a case of their dimension takes, their extent
//! along z, and that they lie inside the grid.

use super::grid::Bounds;
use crate::case::{Body, Case};
use crate::check::Checked;

/// Every body.
pub(super) fn check(c: &Case) -> Checked {
    let bounds = Bounds::of(c);
    for (i, b) in c.bodies.iter().enumerate() {
        let key = format!("bodies[{i}]");
        b.check(&key)?;
        uniform_stress(&key, b, c.dimension())?;
        initial(c, &key, b)?;
        depth(c, &key, b)?;
        let (bmin, bmax) = b.shape.bounds();
        if !bounds.contains(&bmin) || !bounds.contains(&bmax) {
            return Err(format!(
                "key `{key}.shape`: body `{}` ({bmin:?} .. {bmax:?}) reaches outside the grid ({:?} .. {:?}); \
                 particles outside the grid are not allowed",
                b.name,
                &bounds.lo[..2],
                &bounds.hi[..2]
            ));
        }
    }
    match c.dimension() {
        3 => occupancy::<3>(c),
        _ => occupancy::<2>(c),
    }
}

/// Every body holds material points of its own: at least one of the places its
/// `particles_per_cell` gives it lies inside it, and none lies inside an earlier body too (a
/// point belongs to one body; two bodies that overlap would leave the later one without its
/// points there, silently).
fn occupancy<const D: usize>(c: &Case) -> Checked {
    let grid = crate::model::grid_of::<D>(c);
    for (i, b) in c.bodies.iter().enumerate() {
        let (mut held, mut overlaps) = (0usize, vec![0usize; i]);
        let values = c.initial_values(crate::case::BodyId::new(i));
        let mut not_finite = None;
        crate::model::particles::for_each_candidate(c, &grid, i, |_, _, x| {
            if c.body_holds(b, x) {
                held += 1;
                match c.bodies[..i].iter().position(|o| c.body_holds(o, x)) {
                    Some(e) => overlaps[e] += 1,
                    None if not_finite.is_none() => not_finite = values.not_finite_at(x).map(|f| (f, x)),
                    None => {}
                }
            }
        });
        if let Some(((field, v), x)) = not_finite {
            return Err(format!(
                "key `bodies[{i}].initial.{field}`: body `{}` has the value {v} at its material point {x:?}; an \
                 initial field must be finite at every point",
                b.name
            ));
        }
        let key = format!("bodies[{i}].shape");
        let own = held - overlaps.iter().sum::<usize>();
        if held == 0 || own == 0 {
            let (n, per) = (b.particles_per_cell, if D == 3 { "³" } else { "²" });
            let spacing = grid.h[0].min(grid.h[1]) / n as f64;
            let why = match held {
                0 => format!(
                    "none of its {n}{per} points per cell lies inside it (it is thinner than the point spacing, \
                     {spacing:e} m); make it larger or give it more `particles_per_cell`"
                ),
                _ => "every point it would hold lies inside an earlier body".into(),
            };
            return Err(format!("key `{key}`: body `{}` holds no material point: {why}", b.name));
        }
        let refuses = b.overlap == crate::case::Overlap::Refuse;
        if let Some((e, &n)) = overlaps.iter().enumerate().find(|(_, &n)| n > 0 && refuses) {
            return Err(format!(
                "key `{key}`: body `{}` overlaps body `{}` (bodies[{e}]): {n} of its {held} material points lie \
                 inside both; a material point belongs to one body: make them meet without overlapping, or \
                 give this body `overlap = \"yield\"` to leave those points to the earlier one",
                b.name, c.bodies[e].name
            ));
        }
    }
    Ok(())
}

/// Four components [xx, yy, xy, zz], or six in three dimensions, all finite.
fn uniform_stress(key: &str, b: &Body, dim: usize) -> Checked {
    let Some(s) = &b.uniform_stress else {
        return Ok(());
    };
    stress_components(&format!("{key}.uniform_stress"), s.len(), dim)?;
    if s.iter().any(|v| !v.is_finite()) {
        return Err(format!("key `{key}.uniform_stress`: must be finite"));
    }
    Ok(())
}

/// A stress of `n` components at `key`: four [xx, yy, xy, zz], or six in three dimensions.
fn stress_components(key: &str, n: usize, dim: usize) -> Checked {
    if n == 4 || (dim == 3 && n == 6) {
        return Ok(());
    }
    Err(format!(
        "key `{key}`: four entries [xx, yy, xy, zz]{}, got {n}",
        if dim == 3 { " or six [xx, yy, xy, zz, yz, zx]" } else { " in a plane case" }
    ))
}

/// A body's initial fields: a velocity of one component per direction, a stress of four components
/// (or six in three dimensions) instead of `initial_stress` and `uniform_stress`, a pore pressure
/// in a two-phase case only and instead of a geostatic state's.
fn initial(c: &Case, key: &str, b: &Body) -> Checked {
    let Some(init) = &b.initial else {
        return Ok(());
    };
    let dim = c.dimension();
    if let Some(v) = init.velocity.as_ref().filter(|v| v.len() != dim) {
        return Err(format!(
            "key `{key}.initial.velocity`: {dim} components in a case of dimension {dim}, got {}",
            v.len()
        ));
    }
    if let Some(s) = &init.stress {
        stress_components(&format!("{key}.initial.stress"), s.len(), dim)?;
        if b.initial_stress.is_some() || b.uniform_stress.is_some() {
            return Err(format!(
                "key `{key}.initial.stress`: give the body's stress once: `initial.stress`, `initial_stress` or \
                 `uniform_stress`"
            ));
        }
    }
    if init.pore_pressure.is_some() {
        if c.analysis.formulation != crate::case::Formulation::TwoPhase {
            return Err(format!("key `{key}.initial.pore_pressure`: a one_phase analysis has no pore pressure"));
        }
        if b.initial_stress.is_some() {
            return Err(format!(
                "key `{key}.initial.pore_pressure`: the geostatic `initial_stress` gives the pore pressure; give one \
                 or the other"
            ));
        }
    }
    Ok(())
}

/// A body's extent along z: only in three dimensions, ordered, inside the grid; a solid shape
/// only in three dimensions, with its own extent.
fn depth(c: &Case, key: &str, b: &Body) -> Checked {
    if b.shape.solid().is_some() {
        if c.dimension() != 3 {
            return Err(format!("key `{key}.shape`: a box, sphere or cylinder is a shape of a three-dimensional case"));
        }
        if b.z.is_some() {
            return Err(format!("key `{key}.z`: a solid shape has its own extent along z; give no `z`"));
        }
    }
    match (c.dimension(), b.z.or_else(|| b.shape.depth())) {
        (2, Some(_)) => Err(format!(
            "key `{key}.z`: only a three-dimensional case (three entries in `grid.size`) takes a body's extent \
             along z"
        )),
        (3, Some([z0, z1])) => {
            let (g0, g1) = (c.grid.origin.get(2).copied().unwrap_or(0.0), c.grid.size[2]);
            let tol = 1e-9 * g1 / c.grid.cells[2] as f64;
            if z0.is_finite() && z1.is_finite() && z0 < z1 && z0 >= g0 - tol && z1 <= g0 + g1 + tol {
                return Ok(());
            }
            let what = if b.shape.solid().is_some() { "shape" } else { "z" };
            Err(format!(
                "key `{key}.{what}`: body `{}` needs z_min < z_max inside the grid's [{g0}, {}], got [{z0}, {z1}]",
                b.name,
                g0 + g1
            ))
        }
        _ => Ok(()),
    }
}
