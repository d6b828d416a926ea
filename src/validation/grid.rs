//! The grid: its keys, what its dimension allows, and the questions the other sections ask of it
//! (whether a point lies inside, which grid lines a box holds).

use super::dimensions;
use crate::case::{Case, Region};
use crate::check::Checked;

/// The grid's checks, then what its dimension allows ([`dimensions`]).
pub(super) fn check(c: &Case) -> Checked {
    c.grid.check("grid")?;
    if c.dimension() == 3 {
        dimensions::three_dimensional(c)?;
    } else {
        dimensions::plane_regions(c)?;
        dimensions::plane_pressures(c)?;
    }
    dimensions::axisymmetry(c, Bounds::of(c).tol[0])
}

/// The grid's bounds (beyond the case's dimension unused) with the tolerance of a point on them.
pub(super) struct Bounds {
    /// The lower corner [m].
    pub lo: [f64; 3],
    /// The upper corner [m].
    pub hi: [f64; 3],
    /// The cell size [m].
    pub h: [f64; 3],
    /// 1e-9 of the cell size [m].
    pub tol: [f64; 3],
}

impl Bounds {
    /// The bounds of `c`'s grid.
    pub fn of(c: &Case) -> Bounds {
        let lo = c.origin_in::<3>();
        let h = c.cell_size_in::<3>();
        let hi = std::array::from_fn(|d| lo[d] + c.grid.size.get(d).copied().unwrap_or(1.0));
        Bounds { lo, hi, h, tol: h.map(|h| 1e-9 * h) }
    }

    /// Whether a point with a coordinate per direction (a plane section's two, or a case's D) lies
    /// within the bounds.
    pub fn contains(&self, p: &[f64]) -> bool {
        p.iter().enumerate().all(|(d, &x)| x >= self.lo[d] - self.tol[d] && x <= self.hi[d] + self.tol[d])
    }
}

/// How many of the grid's lines across direction `d` (its node positions along `d`) lie in the box
/// `region` (with `slack` [m] beyond its tolerance in x and y; along z the region's `z` range, all
/// of it without one).
pub(super) fn grid_lines_in(c: &Case, region: &Region, d: usize, slack: f64) -> usize {
    let (origin, h, cells) = (c.origin_in::<3>(), c.cell_size_in::<3>(), c.cells_in::<3>());
    (0..=cells[d])
        .filter(|&i| {
            let x = origin[d] + i as f64 * h[d];
            if d == 2 {
                region.spans_z(x)
            } else {
                region.spans(d, x, slack)
            }
        })
        .count()
}
