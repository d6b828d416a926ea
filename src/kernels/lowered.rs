//! The stiffness a point contributes to the preconditioning matrix of a one-phase solid with
//! `-porompm_pc_matrix multilinear` (docs/solvers.md, "A sparser matrix for the preconditioner"):
//! its material stiffness V B_aᵀ D_alg B_b on the multilinear functions of the grid cell that holds
//! it (Q1: the 2^D corners, gradients ∇N_a at x_p), and, for every other node of its stencil, the
//! diagonal block V B_iᵀ D_alg B_i of its own basis (so that a node the point reaches only
//! through its wider support keeps a positive diagonal of the right scale).
//!
//! The matrix is a low-order discretisation of the same operator on the same nodes (the way
//! high-order and spline discretisations are preconditioned by their linear relatives): it couples
//! a node with its 3^D neighbours instead of the (2r + 1)^D of a basis of support radius r (343
//! neighbours in three dimensions for GIMP and quadratic B-splines), so that algebraic multigrid
//! builds and applies its hierarchy on a matrix several times sparser than the Jacobian. The
//! Krylov method still multiplies by the exact Jacobian: the answers are the Jacobian's.
//!
//! Strain rows are those of [`crate::soils::stress::Stress`], engineering shears: [xx, yy, γxy,
//! zz, γyz, γzx]; a plane point's zz row is zero.

use crate::soils::stress::NS;

/// The rows of the strain operator of gradient `g` (B_i with ε = B_i u_i), [`NS`] × D.
#[inline]
pub fn strain_operator<const D: usize>(g: [f64; D]) -> [[f64; D]; NS] {
    let mut b = [[0.0; D]; NS];
    b[0][0] = g[0];
    b[1][1] = g[1];
    b[2][0] = g[1];
    b[2][1] = g[0];
    if D == 3 {
        b[3][2] = g[2];
        b[4][1] = g[2];
        b[4][2] = g[1];
        b[5][0] = g[2];
        b[5][2] = g[0];
    }
    b
}

/// V B_aᵀ D B_b, the D × D block of two strain operators.
#[inline]
pub fn pair_block<const D: usize>(
    ba: &[[f64; D]; NS],
    bb: &[[f64; D]; NS],
    d: &[[f64; NS]; NS],
    v: f64,
) -> [[f64; D]; D] {
    // D B_b first (NS × D), then B_aᵀ times it.
    let mut db = [[0.0; D]; NS];
    for (r, row) in db.iter_mut().enumerate() {
        for (s, bs) in bb.iter().enumerate() {
            let drs = d[r][s];
            if drs != 0.0 {
                for c in 0..D {
                    row[c] += drs * bs[c];
                }
            }
        }
    }
    let mut out = [[0.0; D]; D];
    for (r, ar) in ba.iter().enumerate() {
        for (i, &a) in ar.iter().enumerate() {
            if a != 0.0 {
                for c in 0..D {
                    out[i][c] += v * a * db[r][c];
                }
            }
        }
    }
    out
}

/// The nonzero entries of each column of a strain operator ([`strain_operator`]): the rows
/// (strain components) displacement component c enters and the gradient component each takes.
const COLUMNS_3D: [[(usize, usize); 3]; 3] =
    [[(0, 0), (2, 1), (5, 2)], [(1, 1), (2, 0), (4, 2)], [(3, 2), (4, 1), (5, 0)]];
const COLUMNS_2D: [[(usize, usize); 3]; 3] = [[(0, 0), (2, 1), (2, 1)], [(1, 1), (2, 0), (2, 0)], [(0, 0); 3]];

/// The cell block: V B_aᵀ D B_b for the cell's corners a, b (gradients `grads`, at most 2^D, in
/// the caller's corner order), row-major (n D)² into `out` for n corners. Each B has three
/// nonzeros per column (two in the plane), which the products take alone.
pub fn cell_block<const D: usize>(grads: &[[f64; D]], d: &[[f64; NS]; NS], v: f64, out: &mut [f64]) {
    let nc = grads.len();
    let n = nc * D;
    let (columns, used) = if D == 3 { (&COLUMNS_3D, 3) } else { (&COLUMNS_2D, 2) };
    // V D B_b, NS × D per corner.
    let mut db = [[[0.0; 3]; NS]; 8];
    for (b, g) in grads.iter().enumerate() {
        for (c, col) in columns.iter().enumerate().take(D) {
            for &(s, e) in &col[..used] {
                let x = v * g[e];
                for (r, row) in db[b].iter_mut().enumerate() {
                    row[c] += d[r][s] * x;
                }
            }
        }
    }
    for (a, g) in grads.iter().enumerate() {
        for (i, col) in columns.iter().enumerate().take(D) {
            let row = &mut out[(a * D + i) * n..(a * D + i + 1) * n];
            row.fill(0.0);
            for &(r, e) in &col[..used] {
                let x = g[e];
                for (b, dbb) in db.iter().enumerate().take(nc) {
                    for c in 0..D {
                        row[b * D + c] += x * dbb[r][c];
                    }
                }
            }
        }
    }
}

/// The multilinear functions' gradients of the corners of the cell whose lowest corner is at
/// `lo` (size `h`) at the point `x`, corner `c` at lo + h·bits(c) (bit d of c: the upper side in
/// direction d), [`crate::model::shape::multilinear`]'s gradient inside the cell; the first 2^D
/// entries are the corners'.
pub fn corner_gradients<const D: usize>(lo: [f64; D], h: [f64; D], x: [f64; D]) -> [[f64; D]; 8] {
    let xi: [f64; D] = std::array::from_fn(|d| ((x[d] - lo[d]) / h[d]).clamp(0.0, 1.0));
    std::array::from_fn(|c| {
        let n1: [f64; D] = std::array::from_fn(|d| if c >> d & 1 == 1 { xi[d] } else { 1.0 - xi[d] });
        let dn: [f64; D] = std::array::from_fn(|d| if c >> d & 1 == 1 { 1.0 / h[d] } else { -1.0 / h[d] });
        std::array::from_fn(|d| (0..D).fold(dn[d], |p, e| if e == d { p } else { p * n1[e] }))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An isotropic elastic D (engineering shears) of Young's modulus e and Poisson's ratio nu.
    fn elastic(e: f64, nu: f64) -> [[f64; NS]; NS] {
        let l = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
        let g = e / (2.0 * (1.0 + nu));
        let mut d = [[0.0; NS]; NS];
        for &i in &[0, 1, 3] {
            for &j in &[0, 1, 3] {
                d[i][j] = l;
            }
            d[i][i] += 2.0 * g;
        }
        for &i in &[2, 4, 5] {
            d[i][i] = g;
        }
        d
    }

    #[test]
    fn the_cell_block_is_the_energy_of_a_linear_field_and_annihilates_rigid_motions() {
        let (lo, h, x) = ([0.5, 1.0, -0.25], [0.5, 0.25, 0.75], [0.6, 1.2, 0.1]);
        let g = corner_gradients(lo, h, x);
        let g = &g[..8];
        // The gradients sum to zero (partition of unity) and reproduce a linear field's gradient.
        for d in 0..3 {
            assert!(g.iter().map(|gi| gi[d]).sum::<f64>().abs() < 1e-12);
        }
        let corner = |c: usize| -> [f64; 3] { std::array::from_fn(|d| lo[d] + h[d] * (c >> d & 1) as f64) };
        let grad_u = [[1e-3, 2e-3, -1e-3], [4e-4, -3e-3, 5e-4], [2e-4, 1e-4, 6e-4]];
        let u: Vec<f64> = (0..8)
            .flat_map(|c| {
                let xc = corner(c);
                (0..3).map(move |i| (0..3).map(|j| grad_u[i][j] * xc[j]).sum::<f64>())
            })
            .collect();
        let mut recovered = [[0.0; 3]; 3];
        for (c, gc) in g.iter().enumerate() {
            for i in 0..3 {
                for j in 0..3 {
                    recovered[i][j] += u[c * 3 + i] * gc[j];
                }
            }
        }
        for i in 0..3 {
            for j in 0..3 {
                assert!((recovered[i][j] - grad_u[i][j]).abs() < 1e-15, "{i}{j}");
            }
        }
        let (d, v) = (elastic(1e8, 0.3), 0.02);
        let mut k = vec![0.0; 24 * 24];
        cell_block(g, &d, v, &mut k);
        // uᵀ K u = V εᵀ D ε for the linear field.
        let eps = [
            grad_u[0][0],
            grad_u[1][1],
            grad_u[0][1] + grad_u[1][0],
            grad_u[2][2],
            grad_u[1][2] + grad_u[2][1],
            grad_u[2][0] + grad_u[0][2],
        ];
        let energy: f64 = (0..6).map(|r| (0..6).map(|s| eps[r] * d[r][s] * eps[s]).sum::<f64>()).sum::<f64>() * v;
        let uku: f64 = (0..24).map(|a| (0..24).map(|b| u[a] * k[a * 24 + b] * u[b]).sum::<f64>()).sum();
        assert!((uku - energy).abs() < 1e-12 * energy.abs(), "{uku} against {energy}");
        // Symmetric, and a rigid rotation about z (u = ω × x) costs nothing.
        for a in 0..24 {
            for b in 0..24 {
                assert!((k[a * 24 + b] - k[b * 24 + a]).abs() < 1e-9 * k[a * 24 + a].abs());
            }
        }
        let rot: Vec<f64> = (0..8).flat_map(|c| [-corner(c)[1], corner(c)[0], 0.0]).collect();
        for a in 0..24 {
            let f: f64 = (0..24).map(|b| k[a * 24 + b] * rot[b]).sum();
            assert!(f.abs() < 1e-6, "row {a}: {f}");
        }
    }

    /// [`cell_block`] against the dense products of [`pair_block`], with a D of no symmetry.
    fn cell_block_is_the_dense_product<const D: usize>() {
        let mut d = elastic(3e7, 0.45);
        for (r, row) in d.iter_mut().enumerate() {
            for (s, x) in row.iter_mut().enumerate() {
                *x += 1e6 * ((r * 7 + s * 3) % 5) as f64;
            }
        }
        let lo = [0.1; D];
        let h = std::array::from_fn(|e| 0.2 + 0.1 * e as f64);
        let x = std::array::from_fn(|e| 0.13 + 0.07 * e as f64);
        let g = corner_gradients::<D>(lo, h, x);
        let g = &g[..1 << D];
        let n = g.len() * D;
        let mut k = vec![0.0; n * n];
        cell_block(g, &d, 0.7, &mut k);
        for (a, ga) in g.iter().enumerate() {
            for (b, gb) in g.iter().enumerate() {
                let want = pair_block(&strain_operator(*ga), &strain_operator(*gb), &d, 0.7);
                for i in 0..D {
                    for c in 0..D {
                        let got = k[(a * D + i) * n + b * D + c];
                        assert!((got - want[i][c]).abs() <= 1e-9 * want[i][c].abs().max(1.0), "{a}{b}{i}{c}");
                    }
                }
            }
        }
    }

    #[test]
    fn the_cell_block_is_the_dense_product_in_the_plane_and_in_three_dimensions() {
        cell_block_is_the_dense_product::<2>();
        cell_block_is_the_dense_product::<3>();
    }

    #[test]
    fn a_plane_operator_has_no_out_of_plane_rows() {
        let b = strain_operator([2.0, 3.0]);
        assert_eq!(b[0], [2.0, 0.0]);
        assert_eq!(b[1], [0.0, 3.0]);
        assert_eq!(b[2], [3.0, 2.0]);
        assert!(b[3..].iter().all(|r| *r == [0.0, 0.0]));
        let k = pair_block(&b, &b, &elastic(1.0, 0.0), 1.0);
        // ν = 0: D = diag(1, 1, 1/2, 1, …): K = [[4 + 9/2, 3], [3, 9 + 2]].
        assert_eq!(k, [[4.0 + 4.5, 3.0], [3.0, 9.0 + 2.0]]);
    }
}
