//! The composite-MPM (CMPM) patch functions of [001] §5.5 for stress recovery: the strain at a
//! particle from a higher-order Lagrange interpolation over the particle's cell and its neighbours
//! ([001] Eqs. 21–24). In each direction the patch is cubic
//! (a neighbour cell on both sides: nodes at ξ = −3, −1, 1, 3 in the local coordinate of the
//! particle's cell, [001] Eq. 22), quadratic (one neighbour: nodes −1, 1, 3 or −3, −1, 1, the
//! corrected [001] Eq. 23) or linear (none). The functions are negative in places: they recover
//! strains, they never map mass or momentum.
//!
//! `assembly::stencils::cmpm_patches` builds each point's patch from them
//! (`stabilisation.stress_recovery = "cmpm"`); the tests below check that the functions are a
//! partition of unity and reproduce polynomials of their degree.

/// Which 1D patch a direction uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Patch1d {
    /// Neighbours on both sides: nodes ξ = −3, −1, 1, 3 ([001] Eq. 22).
    Cubic,
    /// A neighbour on the + side only: nodes ξ = −1, 1, 3 ([001] Eq. 23, corrected).
    QuadraticPlus,
    /// A neighbour on the − side only: nodes ξ = −3, −1, 1 (the mirror of Eq. 23).
    QuadraticMinus,
    /// No neighbour: the cell's own nodes ξ = −1, 1.
    Linear,
}

impl Patch1d {
    /// The patch's nodes in the local coordinate ξ of the particle's cell, in increasing order.
    pub fn nodes(self) -> &'static [f64] {
        match self {
            Patch1d::Cubic => &[-3.0, -1.0, 1.0, 3.0],
            Patch1d::QuadraticPlus => &[-1.0, 1.0, 3.0],
            Patch1d::QuadraticMinus => &[-3.0, -1.0, 1.0],
            Patch1d::Linear => &[-1.0, 1.0],
        }
    }
}

/// The patch functions and their derivatives d/dξ at `xi` (the first `patch.nodes().len()`
/// entries, in the order of [`Patch1d::nodes`]), in the closed forms of [001] Eq. 22 and of the
/// corrected Eq. 23 (the printed third entry of Eq. 23 belongs to the nodes −3, −1, 1 and breaks
/// the partition of unity; the correct one is (ξ² − 1)/8). The physical derivative is (2/h) d/dξ.
pub fn functions(patch: Patch1d, xi: f64) -> ([f64; 4], [f64; 4]) {
    let (x, x2, x3) = (xi, xi * xi, xi * xi * xi);
    match patch {
        Patch1d::Cubic => (
            [
                -(x3 - 3.0 * x2 - x + 3.0) / 48.0,
                (x3 - x2 - 9.0 * x + 9.0) / 16.0,
                (-x3 - x2 + 9.0 * x + 9.0) / 16.0,
                (x3 + 3.0 * x2 - x - 3.0) / 48.0,
            ],
            [
                -(3.0 * x2 - 6.0 * x - 1.0) / 48.0,
                (3.0 * x2 - 2.0 * x - 9.0) / 16.0,
                (-3.0 * x2 - 2.0 * x + 9.0) / 16.0,
                (3.0 * x2 + 6.0 * x - 1.0) / 48.0,
            ],
        ),
        Patch1d::QuadraticPlus => (
            [(x2 - 4.0 * x + 3.0) / 8.0, (-x2 + 2.0 * x + 3.0) / 4.0, (x2 - 1.0) / 8.0, 0.0],
            [(x - 2.0) / 4.0, (1.0 - x) / 2.0, x / 4.0, 0.0],
        ),
        Patch1d::QuadraticMinus => (
            [(x2 - 1.0) / 8.0, -(x + 3.0) * (x - 1.0) / 4.0, (x + 1.0) * (x + 3.0) / 8.0, 0.0],
            [x / 4.0, -(x + 1.0) / 2.0, (x + 2.0) / 4.0, 0.0],
        ),
        Patch1d::Linear => ([(1.0 - x) / 2.0, (1.0 + x) / 2.0, 0.0, 0.0], [-0.5, 0.5, 0.0, 0.0]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const PATCHES: [Patch1d; 4] = [Patch1d::Cubic, Patch1d::QuadraticPlus, Patch1d::QuadraticMinus, Patch1d::Linear];

    /// The Lagrange polynomial of node `j` of `nodes` at `xi` ([001] Eq. 21), for the cross-check.
    fn lagrange(nodes: &[f64], j: usize, xi: f64) -> f64 {
        nodes.iter().enumerate().filter(|&(m, _)| m != j).map(|(_, &xm)| (xi - xm) / (nodes[j] - xm)).product()
    }

    fn points() -> impl Iterator<Item = f64> {
        (0..=10).map(|k| -1.0 + 0.2 * k as f64)
    }

    /// The partition of unity: at 11 points of [−1, 1] the functions of every patch sum to 1 and
    /// their derivatives to 0 (1e-14), each is the Lagrange polynomial of its node, and they
    /// reproduce ξ³ (cubic), ξ² (quadratic) and ξ (linear) with their derivatives exactly.
    #[test]
    fn patch_functions_are_a_partition_of_unity_and_reproduce_their_degree() {
        for patch in PATCHES {
            let nodes = patch.nodes();
            let degree = nodes.len() as i32 - 1;
            for xi in points() {
                let (n, d) = functions(patch, xi);
                let m = nodes.len();
                assert!((n[..m].iter().sum::<f64>() - 1.0).abs() < 1e-14, "{patch:?} at {xi}: Σ N");
                assert!(d[..m].iter().sum::<f64>().abs() < 1e-14, "{patch:?} at {xi}: Σ N'");
                for (j, &nj) in n[..m].iter().enumerate() {
                    assert!((nj - lagrange(nodes, j, xi)).abs() < 1e-14, "{patch:?} node {j} at {xi}");
                }
                let f: f64 = n[..m].iter().zip(nodes).map(|(a, x)| a * x.powi(degree)).sum();
                let g: f64 = d[..m].iter().zip(nodes).map(|(a, x)| a * x.powi(degree)).sum();
                assert!((f - xi.powi(degree)).abs() < 1e-13, "{patch:?} at {xi}: ξ^{degree} → {f}");
                let exact = degree as f64 * xi.powi(degree - 1);
                assert!((g - exact).abs() < 1e-13, "{patch:?} at {xi}: (ξ^{degree})' → {g}");
            }
        }
    }

    /// The third entry of [001] Eq. 23 as printed, (ξ² + 4ξ + 3)/8, with the first two: their sum
    /// is (ξ + 3)/2, not 1, so the printed equation must fail the partition of unity that the
    /// corrected one passes.
    #[test]
    fn the_printed_equation_23_is_not_a_partition_of_unity() {
        let printed =
            |x: f64| [(x * x - 4.0 * x + 3.0) / 8.0, (-x * x + 2.0 * x + 3.0) / 4.0, (x * x + 4.0 * x + 3.0) / 8.0];
        let worst = points().map(|x| (printed(x).iter().sum::<f64>() - 1.0).abs()).fold(0.0, f64::max);
        assert!(worst > 0.5, "the printed Eq. 23 sums to 1 within {worst}");
        for x in points() {
            assert!((printed(x).iter().sum::<f64>() - (x + 3.0) / 2.0).abs() < 1e-14);
        }
    }
}
