//! MLSA patch recovery of pore-pressure increments ([003] §3.3, Eqs. 26–30; Zienkiewicz & Zhu 1992),
//! in D dimensions.
//!
//! 1. The nodal increments Δp_i are sampled at the centres of the active cells ([003] Eq. 26): the
//!    multilinear interpolant at a cell centre is the mean of the cell's 2^D nodal values.
//! 2. Every node i owns a patch: the (up to 2^D) active cells around it. A linear polynomial
//!    Δp = a₀ + a₁ X + a₂ Y (+ a₃ Z) (X, Y, Z the offsets from node i in cell sizes) is fitted to
//!    the patch's cell-centre values by least squares ([003] Eqs. 27–29). A direction in which all
//!    the patch's centres coincide (a column one cell wide, a boundary row) gets no slope term.
//! 3. A particle takes Δp from the patch whose box (spanned by the 2^D cell centres around a node,
//!    i.e. centred on its nearest node) holds it ([003] Eq. 30). If that patch is incomplete (fewer
//!    than 2^D active cells: the material's boundary), the patch of the neighbouring node (of the
//!    3^D around the nearest) with the most active cells (the nearest among equals) is extended up
//!    to the particle.
//!
//! Pure: the caller supplies cell activity and nodal values on a block of nodes it holds.

use super::grid::{flat_number, indices_of, Grid};

/// Nodal pressure increments and cell activity on a box of nodes (two-dimensional unless `D` says
/// otherwise).
pub struct PatchField<'a, const D: usize = 2> {
    /// The grid.
    pub grid: &'a Grid<D>,
    /// First node of the block.
    pub start: [usize; D],
    /// Nodes of the block along each direction.
    pub count: [usize; D],
    /// Δp at the block's nodes (x fastest).
    pub dp: &'a [f64],
    /// Whether each node of the block is active.
    pub active: &'a [bool],
}

/// Corner or neighbour `m` of a cell or node as its D bits (bit d: the upper one along d).
fn bit(m: usize, d: usize) -> i64 {
    ((m >> d) & 1) as i64
}

impl<const D: usize> PatchField<'_, D> {
    fn node(&self, n: [i64; D]) -> Option<usize> {
        let mut local = [0usize; D];
        for d in 0..D {
            let i = n[d] - self.start[d] as i64;
            if i < 0 || i >= self.count[d] as i64 {
                return None;
            }
            local[d] = i as usize;
        }
        Some(flat_number(self.count, local))
    }

    /// Δp at the centre of cell `c` if the cell is active (its 2^D nodes are in the block and
    /// active).
    fn cell(&self, c: [i64; D]) -> Option<f64> {
        if (0..D).any(|d| c[d] < 0 || c[d] >= self.grid.cells[d] as i64) {
            return None;
        }
        let corners = 1usize << D;
        let mut sum = 0.0;
        for m in 0..corners {
            let n = self.node(std::array::from_fn(|d| c[d] + bit(m, d)))?;
            if !self.active[n] {
                return None;
            }
            sum += self.dp[n];
        }
        Some(sum / corners as f64)
    }

    /// The active cells of node `n`'s patch: the offsets of their centres from the node in cell
    /// sizes (±1/2) and their Δp.
    fn patch(&self, n: [i64; D]) -> Vec<PatchPoint<D>> {
        let corners = 1usize << D;
        let mut out = Vec::with_capacity(corners);
        for m in 0..corners {
            let c: [i64; D] = std::array::from_fn(|d| n[d] - 1 + bit(m, d));
            if let Some(v) = self.cell(c) {
                out.push((std::array::from_fn(|d| (c[d] - n[d]) as f64 + 0.5), v));
            }
        }
        out
    }

    /// The recovered Δp at a particle at `x`.
    pub fn recover(&self, x: [f64; D]) -> Option<f64> {
        let g = self.grid;
        let s: [f64; D] = std::array::from_fn(|d| (x[d] - g.origin[d]) / g.h[d]);
        let nearest: [i64; D] = s.map(|v| v.round() as i64);
        let full = 1usize << D;
        // The nearest node's patch, or the fullest neighbouring one (nearest among equals).
        // (number of active cells, squared distance, node, patch points) of the best patch so far.
        let mut best: Option<(usize, f64, [i64; D], Vec<PatchPoint<D>>)> = None;
        let around = 3usize.pow(D as u32);
        for k in 0..around {
            let offset = indices_of([3; D], k).map(|o| o as i64 - 1);
            let node: [i64; D] = std::array::from_fn(|d| nearest[d] + offset[d]);
            let pts = self.patch(node);
            if pts.is_empty() {
                continue;
            }
            let d2 = (0..D).map(|d| (s[d] - node[d] as f64).powi(2)).fold(0.0, |a, v| a + v);
            let better = match &best {
                None => true,
                Some((n, bd, _, _)) => pts.len() > *n || (pts.len() == *n && d2 < *bd),
            };
            if offset.iter().all(|&o| o == 0) && pts.len() == full {
                return Some(fit(&pts, std::array::from_fn(|d| s[d] - node[d] as f64)));
            }
            if better {
                best = Some((pts.len(), d2, node, pts));
            }
        }
        best.map(|(_, _, node, pts)| fit(&pts, std::array::from_fn(|d| s[d] - node[d] as f64)))
    }
}

/// A sampling point of a patch: its offsets in cell sizes from the patch's node, and Δp there.
type PatchPoint<const D: usize> = ([f64; D], f64);

/// Least-squares fit of a₀ + Σ_d a_d X_d to `pts` (dropping a slope where the points do not
/// spread), evaluated at `at`.
fn fit<const D: usize>(pts: &[PatchPoint<D>], at: [f64; D]) -> f64 {
    let spreads: [bool; D] = std::array::from_fn(|d| {
        let lo = pts.iter().map(|p| p.0[d]).fold(f64::INFINITY, f64::min);
        let hi = pts.iter().map(|p| p.0[d]).fold(f64::NEG_INFINITY, f64::max);
        hi - lo > 0.5
    });
    let basis = |p: [f64; D]| -> Vec<f64> {
        let mut b = vec![1.0];
        b.extend((0..D).filter(|&d| spreads[d]).map(|d| p[d]));
        b
    };
    let m = basis([0.0; D]).len();
    // Normal equations A a = b ([003] Eq. 29), at most 4 × 4.
    let mut a = [[0.0; 4]; 4];
    let mut b = [0.0; 4];
    for p in pts {
        let q = basis(p.0);
        for r in 0..m {
            b[r] += q[r] * p.1;
            for c in 0..m {
                a[r][c] += q[r] * q[c];
            }
        }
    }
    // Symmetric positive definite when the slopes are kept only where the points spread.
    let coef = crate::algebra::linalg::solve(a, b, m).unwrap_or([b[0] / a[0][0], 0.0, 0.0, 0.0]);
    basis(at).iter().zip(coef).map(|(q, c)| q * c).sum()
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

    /// The values of `f` and the activity at the nodes of a three-dimensional grid (x fastest).
    fn field_3d(
        grid: &Grid<3>,
        f: impl Fn([f64; 3]) -> f64,
        active: impl Fn([usize; 3]) -> bool,
    ) -> (Vec<f64>, Vec<bool>) {
        (0..grid.node_count()).map(|k| grid.node_indices(k)).map(|n| (f(grid.position(n)), active(n))).unzip()
    }

    /// In three dimensions a linear field is recovered exactly, inside (full patches of eight
    /// cells) and at the material's boundary (incomplete patches extended), and a checkerboard of
    /// nodal values (±1 on alternate nodes) is averaged away by the cell centres.
    #[test]
    fn three_dimensional_linear_fields_are_recovered_and_checkerboards_smoothed_out() {
        let g = Grid::new([0.0, 0.0, 0.0], [0.5, 0.25, 0.2], [6, 6, 5]);
        let lin = |p: [f64; 3]| 3.0 + 2.0 * p[0] - 5.0 * p[1] + 7.0 * p[2];
        // Material in the lower 4 × 5 × 4 nodes only.
        let (dp, act) = field_3d(&g, lin, |n| n[0] <= 3 && n[1] <= 4 && n[2] <= 3);
        let pf = PatchField { grid: &g, start: [0; 3], count: g.nodes(), dp: &dp, active: &act };
        for x in [[0.1, 0.05, 0.02], [1.0, 0.6, 0.3], [1.45, 0.98, 0.59], [0.02, 0.9, 0.33], [1.4, 0.01, 0.11]] {
            let r = pf.recover(x).unwrap();
            assert!((r - lin(x)).abs() < 1e-12, "at {x:?}: {r} vs {}", lin(x));
        }
        let sign = |n: [usize; 3]| if (n[0] + n[1] + n[2]).is_multiple_of(2) { 1.0 } else { -1.0 };
        let dp: Vec<f64> = (0..g.node_count()).map(|k| 10.0 + sign(g.node_indices(k))).collect();
        let all = vec![true; g.node_count()];
        let pf = PatchField { grid: &g, start: [0; 3], count: g.nodes(), dp: &dp, active: &all };
        for x in [[0.62, 0.27, 0.41], [1.33, 0.41, 0.5], [0.05, 0.55, 0.93]] {
            assert!((pf.recover(x).unwrap() - 10.0).abs() < 1e-12);
        }
        // A block of the grid held by one rank: the node numbers are the block's.
        let (dp, act) = field_3d(&g, lin, |_| true);
        let (start, count) = ([2, 1, 1], [4, 5, 4]);
        let local = |v: &[f64]| -> Vec<f64> {
            (0..count.iter().product::<usize>())
                .map(|k| {
                    let n = indices_of(count, k);
                    v[g.node_number(std::array::from_fn(|d| n[d] + start[d]))]
                })
                .collect()
        };
        let block_dp = local(&dp);
        let block_act: Vec<bool> =
            local(&act.iter().map(|&a| a as u8 as f64).collect::<Vec<_>>()).iter().map(|&a| a > 0.0).collect();
        let pf = PatchField { grid: &g, start, count, dp: &block_dp, active: &block_act };
        let x = [1.6, 0.6, 0.45];
        assert!((pf.recover(x).unwrap() - lin(x)).abs() < 1e-12);
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
