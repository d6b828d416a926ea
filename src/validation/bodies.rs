//! Bodies: their own values, the stress components a case of their dimension takes, their extent
//! along z, and that they lie inside the grid.

use super::grid::Bounds;
use crate::case::check::Checked;
use crate::case::{Body, Case};

/// Every body.
pub(super) fn check(c: &Case) -> Checked {
    let bounds = Bounds::of(c);
    for (i, b) in c.bodies.iter().enumerate() {
        let key = format!("bodies[{i}]");
        b.check(&key)?;
        uniform_stress(&key, b, c.dimension())?;
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
    Ok(())
}

/// Four components [xx, yy, xy, zz], or six in three dimensions, all finite.
fn uniform_stress(key: &str, b: &Body, dim: usize) -> Checked {
    let Some(s) = &b.uniform_stress else {
        return Ok(());
    };
    if !(s.len() == 4 || (dim == 3 && s.len() == 6)) {
        return Err(format!(
            "key `{key}.uniform_stress`: four entries [xx, yy, xy, zz]{}, got {}",
            if dim == 3 { " or six [xx, yy, xy, zz, yz, zx]" } else { " in a plane case" },
            s.len()
        ));
    }
    if s.iter().any(|v| !v.is_finite()) {
        return Err(format!("key `{key}.uniform_stress`: must be finite"));
    }
    Ok(())
}

/// A body's extent along z: only in three dimensions, ordered, inside the grid.
fn depth(c: &Case, key: &str, b: &Body) -> Checked {
    match (c.dimension(), b.z) {
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
            Err(format!(
                "key `{key}.z`: body `{}` needs z_min < z_max inside the grid's [{g0}, {}], got [{z0}, {z1}]",
                b.name,
                g0 + g1
            ))
        }
        _ => Ok(()),
    }
}
