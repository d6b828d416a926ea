//! Geometry of the uniform structured background grid in D dimensions (nodes 0..=cells[d] in each
//! direction d; flat node numbers run fastest in x, then y, then z).

/// The background grid: two-dimensional unless `D` says otherwise.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid<const D: usize = 2> {
    /// Lower corner [m].
    pub origin: [f64; D],
    /// Cell size [m].
    pub h: [f64; D],
    /// Cells per direction.
    pub cells: [usize; D],
}

impl<const D: usize> Grid<D> {
    /// A grid with the given origin, cell size and cell counts.
    pub fn new(origin: [f64; D], h: [f64; D], cells: [usize; D]) -> Grid<D> {
        Grid { origin, h, cells }
    }

    /// Nodes per direction.
    pub fn nodes(&self) -> [usize; D] {
        self.cells.map(|c| c + 1)
    }

    /// Total number of nodes.
    pub fn node_count(&self) -> usize {
        self.nodes().iter().product()
    }

    /// The flat number of the node with indices `n` (x fastest).
    pub fn node_number(&self, n: [usize; D]) -> usize {
        flat_number(self.nodes(), n)
    }

    /// The indices of the node with flat number `k` ([`Grid::node_number`]'s inverse).
    pub fn node_indices(&self, k: usize) -> [usize; D] {
        indices_of(self.nodes(), k)
    }

    /// The flat number of the cell with indices `c` (x fastest), as [`Grid::node_number`] numbers
    /// the nodes.
    pub fn cell_number(&self, c: [usize; D]) -> usize {
        flat_number(self.cells, c)
    }

    /// The smallest cell size of the directions [m].
    pub fn h_min(&self) -> f64 {
        self.h.iter().fold(f64::INFINITY, |m, &h| m.min(h))
    }

    /// Position of the node with indices `n` [m].
    pub fn position(&self, n: [usize; D]) -> [f64; D] {
        std::array::from_fn(|d| self.origin[d] + n[d] as f64 * self.h[d])
    }

    /// The local coordinates ξ ∈ [−1, 1]^D of `x` in the cell with lower corner node `c`.
    pub fn local_coords(&self, c: [usize; D], x: [f64; D]) -> [f64; D] {
        let lo = self.position(c);
        std::array::from_fn(|d| 2.0 * (x[d] - lo[d]) / self.h[d] - 1.0)
    }

    /// The cell (its lower corner node) containing `x`, or `None` outside the grid (points on an
    /// upper boundary belong to the last cell).
    pub fn cell_containing(&self, x: [f64; D]) -> Option<[usize; D]> {
        let inside = (0..D).all(|d| {
            let s = (x[d] - self.origin[d]) / self.h[d];
            s >= -1e-9 && s <= self.cells[d] as f64 + 1e-9
        });
        inside.then(|| self.nearest(x))
    }

    /// The cell containing `x`, or the nearest cell outside the grid (cell 0 for a position that is
    /// not finite).
    pub fn nearest(&self, x: [f64; D]) -> [usize; D] {
        std::array::from_fn(|d| {
            let s = (x[d] - self.origin[d]) / self.h[d];
            if s.is_finite() {
                (s.floor().max(0.0) as usize).min(self.cells[d] - 1)
            } else {
                0
            }
        })
    }

    /// Centre of the cell with lower corner node `c` [m].
    pub fn centre(&self, c: [usize; D]) -> [f64; D] {
        std::array::from_fn(|d| self.origin[d] + (c[d] as f64 + 0.5) * self.h[d])
    }

    /// Upper corner [m].
    pub fn extent_max(&self) -> [f64; D] {
        std::array::from_fn(|d| self.origin[d] + self.cells[d] as f64 * self.h[d])
    }
}

/// The flat number, x fastest, of indices `n` in a block of `counts` per direction.
pub fn flat_number<const D: usize>(counts: [usize; D], n: [usize; D]) -> usize {
    (0..D).rev().fold(0, |acc, d| acc * counts[d] + n[d])
}

/// The indices of flat number `k` in a block of `counts` per direction ([`flat_number`]'s inverse).
pub fn indices_of<const D: usize>(counts: [usize; D], mut k: usize) -> [usize; D] {
    std::array::from_fn(|d| {
        let i = k % counts[d];
        k /= counts[d];
        i
    })
}

/// The two-dimensional forms with (i, j) indices, which the plane code uses.
impl Grid<2> {
    /// Position of node (i, j) [m].
    pub fn node_position(&self, i: usize, j: usize) -> [f64; 2] {
        self.position([i, j])
    }

    /// The local coordinates ξ ∈ [−1, 1]² of `x` in cell (i, j) (its lower-left node).
    pub fn local_coordinates(&self, (i, j): (usize, usize), x: [f64; 2]) -> [f64; 2] {
        self.local_coords([i, j], x)
    }

    /// The cell (i, j) containing `x`, or `None` outside the grid (points on the upper boundary
    /// belong to the last cell).
    pub fn cell_of(&self, x: [f64; 2]) -> Option<(usize, usize)> {
        self.cell_containing(x).map(|[i, j]| (i, j))
    }

    /// The cell (i, j) containing `x`, or the nearest cell outside the grid (cell (0, 0) for a
    /// position that is not finite).
    pub fn nearest_cell(&self, x: [f64; 2]) -> (usize, usize) {
        let [i, j] = self.nearest(x);
        (i, j)
    }

    /// Centre of cell (i, j) [m].
    pub fn cell_centre(&self, i: usize, j: usize) -> [f64; 2] {
        self.centre([i, j])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn node_numbers_run_fastest_in_x_and_invert() {
        let g = Grid::new([0.0, -1.0, 2.0], [0.5, 0.25, 1.0], [3, 2, 4]);
        assert_eq!(g.nodes(), [4, 3, 5]);
        assert_eq!(g.node_count(), 60);
        assert_eq!(g.node_number([1, 0, 0]), 1);
        assert_eq!(g.node_number([0, 1, 0]), 4);
        assert_eq!(g.node_number([0, 0, 1]), 12);
        for k in 0..g.node_count() {
            assert_eq!(g.node_number(g.node_indices(k)), k);
        }
        assert_eq!(g.position([2, 1, 3]), [1.0, -0.75, 5.0]);
        assert_eq!(g.extent_max(), [1.5, -0.5, 6.0]);
        // A point on the upper faces belongs to the last cells; one outside to none.
        assert_eq!(g.cell_containing([1.5, -0.5, 6.0]), Some([2, 1, 3]));
        assert_eq!(g.cell_containing([0.7, -0.9, 2.1]), Some([1, 0, 0]));
        assert_eq!(g.cell_containing([0.7, -1.1, 2.1]), None);
        assert_eq!(g.nearest([0.7, -1.1, f64::NAN]), [1, 0, 0]);
        assert_eq!(g.centre([0, 0, 0]), [0.25, -0.875, 2.5]);
        assert_eq!(g.local_coords([1, 0, 0], [0.75, -1.0, 3.0]), [0.0, -1.0, 1.0]);
        // The plane grid's (i, j) forms are the same numbers.
        let p = Grid::new([1.0, 2.0], [0.5, 0.5], [4, 2]);
        assert_eq!(p.node_number([3, 2]), 13);
        assert_eq!(p.cell_of([2.9, 2.2]), Some((3, 0)));
        assert_eq!(p.node_position(3, 2), p.position([3, 2]));
    }
}
