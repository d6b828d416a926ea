//! MLSA patch recovery of pore-pressure increments ([003] §3.3, Eqs. 26–30; Zienkiewicz & Zhu 1992).
//!
//! 1. The nodal increments Δp_i are sampled at the centres of the active cells ([003] Eq. 26): the
//!    bilinear interpolant at a cell centre is the mean of the cell's four nodal values.
//! 2. Every node i owns a patch: the (up to four) active cells around it. A linear polynomial
//!    Δp = a₀ + a₁ X + a₂ Y (X, Y the offsets from node i in cell sizes) is fitted to the patch's
//!    cell-centre values by least squares ([003] Eqs. 27–29). A direction in which all the patch's
//!    centres coincide (a column one cell wide, a boundary row) gets no slope term.
//! 3. A particle takes Δp from the patch whose rectangle (spanned by the four cell centres around a
//!    node, i.e. centred on its nearest node) holds it ([003] Eq. 30). If that patch is incomplete
//!    (fewer than four active cells: the material's boundary), the patch of the neighbouring node with
//!    the most active cells (the nearest among equals) is extended up to the particle.
//!
//! Pure: the caller supplies cell activity and nodal values on a block of nodes it holds.

use super::grid::Grid;

/// Nodal pressure increments and cell activity on a rectangular block of nodes.
pub struct PatchField<'a> {
    /// The grid.
    pub grid: &'a Grid,
    /// First node (i, j) of the block.
    pub start: [usize; 2],
    /// Nodes of the block in x and y.
    pub count: [usize; 2],
    /// Δp at the block's nodes (x fastest).
    pub dp: &'a [f64],
    /// Whether each node of the block is active.
    pub active: &'a [bool],
}

impl PatchField<'_> {
    fn node(&self, i: i64, j: i64) -> Option<usize> {
        let (i0, j0) = (self.start[0] as i64, self.start[1] as i64);
        if i < i0 || j < j0 || i >= i0 + self.count[0] as i64 || j >= j0 + self.count[1] as i64 {
            return None;
        }
        Some(((j - j0) as usize) * self.count[0] + (i - i0) as usize)
    }

    /// Δp at the centre of cell (i, j) if the cell is active (its four nodes are in the block and
    /// active).
    fn cell(&self, i: i64, j: i64) -> Option<f64> {
        if i < 0 || j < 0 || i >= self.grid.cells[0] as i64 || j >= self.grid.cells[1] as i64 {
            return None;
        }
        let mut sum = 0.0;
        for (di, dj) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
            let n = self.node(i + di, j + dj)?;
            if !self.active[n] {
                return None;
            }
            sum += self.dp[n];
        }
        Some(0.25 * sum)
    }

    /// The active cells of node (i, j)'s patch: (X, Y, Δp) with X, Y the offsets of the cell centre
    /// from the node in cell sizes (±1/2).
    fn patch(&self, i: i64, j: i64) -> Vec<PatchPoint> {
        let mut out = Vec::with_capacity(4);
        for (ci, cj) in [(i - 1, j - 1), (i, j - 1), (i - 1, j), (i, j)] {
            if let Some(v) = self.cell(ci, cj) {
                out.push(((ci - i) as f64 + 0.5, (cj - j) as f64 + 0.5, v));
            }
        }
        out
    }

    /// The recovered Δp at a particle at `x`.
    pub fn recover(&self, x: [f64; 2]) -> Option<f64> {
        let g = self.grid;
        let s = [(x[0] - g.origin[0]) / g.h[0], (x[1] - g.origin[1]) / g.h[1]];
        let nearest = [s[0].round() as i64, s[1].round() as i64];
        // The nearest node's patch, or the fullest neighbouring one (nearest among equals).
        // (number of active cells, squared distance, node, patch points) of the best patch so far.
        let mut best: Option<(usize, f64, [i64; 2], Vec<PatchPoint>)> = None;
        for dj in -1..=1 {
            for di in -1..=1 {
                let node = [nearest[0] + di, nearest[1] + dj];
                let pts = self.patch(node[0], node[1]);
                if pts.is_empty() {
                    continue;
                }
                let d2 = (s[0] - node[0] as f64).powi(2) + (s[1] - node[1] as f64).powi(2);
                let better = match &best {
                    None => true,
                    Some((n, bd, _, _)) => pts.len() > *n || (pts.len() == *n && d2 < *bd),
                };
                if (di, dj) == (0, 0) && pts.len() == 4 {
                    return Some(fit(&pts, s[0] - node[0] as f64, s[1] - node[1] as f64));
                }
                if better {
                    best = Some((pts.len(), d2, node, pts));
                }
            }
        }
        best.map(|(_, _, node, pts)| fit(&pts, s[0] - node[0] as f64, s[1] - node[1] as f64))
    }
}

/// A sampling point of a patch: (X, Y, Δp) with X, Y in cell sizes from the patch's node.
type PatchPoint = (f64, f64, f64);

/// Least-squares fit of a₀ + a₁X + a₂Y to `pts` (dropping a slope where the points do not spread),
/// evaluated at (X, Y).
fn fit(pts: &[PatchPoint], x: f64, y: f64) -> f64 {
    let spread = |f: fn(&PatchPoint) -> f64| {
        let lo = pts.iter().map(f).fold(f64::INFINITY, f64::min);
        let hi = pts.iter().map(f).fold(f64::NEG_INFINITY, f64::max);
        hi - lo > 0.5
    };
    let (use_x, use_y) = (spread(|p| p.0), spread(|p| p.1));
    let basis = |p: (f64, f64)| -> Vec<f64> {
        let mut b = vec![1.0];
        if use_x {
            b.push(p.0);
        }
        if use_y {
            b.push(p.1);
        }
        b
    };
    let m = basis((0.0, 0.0)).len();
    // Normal equations A a = b ([003] Eq. 29), at most 3 × 3.
    let mut a = [[0.0; 3]; 3];
    let mut b = [0.0; 3];
    for p in pts {
        let q = basis((p.0, p.1));
        for r in 0..m {
            b[r] += q[r] * p.2;
            for c in 0..m {
                a[r][c] += q[r] * q[c];
            }
        }
    }
    // Symmetric positive definite when the slopes are kept only where the points spread.
    let coef = crate::model::linalg::solve(a, b, m).unwrap_or([b[0] / a[0][0], 0.0, 0.0]);
    basis((x, y)).iter().zip(coef).map(|(q, c)| q * c).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn field(grid: &Grid, f: impl Fn([f64; 2]) -> f64, active: impl Fn(usize, usize) -> bool) -> (Vec<f64>, Vec<bool>) {
        let [nx, ny] = grid.nodes();
        let mut dp = Vec::new();
        let mut act = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                dp.push(f(grid.node_position(i, j)));
                act.push(active(i, j));
            }
        }
        (dp, act)
    }

    #[test]
    fn linear_fields_are_recovered_exactly_inside_and_at_boundaries() {
        let g = Grid::new([0.0, 0.0], [0.5, 0.25], [8, 8]);
        let lin = |p: [f64; 2]| 3.0 + 2.0 * p[0] - 5.0 * p[1];
        // Material in the lower-left 5 × 6 nodes only: boundary patches are incomplete and extended.
        let (dp, act) = field(&g, lin, |i, j| i <= 4 && j <= 5);
        let pf = PatchField { grid: &g, start: [0, 0], count: g.nodes(), dp: &dp, active: &act };
        for x in [[0.1, 0.05], [1.0, 0.6], [1.9, 1.2], [0.02, 1.23], [1.98, 0.01]] {
            let r = pf.recover(x).unwrap();
            assert!((r - lin(x)).abs() < 1e-12, "at {x:?}: {r} vs {}", lin(x));
        }
    }

    #[test]
    fn a_checkerboard_of_nodal_values_is_smoothed_out() {
        let g = Grid::new([0.0, 0.0], [0.1, 0.1], [6, 6]);
        // Smooth part 10 + checkerboard ±1 on the nodes: every cell centre averages it away.
        let (dp, act) = field(
            &g,
            |p| 10.0 + if ((p[0] / 0.1).round() + (p[1] / 0.1).round()) as i64 % 2 == 0 { 1.0 } else { -1.0 },
            |_, _| true,
        );
        let pf = PatchField { grid: &g, start: [0, 0], count: g.nodes(), dp: &dp, active: &act };
        for x in [[0.12, 0.27], [0.33, 0.41], [0.05, 0.55]] {
            assert!((pf.recover(x).unwrap() - 10.0).abs() < 1e-12);
        }
    }

    #[test]
    fn a_column_one_cell_wide_uses_vertical_patches() {
        let g = Grid::new([0.0, 0.0], [0.1, 0.1], [1, 10]);
        let quad = |p: [f64; 2]| p[1] * p[1];
        let (dp, act) = field(&g, quad, |_, _| true);
        let pf = PatchField { grid: &g, start: [0, 0], count: g.nodes(), dp: &dp, active: &act };
        // Between the centres of cells 4 and 5 (y = 0.45, 0.55) the patch interpolates the centre
        // values linearly; the top particle (y = 0.975) extrapolates from cells 8 and 9.
        let centre = |j: usize| 0.5 * (quad([0.0, j as f64 * 0.1]) + quad([0.0, (j + 1) as f64 * 0.1]));
        let r = pf.recover([0.025, 0.525]).unwrap();
        assert!((r - 0.5 * (centre(4) + centre(5)) - (0.525 - 0.5) / 0.1 * (centre(5) - centre(4))).abs() < 1e-12);
        let r = pf.recover([0.075, 0.975]).unwrap();
        let expect = centre(9) + (0.975 - 0.95) / 0.1 * (centre(9) - centre(8));
        assert!((r - expect).abs() < 1e-12, "{r} vs {expect}");
    }
}
