//! Loads: their vectors with a component per dimension, the layer of nodes a nodal traction
//! loads, an increment factor that evaluates where the loaded faces start, line pressures inside
//! the grid, and surface pressures inside it with material on one side of every point.

use super::grid::{grid_lines_in, Bounds};
use crate::case::{Case, Load, Region};
use crate::check::{components, Checked};

/// Every load.
pub(super) fn check(c: &Case) -> Checked {
    let dim = c.dimension();
    for (i, l) in c.loads.iter().enumerate() {
        let key = format!("loads[{i}]");
        l.check(&key)?;
        match l {
            Load::ParticleTraction(t) => {
                components(&format!("{key}.traction"), &t.traction, dim)?;
                let held = match dim {
                    3 => points_in::<3>(c, i, &t.region),
                    _ => points_in::<2>(c, i, &t.region),
                };
                if !held {
                    return Err(format!(
                        "key `{key}.region`: load `{}` acts on no material point: no point of {} lies in its region",
                        t.name,
                        t.body.as_ref().map_or("any body".to_string(), |b| format!("body `{b}`"))
                    ));
                }
                if let Some(e) = &t.increment_factor {
                    increment_factor(c, &key, &t.region, e)?;
                }
            }
            Load::NodalTraction(t) => {
                components(&format!("{key}.traction"), &t.traction, dim)?;
                nodal_layer(c, &t.region).map_err(|m| format!("key `{key}.region`: {m}"))?;
            }
            Load::BodyForce(f) => components(&format!("{key}.acceleration"), &f.acceleration, dim)?,
            Load::LinePressure(p) => {
                let bounds = Bounds::of(c);
                if let Some((j, p)) = p.points.iter().enumerate().find(|(_, p)| !bounds.contains(&p[..])) {
                    return Err(format!("key `{key}.points[{j}]`: {p:?} is outside the grid"));
                }
            }
            Load::SurfacePressure(p) => {
                let bounds = Bounds::of(c);
                let file = p.surface.file();
                if let Some((x, _)) = p.surface.points().iter().find(|(x, _)| !bounds.contains(&x[..])) {
                    return Err(format!("key `{key}.surface`: {file}: its point {x:?} is outside the grid"));
                }
                crate::model::loads::surface_pressure_points(c, p.surface.points(), c.cell_size_in::<3>())
                    .map_err(|e| format!("key `{key}.surface`: {file}: {e}"))?;
            }
        }
    }
    Ok(())
}

/// Whether `region` holds a material point of the bodies load `load` acts on (whether the point's
/// loaded face is on the material's surface is the run's question: it depends on the others).
fn points_in<const D: usize>(c: &Case, load: usize, region: &Region) -> bool {
    let grid = crate::model::grid_of::<D>(c);
    let bodies = c.load_bodies(crate::case::LoadId::new(load));
    let mut found = false;
    for b in 0..c.bodies.len() {
        if found || bodies.is_some_and(|bs| !bs.iter().any(|id| id.index() == b)) {
            continue;
        }
        crate::model::particles::for_each_point(c, &grid, b, |p| found = found || region.contains_in(p.x));
    }
    found
}

/// Whether an increment factor `e` evaluates where the loaded faces start: the region's centre
/// (its z range's, or the grid's, in three dimensions).
fn increment_factor(c: &Case, key: &str, region: &Region, e: &str) -> Checked {
    let mut centre = vec![0.5 * (region.min[0] + region.max[0]), 0.5 * (region.min[1] + region.max[1])];
    if c.dimension() == 3 {
        let z0 = c.origin_in::<3>()[2];
        let [lo, hi] = region.z.unwrap_or([z0, z0 + c.grid.size[2]]);
        centre.push(0.5 * (lo + hi));
    }
    crate::model::loads::increment_factor(e, &c.parameters, &centre)
        .map(|_| ())
        .map_err(|m| format!("key `{key}.increment_factor`: `{e}` at {centre:?}: {m}"))
}

/// Whether the grid nodes inside a nodal traction's `region` form what it loads: a line of the
/// plane's grid or a surface of a three-dimensional one (the nodes of a box are a block of the grid;
/// it must be one node thick in exactly one direction, and more than one node wide in the others,
/// or the tributary measures of `model::loads::tributary_nodes` would be zero or counted twice).
fn nodal_layer(c: &Case, region: &Region) -> Checked {
    let dim = c.dimension();
    let counts: Vec<usize> = (0..dim).map(|d| grid_lines_in(c, region, d, 0.0)).collect();
    let what = if dim == 2 { "a line" } else { "a surface" };
    if counts.contains(&0) {
        return Err("holds no grid node".into());
    }
    let thin = counts.iter().filter(|&&n| n == 1).count();
    if thin != 1 {
        return Err(format!(
            "the grid nodes inside it must form {what} of the grid (one node thick in one direction), but it holds \
             {} nodes along x, y{} ({})",
            counts.iter().map(|n| n.to_string()).collect::<Vec<_>>().join(", "),
            if dim == 3 { ", z" } else { "" },
            if thin == 0 {
                "a block"
            } else if dim == 3 && thin == 2 {
                "a line"
            } else {
                "a single node"
            }
        ));
    }
    Ok(())
}
