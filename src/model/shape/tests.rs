//! The bases' checks: partition of unity, linear fields, gradients against differences, the
//! edge-modified B-splines, the axisymmetric operators and the generic stencils.

use super::*;

#[test]
fn uniform_bsplines_are_partitions_of_unity_with_their_moments_and_derivatives() {
    // Σ_i N(s − i) = 1, Σ_i i N(s − i) = s and Σ_i i² N(s − i) = s² + (p + 1)/12 for the centred
    // B-spline of degree p; dN/dξ against central differences; C¹ at the knots.
    for degree in [2usize, 3] {
        for k in 0..=40 {
            let s = 3.0 + k as f64 / 40.0;
            let (mut m0, mut m1, mut m2, mut d0) = (0.0, 0.0, 0.0, 0.0);
            for i in 0..8 {
                let (w, g) = uniform_bspline(degree, s - i as f64);
                m0 += w;
                m1 += i as f64 * w;
                m2 += (i * i) as f64 * w;
                d0 += g;
                let e = 1e-6;
                let fd = (uniform_bspline(degree, s - i as f64 + e).0 - uniform_bspline(degree, s - i as f64 - e).0)
                    / (2.0 * e);
                // Central differences across a knot see the jump of the second derivative: O(e).
                assert!((fd - g).abs() < 1e-5, "degree {degree} s {s} node {i}: {g} vs {fd}");
            }
            assert!((m0 - 1.0).abs() < 1e-14 && d0.abs() < 1e-14, "degree {degree}: {m0} {d0}");
            assert!((m1 - s).abs() < 1e-13, "degree {degree}: first moment {m1} at {s}");
            let c = (degree as f64 + 1.0) / 12.0;
            assert!((m2 - s * s - c).abs() < 1e-12, "degree {degree}: second moment {m2} at {s}");
        }
        // C¹: the derivative is continuous at the knots (half-integers for p = 2, integers for 3).
        let knots: &[f64] = if degree == 2 { &[0.5, 1.5] } else { &[1.0, 2.0] };
        for &kn in knots {
            let (l, r) = (uniform_bspline(degree, kn - 1e-12), uniform_bspline(degree, kn + 1e-12));
            assert!((l.0 - r.0).abs() < 1e-10 && (l.1 - r.1).abs() < 1e-10, "degree {degree} knot {kn}");
        }
    }
}

#[test]
fn edge_modified_bsplines_keep_unity_and_linear_fields_up_to_the_edge() {
    // On grid lines of 1, 2, 3 and 7 cells, at points across the whole line (edges included):
    // Σ N = 1, Σ dN = 0, Σ x_i N_i = x, Σ x_i dN_i = 1, N ≥ 0, dN against central differences,
    // N₀ = 1 on the edge, and the quadratic basis equal to the linear hat on the edge's half cell.
    let h = 0.4;
    for degree in [2usize, 3] {
        for n in [1usize, 2, 3, 7] {
            for k in 0..=(40 * n) {
                let s = k as f64 / 40.0;
                let (w, len) = bspline_1d(degree, s, n, h);
                assert!((2..=4).contains(&len));
                let sum: f64 = w[..len].iter().map(|o| o.1).sum();
                let dsum: f64 = w[..len].iter().map(|o| o.2).sum();
                let x1: f64 = w[..len].iter().map(|o| o.0 as f64 * h * o.1).sum();
                let dx1: f64 = w[..len].iter().map(|o| o.0 as f64 * h * o.2).sum();
                assert!((sum - 1.0).abs() < 1e-14, "p {degree} n {n} s {s}: Σ N = {sum}");
                assert!(dsum.abs() < 1e-13, "p {degree} n {n} s {s}: Σ dN = {dsum}");
                assert!((x1 - s * h).abs() < 1e-14, "p {degree} n {n} s {s}: Σ x N = {x1}");
                assert!((dx1 - 1.0).abs() < 1e-13, "p {degree} n {n} s {s}: Σ x dN = {dx1}");
                for &(i, wi, gi) in &w[..len] {
                    assert!(wi >= -1e-15 && (i as usize) <= n, "p {degree} n {n} s {s}: N_{i} = {wi}");
                    if (s > 1e-3 && s < n as f64 - 1e-3) && (s * 2.0).fract().abs() > 1e-3 {
                        let e = 1e-7;
                        let at = |t: f64| {
                            let (v, l) = bspline_1d(degree, t, n, h);
                            v[..l].iter().find(|o| o.0 == i).map_or(0.0, |o| o.1)
                        };
                        let fd = (at(s + e) - at(s - e)) / (2.0 * e * h);
                        assert!((fd - gi).abs() < 1e-6, "p {degree} n {n} s {s} node {i}: {gi} vs {fd}");
                    }
                }
                if degree == 2 && (s <= 0.5 || n == 1) {
                    let n0 = w[..len].iter().find(|o| o.0 == 0).unwrap().1;
                    assert!((n0 - (1.0 - s).max(0.0)).abs() < 1e-14, "p 2 n {n} s {s}: N₀ = {n0}");
                }
            }
            for (s, node) in [(0.0, 0u32), (n as f64, n as u32)] {
                let (w, len) = bspline_1d(degree, s, n, h);
                for &(i, wi, _) in &w[..len] {
                    let want = if i == node { 1.0 } else { 0.0 };
                    assert!((wi - want).abs() < 1e-15, "p {degree} n {n}: N_{i}({s}) = {wi}");
                }
            }
        }
    }
    // Far from the edges the functions are the uniform ones.
    let (w, len) = bspline_1d(3, 3.3, 7, h);
    assert_eq!(len, 4);
    for &(i, wi, _) in &w[..len] {
        assert!((wi - uniform_bspline(3, 3.3 - i as f64).0).abs() < 1e-15);
    }
}

#[test]
fn bspline_stencils_reproduce_linear_fields_in_two_dimensions() {
    let g = Grid { origin: [-1.0, 0.5], h: [0.25, 0.2], cells: [8, 5] };
    for basis in [Basis::BSpline2, Basis::BSpline3] {
        for x in [[-1.0, 0.5], [-0.93, 0.61], [0.0, 1.5], [0.99, 1.45], [1.0, 1.3]] {
            let st = stencil(basis, &g, x, [0.05, 0.05]);
            let (mut sum, mut lin, mut grad) = (0.0, [0.0; 2], [[0.0; 2]; 2]);
            for ([i, j], w, dw) in st.iter() {
                let xi = [g.origin[0] + i as f64 * g.h[0], g.origin[1] + j as f64 * g.h[1]];
                sum += w;
                for a in 0..2 {
                    lin[a] += w * xi[a];
                    for b in 0..2 {
                        grad[a][b] += xi[a] * dw[b];
                    }
                }
            }
            assert!((sum - 1.0).abs() < 1e-14, "{basis:?} at {x:?}");
            assert!((lin[0] - x[0]).abs() < 1e-14 && (lin[1] - x[1]).abs() < 1e-14, "{basis:?} at {x:?}");
            for a in 0..2 {
                for b in 0..2 {
                    let want = if a == b { 1.0 } else { 0.0 };
                    assert!((grad[a][b] - want).abs() < 1e-13, "{basis:?} at {x:?}: {grad:?}");
                }
            }
        }
        // Outside the grid (beyond round-off) there is no stencil.
        assert_eq!(stencil(basis, &g, [-1.001, 0.6], [0.05, 0.05]).len, 0);
    }
}

#[test]
fn the_right_stretch_ignores_rotation_and_squares_to_ftf() {
    let (c, sn) = (0.6f64.cos(), 0.6f64.sin());
    let stretch = [[1.3, 0.2], [0.2, 0.7]];
    // F = R U with R a rotation by 0.6 rad.
    let f = [
        [c * stretch[0][0] - sn * stretch[1][0], c * stretch[0][1] - sn * stretch[1][1]],
        [sn * stretch[0][0] + c * stretch[1][0], sn * stretch[0][1] + c * stretch[1][1]],
    ];
    let u = right_stretch(f);
    for a in 0..2 {
        for b in 0..2 {
            assert!((u[a][b] - stretch[a][b]).abs() < 1e-12, "{u:?}");
        }
    }
    // Uniaxial compression: U = F.
    let u = right_stretch([[1.0, 0.0], [0.0, 0.82]]);
    assert!((u[0][0] - 1.0).abs() < 1e-15 && (u[1][1] - 0.82).abs() < 1e-15 && u[0][1].abs() < 1e-15);
}

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
fn face_weights_are_the_hat_functions_and_move_continuously() {
    let g = grid();
    let top = g.extent_max()[1];
    // A face on the grid's edge loads the edge nodes, also a hair beyond it.
    for y in [top, top * (1.0 + 1e-15)] {
        let w = face_weights(Basis::Gimp, &g, [1.1, y]);
        let edge: f64 = w.iter().filter(|([_, j], _, _)| *j as usize == g.cells[1]).map(|(_, s, _)| s).sum();
        assert!((edge - 1.0).abs() < 1e-12, "y = {y:e}: {edge}");
    }
    // Crossing the grid line y = 0.75 changes no weight by more than the motion.
    let (a, b) = (face_weights(Basis::Gimp, &g, [1.1, 0.75 - 1e-9]), face_weights(Basis::Gimp, &g, [1.1, 0.75 + 1e-9]));
    for j in 2..=4u32 {
        let on = |w: &Stencil| -> f64 { w.iter().filter(|([_, jj], _, _)| *jj == j).map(|(_, s, _)| s).sum() };
        assert!((on(&a) - on(&b)).abs() < 1e-7, "row {j}: {} vs {}", on(&a), on(&b));
    }
    assert!((a.iter().map(|(_, s, _)| s).sum::<f64>() - 1.0).abs() < 1e-12);
}

#[test]
fn face_weights_balance_the_gimp_internal_force_of_a_uniform_stress() {
    // ∫_Ω_p ∂S_i/∂y dV (GIMP, [003] Eq. 14 times V) equals the top-face weights minus the
    // bottom-face weights times the face length, for domains across a horizontal grid line.
    let g = grid();
    for (x, lp) in [([1.2, 0.74], [0.1, 0.05]), ([1.2, 0.78], [0.2, 0.03]), ([1.2, 0.9], [0.2, 0.1])] {
        let st = stencil(Basis::Gimp, &g, x, lp);
        let (top, bottom) =
            (face_weights(Basis::Gimp, &g, [x[0], x[1] + lp[1]]), face_weights(Basis::Gimp, &g, [x[0], x[1] - lp[1]]));
        let v = 4.0 * lp[0] * lp[1];
        for (node, _, dw) in st.iter() {
            let at = |w: &Stencil| w.iter().filter(|(n, _, _)| *n == node).map(|(_, s, _)| s).sum::<f64>();
            let expected = (at(&top) - at(&bottom)) * 2.0 * lp[0];
            assert!((dw[1] * v - expected).abs() < 1e-12, "{x:?} {node:?}: {} vs {expected}", dw[1] * v);
        }
    }
}

#[test]
fn volumetric_gradients_average_the_cell_centre_divergence() {
    let g = grid();
    for (basis, x, lp) in [
        (Basis::Gimp, [1.2, 0.6], [0.125, 0.0625]),
        (Basis::Gimp, [1.01, 0.51], [0.125, 0.0625]),
        (Basis::Linear, [1.3, 0.6], [0.0, 0.0]),
    ] {
        let mut st = stencil(basis, &g, x, lp);
        let gv = volumetric_operators(basis, &g, x, lp, &mut st, &|i, j| (i, j), false).0;
        // Σ ∇̄S_i = 0 and Σ ∇̄S_i ⊗ x_i = I: a linear displacement field gives its exact divergence.
        let sum: [f64; 2] = (0..st.len).fold([0.0; 2], |a, k| [a[0] + gv[k][0], a[1] + gv[k][1]]);
        assert!(sum[0].abs() < 1e-12 && sum[1].abs() < 1e-12, "{basis:?} {sum:?}");
        let mut m = [[0.0; 2]; 2];
        for (node, gk) in st.nodes[..st.len].iter().zip(&gv) {
            let p = g.node_position(node[0] as usize, node[1] as usize);
            for a in 0..2 {
                for b in 0..2 {
                    m[a][b] += gk[a] * p[b];
                }
            }
        }
        assert!(
            (m[0][0] - 1.0).abs() < 1e-12 && (m[1][1] - 1.0).abs() < 1e-12 && m[0][1].abs() < 1e-12,
            "{basis:?} {m:?}"
        );
    }
    // A domain inside one cell takes that cell's centre gradients: ±1/(2h).
    let mut st = stencil(Basis::Gimp, &g, [1.25, 0.625], [0.125, 0.0625]);
    let gv = volumetric_operators(Basis::Gimp, &g, [1.25, 0.625], [0.125, 0.0625], &mut st, &|i, j| (i, j), false).0;
    let k = st.nodes[..st.len].iter().position(|&n| n == [2, 2]).unwrap();
    assert!((gv[k][0] + 1.0).abs() < 1e-12 && (gv[k][1] + 2.0).abs() < 1e-12, "{:?}", gv[k]);
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
            let xr: f64 = s.iter().map(|([i, _], w, _)| w * g.node_position(i as usize, 0)[0]).sum();
            assert!((xr - x[0]).abs() < 1e-12);
            // Σ ∇S_i x_i = 1.
            let dxx: f64 = s.iter().map(|([i, _], _, d)| d[0] * g.node_position(i as usize, 0)[0]).sum();
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
        s.iter().any(|([i, _], w, d)| i == 0 && w == 0.0 && d == [0.0, 0.0])
            || s.iter().any(|([i, _], w, _)| i == 1 && w == 0.0)
    );
    let s = stencil(Basis::Linear, &g, [0.5 + 0.01, 0.125], [0.125, 0.0625]);
    assert_eq!(s.len, 4);
    // One particle per cell: the domain is the cell and touches four lines: 4 × 4 nodes.
    let s = stencil(Basis::Gimp, &g, [0.75, 0.375], [0.25, 0.125]);
    assert_eq!(s.len, 16);
    assert!((s.iter().map(|(_, w, _)| w).sum::<f64>() - 1.0).abs() < 1e-12);
}

/// Two points per cell and direction, at a quarter and three quarters of their cell: each domain
/// reaches the two nodes of its cell and only touches the one beyond. On grids whose spacing is not
/// a binary fraction (1/13, 1/7, 0.3) the touching edge lands a few ulps either side of the node's
/// support; the touched node must still carry exact zeros, or every stored stencil and the matrix
/// grow from 2 to 3 nodes per direction (3.4 times the nonzeros of a three-dimensional u–p matrix).
#[test]
fn a_domain_touching_a_support_by_round_off_has_exactly_zero_weight_there() {
    for (cells, size) in [(13usize, 1.0), (7, 1.0), (10, 3.0), (62, 1.0), (8, 1.0)] {
        let h = size / cells as f64;
        let lp = h / 4.0;
        for c in 0..cells {
            for q in [0.25, 0.75] {
                let x = (c as f64 + q) * h;
                let (out, n) = weights_1d(Basis::Gimp, x, lp, 0.0, h, cells);
                let reached = out[..n].iter().filter(|(_, w, g)| *w != 0.0 || *g != 0.0).count();
                assert_eq!(reached, 2, "{cells} cells of {h}: the point at {x} reaches {:?}", &out[..n]);
                let sum: f64 = out[..n].iter().map(|o| o.1).sum();
                let slope: f64 = out[..n].iter().map(|o| o.2).sum();
                assert!((sum - 1.0).abs() < 1e-14 && slope.abs() < 1e-12 / h, "{cells} cells: {sum} {slope}");
            }
        }
    }
}

/// The bilinear functions of a cell's four nodes sum to one with gradients summing to zero at
/// any point, and on a grid line the gradient is the one of the side asked for.
#[test]
fn bilinear_functions_are_a_partition_of_unity_with_one_sided_gradients() {
    let h = [0.1, 0.05];
    let nodes = [[0.0, 0.0], [0.1, 0.0], [0.0, 0.05], [0.1, 0.05]];
    let x = [0.037, 0.021];
    let (mut s, mut g) = (0.0, [0.0; 2]);
    for n in nodes {
        let (v, d) = bilinear(n, x, x, h);
        s += v;
        g[0] += d[0];
        g[1] += d[1];
    }
    assert!((s - 1.0).abs() < 1e-14 && g[0].abs() < 1e-12 && g[1].abs() < 1e-12, "{s} {g:?}");
    // On the line y = 0.05 the node at (0, 0.05) falls below it and rises above it.
    let on = [0.0, 0.05];
    let below = bilinear([0.0, 0.05], on, [0.0, 0.05 - 1e-9], h);
    let above = bilinear([0.0, 0.05], on, [0.0, 0.05 + 1e-9], h);
    assert_eq!(below.0, 1.0);
    assert!((below.1[1] - 20.0).abs() < 1e-12 && (above.1[1] + 20.0).abs() < 1e-12, "{below:?} {above:?}");
}

/// [`axisymmetric_stencil`] on a grid whose first node column is the axis, particles near
/// the axis and away from it, one and two per cell.
fn axisymmetric_samples() -> Vec<(Basis, AxisymmetricWeights, [f64; 2], [f64; 2])> {
    let mut out = Vec::new();
    for (basis, weights) in [
        (Basis::Gimp, AxisymmetricWeights::Planar),
        (Basis::Gimp, AxisymmetricWeights::RWeighted),
        (Basis::Linear, AxisymmetricWeights::Planar),
    ] {
        for (x, lp) in [
            ([0.025, 0.31], [0.025, 0.025]),
            ([0.075, 0.62], [0.025, 0.025]),
            ([0.55, 0.4], [0.05, 0.05]),
            ([1.237, 0.77], [0.025, 0.0125]),
        ] {
            out.push((basis, weights, x, lp));
        }
    }
    out
}

/// Axisymmetric strains of a linear field: for u_r = α + βr, u_y = γy the particle's
/// strains are exact, ε_rr = β, ε_yy = γ, ε_θθ = α/r_p + β, and Σ S_i = 1, for both GIMP options
/// and the linear basis.
#[test]
fn axisymmetric_strains_of_a_linear_field_are_exact() {
    let grid = Grid { origin: [0.0, 0.0], h: [0.1, 0.1], cells: [20, 20] };
    let (alpha, beta, gamma) = (3.0e-3, -2.0e-3, 5.0e-4);
    for (basis, weights, x, lp) in axisymmetric_samples() {
        let (st, hoop) = axisymmetric_stencil(basis, weights, &grid, x, lp);
        let (mut sum, mut err, mut eyy, mut ett) = (0.0, 0.0, 0.0, 0.0);
        for (k, t) in hoop.iter().enumerate().take(st.len) {
            let [i, j] = st.nodes[k];
            let (r, y) = (i as f64 * grid.h[0], j as f64 * grid.h[1]);
            let ur = alpha + beta * r;
            sum += st.w[k];
            err += st.dw[k][0] * ur;
            eyy += st.dw[k][1] * gamma * y;
            ett += t * ur;
        }
        let what = format!("{basis:?} {weights:?} at {x:?}");
        assert!((sum - 1.0).abs() < 1e-13, "{what}: Σ S = {sum}");
        assert!((err - beta).abs() < 1e-15, "{what}: ε_rr = {err:e}");
        assert!((eyy - gamma).abs() < 1e-15, "{what}: ε_yy = {eyy:e}");
        assert!((ett - (alpha / x[0] + beta)).abs() < 1e-14, "{what}: ε_θθ = {ett:e}");
    }
}

/// Option B's r-functions against their closed forms (docs/axisymmetry.md, "GIMP in r"): Σ G^r = 0,
/// the same hoop operator as Option A, and S^r = N_i(r_p) + n₁ l²/(3 r_p) for a domain inside one
/// cell (n₁ = ±1/h the hat's slope there).
#[test]
fn r_weighted_gimp_matches_its_closed_forms() {
    let h = 0.1;
    let (rp, lp) = (0.55, 0.025);
    let (mut gsum, mut ssum) = (0.0, 0.0);
    for i in 0..12 {
        let ri = i as f64 * h;
        let (s, g, t) = axisymmetric_gimp_r(rp, lp, ri, h);
        let (planar, _) = gimp_1d(rp - ri, lp, h);
        assert!((t - planar / rp).abs() < 1e-15, "node {i}: T = {t}, planar S/r_p = {}", planar / rp);
        let slope = if (rp - ri).abs() < h { -(rp - ri).signum() / h } else { 0.0 };
        let expected = if (rp - ri).abs() < h { hat(rp - ri, h) + slope * lp * lp / (3.0 * rp) } else { 0.0 };
        assert!((s - expected).abs() < 1e-15, "node {i}: S^r = {s}, closed form {expected}");
        gsum += g;
        ssum += s;
    }
    assert!(gsum.abs() < 1e-13 && (ssum - 1.0).abs() < 1e-14, "Σ G^r = {gsum}, Σ S^r = {ssum}");
}

/// The partition of unity of the local GIMP weights: the weights of all cells sum to 1
/// for a domain inside the grid, and a node's weights summed over the cells are its planar GIMP
/// weight (so a domain inside one cell has the planar weights there), to 1e-14.
#[test]
fn local_gimp_weights_add_up_to_the_planar_ones() {
    let grid = Grid { origin: [0.0, -1.0], h: [0.1, 0.05], cells: [20, 40] };
    for (x, lp) in [
        ([0.537, -0.512], [0.025, 0.0125]),
        ([0.5, -0.5], [0.05, 0.025]),
        ([0.612, -0.27], [0.0125, 0.0125]),
        ([1.2, 0.3], [0.05, 0.02]),
    ] {
        let (cells, n) = local_gimp(&grid, x, lp);
        let total: f64 = cells[..n].iter().flat_map(|c| c.1).sum();
        assert!((total - 1.0).abs() < 1e-14, "{x:?}: Σ S* = {total}");
        let planar = stencil(Basis::Gimp, &grid, x, lp);
        for (node, w, _) in planar.iter() {
            let sum: f64 = cells[..n]
                .iter()
                .flat_map(|&((ci, cj), s)| {
                    [((ci, cj), s[0]), ((ci + 1, cj), s[1]), ((ci, cj + 1), s[2]), ((ci + 1, cj + 1), s[3])]
                })
                .filter(|&(m, _)| [m.0, m.1] == node)
                .map(|(_, v)| v)
                .sum();
            assert!((sum - w).abs() < 1e-14, "{x:?}, node {node:?}: Σ_e S* = {sum}, GIMP {w}");
        }
    }
}

/// The bases in three dimensions: for every basis, at points across a grid of 3 × 2 × 4 cells
/// (edges and faces included, domains crossing grid lines), the stencil is a partition of unity
/// that reproduces linear fields, Σ S = 1, Σ ∇S = 0, Σ x_i S_i = x_p, Σ x_i ⊗ ∇S_i = I; its
/// gradient is the derivative of its values with respect to the point's position (central
/// differences, away from the kinks of the linear basis); B̄'s volumetric gradients reproduce
/// a linear field's gradient as well, Σ x_i ⊗ ∇̄S_i = I; the face weights are a partition of
/// unity that interpolates x; and a point of a plane z = const on a grid line sees the plane
/// stencil times its z weights.
#[test]
fn every_basis_reproduces_linear_fields_in_three_dimensions() {
    let g: Grid<3> = Grid::new([0.0, -0.5, 1.0], [0.5, 0.25, 0.4], [3, 2, 4]);
    let lp = [0.125, 0.0625, 0.1];
    // Domains inside the grid, some touching its faces or crossing grid lines; and, for the bases
    // whose support does not depend on a domain, points on the grid's faces and edges.
    let inner = [[0.3, -0.4, 1.3], [0.125, -0.0625, 2.5], [1.375, -0.25, 1.1], [0.74, -0.26, 2.21], [1.2, -0.07, 1.79]];
    let faces = [[0.0, 0.0, 2.6], [1.5, -0.5, 1.0], [1.5, 0.0, 2.6]];
    for basis in [Basis::Gimp, Basis::Linear, Basis::BSpline2, Basis::BSpline3] {
        let on_faces: &[[f64; 3]] = if basis == Basis::Gimp { &[] } else { &faces };
        for &x in inner.iter().chain(on_faces) {
            let st: Stencil<3, MAX_STENCIL_3D> = stencil_in(basis, &g, x, lp);
            assert!(st.len >= 8, "{basis:?} {x:?}: {} nodes", st.len);
            let sum: f64 = st.w[..st.len].iter().sum();
            assert!((sum - 1.0).abs() < 1e-14, "{basis:?} {x:?}: Σ S = {sum}");
            for d in 0..3 {
                let gsum: f64 = st.dw[..st.len].iter().map(|v| v[d]).sum();
                assert!(gsum.abs() < 1e-12, "{basis:?} {x:?}: Σ ∂S/∂x{d} = {gsum}");
                let xd: f64 = st.iter().map(|(n, w, _)| w * g.position(n.map(|i| i as usize))[d]).sum();
                assert!((xd - x[d]).abs() < 1e-14, "{basis:?} {x:?}: Σ x S = {xd}");
                for e in 0..3 {
                    let gx: f64 = st.iter().map(|(n, _, dw)| dw[e] * g.position(n.map(|i| i as usize))[d]).sum();
                    let want = if d == e { 1.0 } else { 0.0 };
                    assert!((gx - want).abs() < 1e-12, "{basis:?} {x:?}: Σ x{d} ∂S/∂x{e} = {gx}");
                }
            }
            // The gradient is the derivative of the values (the linear basis has kinks at the
            // grid lines: only strictly inside a cell).
            let inside = (0..3).all(|d| {
                let s = (x[d] - g.origin[d]) / g.h[d];
                (s - s.round()).abs() > 1e-3
            });
            // (Central differences need both sides inside the grid: not on its faces.)
            if inner.contains(&x) && (basis != Basis::Linear || inside) {
                for d in 0..3 {
                    let e = 1e-7;
                    let (mut xp, mut xm) = (x, x);
                    xp[d] += e;
                    xm[d] -= e;
                    let (sp, sm): (Stencil<3, MAX_STENCIL_3D>, Stencil<3, MAX_STENCIL_3D>) =
                        (stencil_in(basis, &g, xp, lp), stencil_in(basis, &g, xm, lp));
                    let at =
                        |s: &Stencil<3, MAX_STENCIL_3D>, n: [u32; 3]| s.iter().find(|o| o.0 == n).map_or(0.0, |o| o.1);
                    for (n, _, dw) in st.iter() {
                        let fd = (at(&sp, n) - at(&sm, n)) / (2.0 * e);
                        assert!((fd - dw[d]).abs() < 1e-5, "{basis:?} {x:?} node {n:?} d{d}: {} vs {fd}", dw[d]);
                    }
                }
            }
            // B̄'s volumetric gradients (no aggregation: every cell its own root).
            let mut stv = st;
            let (gv, _) = volumetric_operators_in(basis, &g, x, lp, &mut stv, &|c| c, false);
            for d in 0..3 {
                for e in 0..3 {
                    let sum: f64 = gv[..stv.len]
                        .iter()
                        .zip(&stv.nodes)
                        .map(|(gk, n)| gk[e] * g.position(n.map(|i| i as usize))[d])
                        .sum();
                    let want = if d == e { 1.0 } else { 0.0 };
                    assert!((sum - want).abs() < 1e-12, "{basis:?} {x:?}: Σ x{d} ∂̄S/∂x{e} = {sum}");
                }
            }
            // Face weights at the point.
            let f: Stencil<3, MAX_STENCIL_3D> = face_weights_in(basis, &g, x);
            let fsum: f64 = f.w[..f.len].iter().sum();
            assert!((fsum - 1.0).abs() < 1e-14, "{basis:?} {x:?}: face weights sum to {fsum}");
            for d in 0..3 {
                let xd: f64 = f.iter().map(|(n, w, _)| w * g.position(n.map(|i| i as usize))[d]).sum();
                assert!((xd - x[d]).abs() < 1e-14, "{basis:?} {x:?}: face weights give x{d} = {xd}");
            }
        }
        // A point on the grid plane z = 2.2 (node layer 3): the linear and GIMP weights of
        // that layer are the plane stencil's (z weight 1 for linear; for GIMP the domain's
        // share on each side).
        let (x2, l2) = ([0.74, -0.26], [0.125, 0.0625]);
        let plane = stencil(basis, &Grid::new([0.0, -0.5], [0.5, 0.25], [3, 2]), x2, l2);
        let solid: Stencil<3, MAX_STENCIL_3D> = stencil_in(basis, &g, [x2[0], x2[1], 2.2], [l2[0], l2[1], 0.1]);
        let (wz, nz) = weights_1d(basis, 2.2, 0.1, 1.0, 0.4, 4);
        for (n, w, dw) in plane.iter() {
            for &(k, sz, gz) in &wz[..nz] {
                let m = solid.iter().find(|o| o.0 == [n[0], n[1], k]).expect("the node is in the 3D stencil");
                assert!((m.1 - w * sz).abs() < 1e-15, "{basis:?}: {} vs {}", m.1, w * sz);
                assert!((m.2[0] - dw[0] * sz).abs() < 1e-13 && (m.2[2] - w * gz).abs() < 1e-13);
            }
        }
        assert_eq!(solid.len, plane.len * nz);
    }
}
