//! Geometry of the uniform structured background grid (nodes i = 0..=cells_x, j = 0..=cells_y).

/// The background grid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    /// Lower-left corner [m].
    pub origin: [f64; 2],
    /// Cell size [m].
    pub h: [f64; 2],
    /// Cells per direction.
    pub cells: [usize; 2],
}

impl Grid {
    /// A grid with the given origin, cell size and cell counts.
    pub fn new(origin: [f64; 2], h: [f64; 2], cells: [usize; 2]) -> Grid {
        Grid { origin, h, cells }
    }

    /// Nodes per direction.
    pub fn nodes(&self) -> [usize; 2] {
        [self.cells[0] + 1, self.cells[1] + 1]
    }

    /// Total number of nodes.
    pub fn node_count(&self) -> usize {
        self.nodes()[0] * self.nodes()[1]
    }

    /// Position of node (i, j) [m].
    pub fn node_position(&self, i: usize, j: usize) -> [f64; 2] {
        [self.origin[0] + i as f64 * self.h[0], self.origin[1] + j as f64 * self.h[1]]
    }

    /// The local coordinates ξ ∈ [−1, 1]² of `x` in cell (i, j) (its lower-left node).
    pub fn local_coordinates(&self, (i, j): (usize, usize), x: [f64; 2]) -> [f64; 2] {
        let lo = self.node_position(i, j);
        [2.0 * (x[0] - lo[0]) / self.h[0] - 1.0, 2.0 * (x[1] - lo[1]) / self.h[1] - 1.0]
    }

    /// The cell (i, j) containing `x`, or `None` outside the grid (points on the upper boundary
    /// belong to the last cell).
    pub fn cell_of(&self, x: [f64; 2]) -> Option<(usize, usize)> {
        let inside = (0..2).all(|d| {
            let s = (x[d] - self.origin[d]) / self.h[d];
            s >= -1e-9 && s <= self.cells[d] as f64 + 1e-9
        });
        inside.then(|| self.nearest_cell(x))
    }

    /// The cell (i, j) containing `x`, or the nearest cell outside the grid (cell (0, 0) for a
    /// position that is not finite).
    pub fn nearest_cell(&self, x: [f64; 2]) -> (usize, usize) {
        let mut c = [0usize; 2];
        for d in 0..2 {
            let s = (x[d] - self.origin[d]) / self.h[d];
            c[d] = if s.is_finite() { (s.floor().max(0.0) as usize).min(self.cells[d] - 1) } else { 0 };
        }
        (c[0], c[1])
    }

    /// Centre of cell (i, j) [m].
    pub fn cell_centre(&self, i: usize, j: usize) -> [f64; 2] {
        [self.origin[0] + (i as f64 + 0.5) * self.h[0], self.origin[1] + (j as f64 + 0.5) * self.h[1]]
    }

    /// Upper-right corner [m].
    pub fn extent_max(&self) -> [f64; 2] {
        [self.origin[0] + self.cells[0] as f64 * self.h[0], self.origin[1] + self.cells[1] as f64 * self.h[1]]
    }
}
