//! Basis functions of the material point method: uGIMP ([003] Eqs. 13–15) and standard linear MPM.
//!
//! In 1D the GIMP function of node i for a particle at x_p with half-width l_p is the average of the
//! linear hat N_i over the particle domain [x_p − l_p, x_p + l_p]:
//!   S_i = (1/2l_p) ∫ N_i dx = (G(r + l_p) − G(r − l_p)) / 2l_p,   ∇S_i = (N(r + l_p) − N(r − l_p)) / 2l_p,
//! with r = x_p − x_i and G the antiderivative of the hat. In 2D the functions are products of the
//! 1D ones. Nodes outside the grid are dropped (the domain integral is over Ω_p ∩ Ω).

use super::grid::Grid;

/// Which basis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Basis {
    /// Undeformed GIMP.
    Gimp,
    /// Bilinear hat functions evaluated at the particle.
    Linear,
}

/// Hat function N(r) = max(0, 1 − |r|/h).
#[inline]
fn hat(r: f64, h: f64) -> f64 {
    (1.0 - r.abs() / h).max(0.0)
}

/// Antiderivative of the hat: G(s) = ∫_{−∞}^{s} N.
#[inline]
fn hat_integral(s: f64, h: f64) -> f64 {
    if s <= -h {
        0.0
    } else if s <= 0.0 {
        (s + h) * (s + h) / (2.0 * h)
    } else if s < h {
        h - (h - s) * (h - s) / (2.0 * h)
    } else {
        h
    }
}

/// 1D GIMP value and gradient for r = x_p − x_i ([003] Eqs. 13–14).
#[inline]
pub fn gimp_1d(r: f64, lp: f64, h: f64) -> (f64, f64) {
    let w = (hat_integral(r + lp, h) - hat_integral(r - lp, h)) / (2.0 * lp);
    let g = (hat(r + lp, h) - hat(r - lp, h)) / (2.0 * lp);
    (w, g)
}

/// Largest stencil: 4 × 4 nodes (a domain of one particle per cell touches the grid lines on both
/// sides; two or more particles per cell reach at most 3 × 3 nodes).
pub const MAX_STENCIL: usize = 16;

/// Nodes, weights and weight gradients of one particle.
#[derive(Debug, Clone, Copy)]
pub struct Stencil {
    /// Number of nodes used.
    pub len: usize,
    /// Global node indices (i, j).
    pub nodes: [(u32, u32); MAX_STENCIL],
    /// S_i.
    pub w: [f64; MAX_STENCIL],
    /// ∇S_i.
    pub dw: [[f64; 2]; MAX_STENCIL],
}

impl Default for Stencil {
    fn default() -> Self {
        Stencil { len: 0, nodes: [(0, 0); MAX_STENCIL], w: [0.0; MAX_STENCIL], dw: [[0.0; 2]; MAX_STENCIL] }
    }
}

impl Stencil {
    /// Iterates (node, S, ∇S).
    pub fn iter(&self) -> impl Iterator<Item = ((u32, u32), f64, [f64; 2])> + '_ {
        (0..self.len).map(move |k| (self.nodes[k], self.w[k], self.dw[k]))
    }
}

/// Weights of a particle at `x` along one direction: up to 4 (node, S, dS).
fn weights_1d(basis: Basis, x: f64, lp: f64, origin: f64, h: f64, ncells: usize) -> ([(u32, f64, f64); 4], usize) {
    let mut out = [(0u32, 0.0, 0.0); 4];
    let mut n = 0;
    match basis {
        Basis::Linear => {
            // The two nodes of the cell holding the particle (a particle on a grid line belongs to
            // the cell above it, or to the last cell), so that the gradients always sum to zero.
            // Points within round-off (1e-9 of a cell) of the grid's edge are on it.
            let s = (x - origin) / h;
            if !(s >= -1e-9 && s <= ncells as f64 + 1e-9) {
                return (out, 0);
            }
            let s = s.clamp(0.0, ncells as f64);
            let c = (s.floor() as usize).min(ncells - 1);
            let xi = s - c as f64;
            out[0] = (c as u32, 1.0 - xi, -1.0 / h);
            out[1] = (c as u32 + 1, xi, 1.0 / h);
            n = 2;
        }
        Basis::Gimp => {
            let tol = 1e-9 * h;
            let first = ((x - lp - tol - origin) / h).floor() as i64;
            let last = ((x + lp + tol - origin) / h).floor() as i64 + 1;
            for i in first.max(0)..=last.min(ncells as i64) {
                let r = x - (origin + i as f64 * h);
                // Nodes the particle domain only touches (weight exactly zero) are kept, so that the
                // stencil, and with it the matrix structure, does not change when the particle moves
                // by a hair across the grid line its domain ends on.
                if r.abs() <= h + lp + tol && n < 4 {
                    let (w, g) = gimp_1d(r, lp, h);
                    out[n] = (i as u32, w, g);
                    n += 1;
                }
            }
        }
    }
    (out, n)
}

/// Builds the stencil of a particle at `x` with half-widths `lp` on `grid`.
pub fn stencil(basis: Basis, grid: &Grid, x: [f64; 2], lp: [f64; 2]) -> Stencil {
    let (wx, nx) = weights_1d(basis, x[0], lp[0], grid.origin[0], grid.h[0], grid.cells[0]);
    let (wy, ny) = weights_1d(basis, x[1], lp[1], grid.origin[1], grid.h[1], grid.cells[1]);
    let mut s = Stencil::default();
    for &(j, sy, gy) in &wy[..ny] {
        for &(i, sx, gx) in &wx[..nx] {
            let k = s.len;
            s.nodes[k] = (i, j);
            s.w[k] = sx * sy;
            s.dw[k] = [gx * sy, sx * gy];
            s.len += 1;
        }
    }
    s
}

/// Linear hat weights at a point where a force acts (the centre of a loaded particle face). A
/// point up to half a cell outside the grid acts on the grid's edge nodes: a loaded surface that
/// coincides with the grid's edge moves across it by small amounts (e.g. in the tension half of
/// a cyclic load), and its load must not vanish then. Farther out there are no weights.
pub fn point_weights(grid: &Grid, x: [f64; 2]) -> Stencil {
    let lo = grid.origin;
    let hi = grid.extent_max();
    let mut y = x;
    for d in 0..2 {
        let half = 0.5 * grid.h[d];
        if x[d] < lo[d] - half || x[d] > hi[d] + half {
            return Stencil::default();
        }
        y[d] = x[d].clamp(lo[d], hi[d]);
    }
    stencil(Basis::Linear, grid, y, [0.0, 0.0])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid() -> Grid {
        Grid::new([0.0, 0.0], [0.5, 0.25], [10, 10])
    }

    #[test]
    fn gimp_matches_closed_form_in_every_region() {
        // Closed form of Bardenhagen & Kober (2004) for l_p ≤ h/2.
        let (h, lp) = (1.0, 0.25);
        let closed = |r: f64| -> (f64, f64) {
            let a = r.abs();
            let sg = r.signum();
            if a >= h + lp {
                (0.0, 0.0)
            } else if a >= h - lp {
                ((h + lp - a).powi(2) / (4.0 * h * lp), -sg * (h + lp - a) / (2.0 * h * lp))
            } else if a >= lp {
                (1.0 - a / h, -sg / h)
            } else {
                (1.0 - (r * r + lp * lp) / (2.0 * h * lp), -r / (h * lp))
            }
        };
        for k in -130..=130 {
            let r = k as f64 * 0.01 + 0.0031;
            let (w, g) = gimp_1d(r, lp, h);
            let (wc, gc) = closed(r);
            assert!((w - wc).abs() < 1e-12 && (g - gc).abs() < 1e-12, "r = {r}: ({w}, {g}) vs ({wc}, {gc})");
        }
    }

    #[test]
    fn points_within_round_off_of_the_grid_edge_get_weights() {
        let g = grid();
        let top = g.extent_max()[1];
        for y in [top, top * (1.0 + 1e-15), top - 1e-13] {
            let w = point_weights(&g, [1.1, y]);
            assert_eq!(w.len, 4, "y = {y:e}");
            assert!((w.iter().map(|(_, s, _)| s).sum::<f64>() - 1.0).abs() < 1e-12);
        }
        // A loaded face a little above the grid still loads the top nodes; far above, nothing.
        let w = point_weights(&g, [1.1, top + 1e-3]);
        assert!(
            w.len == 4
                && w.iter().filter(|((_, j), _, _)| *j as usize == g.cells[1]).map(|(_, s, _)| s).sum::<f64>()
                    > 0.999999
        );
        assert_eq!(point_weights(&g, [1.1, top + 0.6 * g.h[1]]).len, 0);
        // Particles themselves get no linear weights outside the grid.
        assert_eq!(stencil(Basis::Linear, &g, [1.1, top + 1e-3], [0.0; 2]).len, 0);
    }

    #[test]
    fn gradient_is_the_derivative_of_the_weight() {
        for &(lp, h) in &[(0.25, 1.0), (0.5, 1.0), (0.125, 0.5)] {
            for k in -60..=60 {
                let r = k as f64 * 0.0237;
                let e = 1e-6;
                let fd = (gimp_1d(r + e, lp, h).0 - gimp_1d(r - e, lp, h).0) / (2.0 * e);
                assert!((fd - gimp_1d(r, lp, h).1).abs() < 1e-6, "lp {lp} r {r}");
            }
        }
    }

    #[test]
    fn partition_of_unity_and_zero_gradient_sum_inside_the_grid() {
        let g = grid();
        for basis in [Basis::Gimp, Basis::Linear] {
            for k in 0..200 {
                let x = [0.6 + 3.7 * (k as f64 / 200.0), 0.3 + 1.8 * ((k * 7 % 200) as f64 / 200.0)];
                let s = stencil(basis, &g, x, [g.h[0] / 4.0, g.h[1] / 4.0]);
                let sum: f64 = s.iter().map(|(_, w, _)| w).sum();
                let gx: f64 = s.iter().map(|(_, _, d)| d[0]).sum();
                let gy: f64 = s.iter().map(|(_, _, d)| d[1]).sum();
                assert!((sum - 1.0).abs() < 1e-12 && gx.abs() < 1e-9 && gy.abs() < 1e-9, "{basis:?} at {x:?}");
                // Linear completeness: Σ S_i x_i = x_p.
                let xr: f64 = s.iter().map(|((i, _), w, _)| w * g.node_position(i as usize, 0)[0]).sum();
                assert!((xr - x[0]).abs() < 1e-12);
                // Σ ∇S_i x_i = 1.
                let dxx: f64 = s.iter().map(|((i, _), _, d)| d[0] * g.node_position(i as usize, 0)[0]).sum();
                assert!((dxx - 1.0).abs() < 1e-9);
            }
        }
    }

    #[test]
    fn gimp_reaches_across_cell_edges_and_keeps_touched_nodes() {
        let g = grid();
        // Particle close to a vertical cell edge: its GIMP support crosses it (3 nodes in x).
        let s = stencil(Basis::Gimp, &g, [0.5 + 0.01, 0.1], [0.125, 0.0625]);
        assert_eq!(s.len, 6);
        // A domain that only touches a grid line keeps the node beyond it, with zero weight.
        let s = stencil(Basis::Gimp, &g, [0.5 + 0.125, 0.1], [0.125, 0.0625]);
        assert_eq!(s.len, 6);
        assert!(
            s.iter().any(|((i, _), w, d)| i == 0 && w == 0.0 && d == [0.0, 0.0])
                || s.iter().any(|((i, _), w, _)| i == 1 && w == 0.0)
        );
        let s = stencil(Basis::Linear, &g, [0.5 + 0.01, 0.125], [0.125, 0.0625]);
        assert_eq!(s.len, 4);
        // One particle per cell: the domain is the cell and touches four lines: 4 × 4 nodes.
        let s = stencil(Basis::Gimp, &g, [0.75, 0.375], [0.25, 0.125]);
        assert_eq!(s.len, 16);
        assert!((s.iter().map(|(_, w, _)| w).sum::<f64>() - 1.0).abs() < 1e-12);
    }
}
