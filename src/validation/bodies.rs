//! Bodies: their own values, the stress components a case of their dimension takes, their extent
//! along z, and that they lie inside the grid.

use super::grid::Bounds;
use crate::case::{Body, Case, CaseFile, GroupName, LoadSurface, Shape};
use crate::check::Checked;
use crate::geometry::{CellKind, Group, Mesh, PointCloud, Surface};
use std::path::Path;
use std::sync::Arc;

/// Reads the files bodies, loads and boundaries are made from, relative to the case file `origin`:
/// a body's mesh (its cells of the case's dimension, of its group, integrated once to find a cell
/// without measure), STL surface (scaled and moved, which must be closed) or particle file; a
/// surface pressure's faces (their Gauss points); a boundary's mesh curves or faces (their
/// corners).
pub(super) fn read_files(file: &mut CaseFile, origin: &str) -> Checked {
    let base = Path::new(origin).parent().unwrap_or(Path::new(""));
    let dim = if file.dimension() == 3 { 3 } else { 2 };
    let axisymmetric = file.analysis.geometry == crate::case::Geometry::Axisymmetric;
    for (i, b) in file.bodies.iter_mut().enumerate() {
        let key = format!("bodies[{i}].shape");
        match &mut b.shape {
            Shape::Mesh(m) => {
                let path = base.join(&m.file);
                let content =
                    crate::io::geometry::read_msh(&path).map_err(|e| format!("key `{key}.mesh.file`: {e}"))?;
                let named = |e: String| format!("key `{key}.mesh`: {}: {e}", path.display());
                let mesh = Mesh::select(&content, dim, group(&m.group)).map_err(named)?;
                mesh.for_each_point(m.order, |_, _, _| {}).map_err(named)?;
                m.loaded = Some(Arc::new(mesh));
            }
            Shape::Surface(s) => {
                let path = base.join(&s.file);
                let file =
                    crate::io::geometry::read_stl(&path).map_err(|e| format!("key `{key}.surface.file`: {e}"))?;
                let surface = Surface::new(s.placed(&file.vertices), file.triangles)
                    .map_err(|e| format!("key `{key}.surface`: {}: {e}", path.display()))?;
                s.loaded = Some(Arc::new(surface));
            }
            Shape::Points(p) => {
                let path = base.join(&p.file);
                let named = |e: String| format!("key `{key}.points`: {}: {e}", path.display());
                let rows = crate::io::geometry::read_points(&path, dim)
                    .map_err(|e| format!("key `{key}.points.file`: {e}"))?;
                let (x, volume) = (&rows.x, &rows.volume);
                // A plane case's volumes are per metre: areas; an axisymmetric one's are rings.
                let ring = |k: usize| if axisymmetric { std::f64::consts::TAU * x[k][0] } else { 1.0 };
                if let Some(k) = (0..x.len()).find(|&k| axisymmetric && x[k][0] <= 0.0) {
                    return Err(named(format!("its point {k} is at r = {}; a ring needs r > 0", x[k][0])));
                }
                let measure = (0..x.len()).map(|k| volume[k] / ring(k)).collect();
                let mut cloud = PointCloud::new(dim, rows.x.clone(), measure).map_err(named)?;
                point_fields(&rows.fields).map_err(named)?;
                cloud.fields = rows.fields;
                p.loaded = Some(Arc::new(cloud));
            }
            _ => {}
        }
    }
    for (i, l) in file.loads.iter_mut().enumerate() {
        if let crate::case::Load::SurfacePressure(p) = l {
            read_load_surface(&mut p.surface, base, &format!("loads[{i}].surface"))?;
        }
    }
    for (i, b) in file.boundaries.iter_mut().enumerate() {
        if let Some(m) = &mut b.mesh {
            let key = format!("boundaries[{i}].mesh");
            let path = base.join(&m.file);
            let content = crate::io::geometry::read_msh(&path).map_err(|e| format!("key `{key}.file`: {e}"))?;
            let polygons = content
                .polygons(dim - 1, group(&m.group))
                .map_err(|e| format!("key `{key}`: {}: {e}", path.display()))?;
            m.loaded = Some(Arc::new(polygons));
        }
    }
    Ok(())
}

/// A particle file's initial fields are finite.
fn point_fields(f: &crate::geometry::PointFields) -> Checked {
    let rows = |name: &str, values: Option<Vec<&[f64]>>| match values {
        Some(v) => match v.iter().position(|r| r.iter().any(|x| !x.is_finite())) {
            Some(k) => Err(format!("its point {k} has the {name} {:?}; an initial field must be finite", v[k])),
            None => Ok(()),
        },
        None => Ok(()),
    };
    rows("velocity", f.velocity.as_ref().map(|v| v.iter().map(|r| &r[..]).collect()))?;
    rows("stress", f.stress.as_ref().map(|v| v.iter().map(|r| &r[..]).collect()))?;
    rows("pore pressure", f.pore_pressure.as_ref().map(|v| v.iter().map(std::slice::from_ref).collect()))
}

/// Reads a loaded surface's file into its Gauss points; `key` is its table.
fn read_load_surface(surface: &mut LoadSurface, base: &Path, key: &str) -> Checked {
    let path = base.join(surface.file());
    match surface {
        LoadSurface::Mesh(m) => {
            let content = crate::io::geometry::read_msh(&path).map_err(|e| format!("key `{key}.mesh.file`: {e}"))?;
            let points = content
                .face_points(group(&m.group))
                .map_err(|e| format!("key `{key}.mesh`: {}: {e}", path.display()))?;
            m.loaded = Some(Arc::new(points));
        }
        LoadSurface::Stl(s) => {
            let file = crate::io::geometry::read_stl(&path).map_err(|e| format!("key `{key}.stl.file`: {e}"))?;
            let placed = s.placed(&file.vertices);
            let faces = file.triangles.iter().map(|t| (CellKind::Triangle, &t[..]));
            s.loaded = Some(Arc::new(crate::geometry::face_points(&placed, faces)));
        }
    }
    Ok(())
}

/// A physical group named in a case.
fn group(g: &Option<GroupName>) -> Option<Group<'_>> {
    g.as_ref().map(|g| match g {
        GroupName::Tag(t) => Group::Tag(*t),
        GroupName::Name(n) => Group::Name(n),
    })
}

/// Every body.
pub(super) fn check(c: &Case) -> Checked {
    let bounds = Bounds::of(c);
    for (i, b) in c.bodies.iter().enumerate() {
        let key = format!("bodies[{i}]");
        b.check(&key)?;
        if (b.shape.mesh().is_some() || b.shape.points().is_some()) && b.perturbation != 0.0 {
            return Err(format!(
                "key `{key}.perturbation`: moves the points of a body filled on the grid; a mesh's points are its \
                 cells' quadrature points, a particle file's its rows"
            ));
        }
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
        crate::model::particles::for_each_candidate(c, &grid, i, |p| {
            let x = p.x;
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
/// in a two-phase case only and instead of a geostatic state's; a particle file's fields given
/// once, in its columns or in the body's keys.
fn initial(c: &Case, key: &str, b: &Body) -> Checked {
    if let Some(p) = b.shape.points() {
        file_fields(c, key, b, &p.cloud().fields)?;
    }
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

/// A particle file's initial fields against the body's own: each given once; a pore pressure in a
/// two-phase case only.
fn file_fields(c: &Case, key: &str, b: &Body, f: &crate::geometry::PointFields) -> Checked {
    let given = |f: fn(&crate::case::InitialFields) -> bool| b.initial.as_ref().is_some_and(f);
    let twice = |what: &str, also: bool| -> Checked {
        if also {
            return Err(format!(
                "key `{key}.shape.points`: its file gives the points' {what} and the body gives it too; give it once"
            ));
        }
        Ok(())
    };
    twice("velocity", f.velocity.is_some() && given(|i| i.velocity.is_some()))?;
    let body_stress = given(|i| i.stress.is_some()) || b.initial_stress.is_some() || b.uniform_stress.is_some();
    twice("stress", f.stress.is_some() && body_stress)?;
    twice(
        "pore pressure",
        f.pore_pressure.is_some() && (given(|i| i.pore_pressure.is_some()) || b.initial_stress.is_some()),
    )?;
    if f.pore_pressure.is_some() && c.analysis.formulation != crate::case::Formulation::TwoPhase {
        return Err(format!(
            "key `{key}.shape.points`: its file gives a pore pressure, which a one_phase analysis has not"
        ));
    }
    Ok(())
}

/// A body's extent along z: only in three dimensions, ordered, inside the grid; a solid shape
/// only in three dimensions, with its own extent.
fn depth(c: &Case, key: &str, b: &Body) -> Checked {
    if b.shape.solid().is_some() {
        if c.dimension() != 3 {
            return Err(format!(
                "key `{key}.shape`: a box, sphere, cylinder or surface is a shape of a three-dimensional case"
            ));
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
