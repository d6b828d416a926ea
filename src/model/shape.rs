//! Basis functions of the material point method: uGIMP ([003] Eqs. 13–15), standard linear MPM, and
//! quadratic and cubic B-splines ([002] §2.2.1).
//!
//! In 1D the GIMP function of node i for a particle at x_p with half-width l_p is the average of the
//! linear hat N_i over the particle domain [x_p − l_p, x_p + l_p]:
//!   S_i = (1/2l_p) ∫ N_i dx = (G(r + l_p) − G(r − l_p)) / 2l_p,   ∇S_i = (N(r + l_p) − N(r − l_p)) / 2l_p,
//! with r = x_p − x_i and G the antiderivative of the hat. In 2D the functions are products of the
//! 1D ones. Nodes outside the grid are dropped (the domain integral is over Ω_p ∩ Ω).

use super::grid::Grid;
use crate::algebra::right_stretch;

/// Which basis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Basis {
    /// Undeformed GIMP.
    Gimp,
    /// Bilinear hat functions evaluated at the particle.
    Linear,
    /// Quadratic B-splines centred on the nodes (C¹, three nodes per direction), with the
    /// boundary treatment of [`bspline_1d`].
    BSpline2,
    /// Cubic B-splines centred on the nodes (C², four nodes per direction), with the boundary
    /// treatment of [`bspline_1d`].
    BSpline3,
}

impl Basis {
    /// Whether the basis is a B-spline (its support does not depend on the particle domain).
    pub fn is_bspline(&self) -> bool {
        matches!(self, Basis::BSpline2 | Basis::BSpline3)
    }
}

/// The uniform B-spline of degree 2 or 3 centred on a node, N(ξ) and dN/dξ at ξ = (x − x_i)/h
/// ([002] §2.2.1):
///   quadratic: 3/4 − ξ² for |ξ| < 1/2, ½(3/2 − |ξ|)² for 1/2 ≤ |ξ| < 3/2;
///   cubic: ½|ξ|³ − ξ² + 2/3 for |ξ| < 1, (2 − |ξ|)³/6 for 1 ≤ |ξ| < 2; 0 beyond.
#[inline]
pub fn uniform_bspline(degree: usize, xi: f64) -> (f64, f64) {
    let a = xi.abs();
    let sg = if xi < 0.0 { -1.0 } else { 1.0 };
    match degree {
        2 if a < 0.5 => (0.75 - xi * xi, -2.0 * xi),
        2 if a < 1.5 => (0.5 * (1.5 - a) * (1.5 - a), -sg * (1.5 - a)),
        3 if a < 1.0 => (0.5 * a * a * a - xi * xi + 2.0 / 3.0, 1.5 * xi * a - 2.0 * xi),
        3 if a < 2.0 => ((2.0 - a).powi(3) / 6.0, -0.5 * sg * (2.0 - a) * (2.0 - a)),
        _ => (0.0, 0.0),
    }
}

/// The B-spline basis of degree 2 or 3 of the nodes 0..=n of a grid line of n cells (spacing h,
/// ξ measured in cells from node 0), at the point `s` ∈ [0, n]: up to four (node, N, dN/dx).
///
/// Boundary treatment: uniform B-splines centred on the nodes would need a ghost node −1 (and
/// n + 1) beyond each end of the grid; its function is folded into the first two nodes by linear
/// extrapolation, u₋₁ = 2u₀ − u₁, i.e. N₀ += 2N₋₁ and N₁ −= N₋₁ (the node beyond −1 does not reach
/// into the grid for either degree). The basis then keeps the partition of unity and reproduces
/// linear fields exactly up to the edge, every function stays non-negative, and it is
/// interpolatory at the edge (N₀(0) = 1, all others 0), so a condition on the edge's nodes holds on
/// the edge itself, as with the linear and GIMP bases. On the edge's half cell the quadratic basis
/// is the linear hat; in a direction of one cell both degrees reduce to it (two functions that
/// reproduce 1 and x). The uniform functions are used in the interior (quadratic B-spline MPM as in
/// Steffen, Kirby & Berzins 2008; [002] uses them on a grid extended beyond the material).
pub fn bspline_1d(degree: usize, s: f64, n: usize, h: f64) -> ([(u32, f64, f64); 4], usize) {
    // Candidate nodes, ghosts included: quadratic the three nodes nearest s, cubic the four of
    // the cell holding s and its neighbours (weights may be zero at the ends of the support, which
    // keeps the stencil's shape fixed while the particle moves inside a cell).
    let (first, count) = match degree {
        2 => ((s + 0.5).floor() as i64 - 1, 3),
        _ => ((s.floor() as i64).min(n as i64 - 1) - 1, 4),
    };
    let mut raw = [(0i64, 0.0, 0.0); 4];
    for (k, r) in raw.iter_mut().enumerate().take(count) {
        let i = first + k as i64;
        let (w, g) = uniform_bspline(degree, s - i as f64);
        *r = (i, w, g / h);
    }
    let mut out = [(0u32, 0.0, 0.0); 4];
    let mut len = 0;
    let mut add = |i: i64, w: f64, g: f64, out: &mut [(u32, f64, f64); 4]| {
        let i = i as u32;
        match out[..len].iter().position(|o| o.0 == i) {
            Some(k) => {
                out[k].1 += w;
                out[k].2 += g;
            }
            None => {
                out[len] = (i, w, g);
                len += 1;
            }
        }
    };
    // Interior nodes first, in order, so that folded ghosts add to existing entries.
    for &(i, w, g) in &raw[..count] {
        if (0..=n as i64).contains(&i) {
            add(i, w, g, &mut out);
        }
    }
    for &(i, w, g) in &raw[..count] {
        let (edge, next) = if i < 0 {
            (0, 1)
        } else if i > n as i64 {
            (n as i64, n as i64 - 1)
        } else {
            continue;
        };
        add(edge, 2.0 * w, 2.0 * g, &mut out);
        add(next, -w, -g, &mut out);
    }
    out[..len].sort_by_key(|o| o.0);
    (out, len)
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

/// Largest stencil of a two-dimensional point: 4 × 4 nodes (a domain of one particle per cell
/// touches the grid lines on both sides; two or more particles per cell reach at most 3 × 3 nodes),
/// plus the nodes of B̄'s root cells outside them (a 5 × 5 box at most).
pub const MAX_STENCIL: usize = 25;

/// Largest stencil of a three-dimensional point: the 5 × 5 × 5 box of [`MAX_STENCIL`]'s argument.
pub const MAX_STENCIL_3D: usize = 125;

/// Nodes, weights and weight gradients of one particle in `D` dimensions, at most `M` nodes
/// (two-dimensional, [`MAX_STENCIL`], unless said otherwise).
#[derive(Debug, Clone, Copy)]
pub struct Stencil<const D: usize = 2, const M: usize = MAX_STENCIL> {
    /// Number of nodes used.
    pub len: usize,
    /// Node indices per direction.
    pub nodes: [[u32; D]; M],
    /// S_i.
    pub w: [f64; M],
    /// ∇S_i.
    pub dw: [[f64; D]; M],
}

impl<const D: usize, const M: usize> Default for Stencil<D, M> {
    fn default() -> Self {
        Stencil { len: 0, nodes: [[0; D]; M], w: [0.0; M], dw: [[0.0; D]; M] }
    }
}

impl<const D: usize, const M: usize> Stencil<D, M> {
    /// Iterates (node, S, ∇S).
    pub fn iter(&self) -> impl Iterator<Item = ([u32; D], f64, [f64; D])> + '_ {
        (0..self.len).map(move |k| (self.nodes[k], self.w[k], self.dw[k]))
    }

    /// The slot of `node`, appended with zero weight and gradient if it is not in the stencil
    /// (`None` when the stencil is full).
    fn slot(&mut self, node: [u32; D]) -> Option<usize> {
        match self.nodes[..self.len].iter().position(|&n| n == node) {
            Some(k) => Some(k),
            None if self.len < M => {
                self.nodes[self.len] = node;
                self.w[self.len] = 0.0;
                self.dw[self.len] = [0.0; D];
                self.len += 1;
                Some(self.len - 1)
            }
            None => None,
        }
    }
}

/// Up to four (node index, value, derivative) along one direction, and how many.
type Weights1d = ([(u32, f64, f64); 4], usize);

/// The value and gradient of a product of one-dimensional functions, Π_d v_d and, in direction
/// d, dv_d Π_{e≠d} v_e (the factors multiplied in the order of the directions).
fn product_rule<const D: usize>(v: [f64; D], dv: [f64; D]) -> (f64, [f64; D]) {
    let value = v.iter().skip(1).fold(v[0], |acc, x| acc * x);
    (value, std::array::from_fn(|d| (0..D).filter(|&e| e != d).fold(dv[d], |acc, e| acc * v[e])))
}

/// Moves the multi-index `at` to the next combination of `counts[d]` choices per direction, x
/// fastest; `false` when every combination has been visited (`at` is then back at zero).
pub(crate) fn next_combination<const D: usize>(at: &mut [usize; D], counts: [usize; D]) -> bool {
    for d in 0..D {
        at[d] += 1;
        if at[d] < counts[d] {
            return true;
        }
        at[d] = 0;
    }
    false
}

/// The tensor product of per-direction lists of (index, value, derivative): every combination,
/// x fastest, with the product of the values and, in direction d, the derivative in d times the
/// other directions' values.
fn tensor_product<const D: usize, const M: usize>(per: &[Weights1d; D]) -> Stencil<D, M> {
    let mut s = Stencil::default();
    let counts = per.map(|p| p.1);
    if counts.contains(&0) {
        return s;
    }
    let mut at = [0usize; D];
    loop {
        let k = s.len;
        let entry = |d: usize| per[d].0[at[d]];
        s.nodes[k] = std::array::from_fn(|d| entry(d).0);
        (s.w[k], s.dw[k]) = product_rule(std::array::from_fn(|d| entry(d).1), std::array::from_fn(|d| entry(d).2));
        s.len += 1;
        if !next_combination(&mut at, counts) {
            return s;
        }
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
        Basis::BSpline2 | Basis::BSpline3 => {
            // As for the linear basis, points within round-off of the grid's edge are on it.
            let s = (x - origin) / h;
            if !(s >= -1e-9 && s <= ncells as f64 + 1e-9) {
                return (out, 0);
            }
            let degree = if basis == Basis::BSpline2 { 2 } else { 3 };
            return bspline_1d(degree, s.clamp(0.0, ncells as f64), ncells, h);
        }
        Basis::Gimp => {
            let tol = 1e-9 * h;
            // The round-off of r = x − x_i: a domain whose edge lies within it of a node's support
            // only touches that node (below).
            let round_off = 16.0 * f64::EPSILON * (x.abs() + origin.abs() + h);
            let first = ((x - lp - tol - origin) / h).floor() as i64;
            let last = ((x + lp + tol - origin) / h).floor() as i64 + 1;
            for i in first.max(0)..=last.min(ncells as i64) {
                let r = x - (origin + i as f64 * h);
                // Nodes the particle domain only touches (weight exactly zero) are kept, so that the
                // stencil's shape does not change when the particle moves by a hair across the grid
                // line its domain ends on (a step's stored stencils leave them out where no other
                // operator needs them, `assembly::stencils::only_reached_nodes`). A domain whose
                // edge lies within the round-off of r = x − x_i of the node's support touches it
                // (on grids whose spacing is not a binary fraction, h = 1/13, the edges of points
                // at rest land a few ulps either side): its weight and gradient, of the order of
                // the round-off and its square, are set to exact zeros, so that the stencil does
                // not grow by round-off from 2 to 3 nodes per direction.
                if r.abs() <= h + lp + tol && n < 4 {
                    let touched = r.abs() >= h + lp - round_off;
                    let (w, g) = if touched { (0.0, 0.0) } else { gimp_1d(r, lp, h) };
                    out[n] = (i as u32, w, g);
                    n += 1;
                }
            }
        }
    }
    (out, n)
}

/// The diagonal of the right stretch tensor U = sqrt(FᵀF) of a deformation gradient of any
/// dimension: [`right_stretch`]'s in two dimensions, through the principal frame of C = FᵀF in
/// three (U_dd = Σ_k sqrt(λ_k) (e_k)_d²).
pub fn stretch_diagonal<const D: usize>(f: &[[f64; D]; D]) -> [f64; D] {
    if D == 2 {
        let u = right_stretch([[f[0][0], f[0][1]], [f[1][0], f[1][1]]]);
        return std::array::from_fn(|d| u[d][d]);
    }
    let c = |a: usize, b: usize| (0..D).map(|k| f[k][a] * f[k][b]).sum::<f64>();
    let pr = crate::soils::principal::Principal::of(&[c(0, 0), c(1, 1), c(0, 1), c(2, 2), c(1, 2), c(2, 0)]);
    std::array::from_fn(|d| (0..3).map(|k| pr.values[k].max(0.0).sqrt() * pr.vectors[k][d] * pr.vectors[k][d]).sum())
}

/// Builds the stencil of a particle at `x` with half-widths `lp` on a grid of any dimension: the
/// tensor product of [`weights_1d`] in each direction.
pub fn stencil_in<const D: usize, const M: usize>(
    basis: Basis,
    grid: &Grid<D>,
    x: [f64; D],
    lp: [f64; D],
) -> Stencil<D, M> {
    let per = std::array::from_fn(|d| weights_1d(basis, x[d], lp[d], grid.origin[d], grid.h[d], grid.cells[d]));
    tensor_product(&per)
}

/// Builds the stencil of a particle at `x` with half-widths `lp` on a two-dimensional `grid`.
pub fn stencil(basis: Basis, grid: &Grid, x: [f64; 2], lp: [f64; 2]) -> Stencil {
    stencil_in(basis, grid, x, lp)
}

/// The geometry of an analysis: plane strain, axial symmetry about the y axis (x ≡ r ≥ 0) with
/// the particle weights of [`AxisymmetricWeights`], or three dimensions.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Geometry {
    /// Plane strain: volumes per metre of thickness, no hoop strain.
    PlaneStrain,
    /// Axial symmetry: ring volumes 2πrA and the hoop strain u_r/r.
    Axisymmetric(AxisymmetricWeights),
    /// Three dimensions: volumes in m³.
    Solid,
}

impl Geometry {
    /// The measure of a unit of (x, y) area or length at radius `r`: 1 in plane strain (per metre
    /// of thickness) and in three dimensions (where a volume is a volume), 2πr in axial symmetry
    /// (the full ring).
    #[inline]
    pub fn measure(&self, r: f64) -> f64 {
        match self {
            Geometry::PlaneStrain | Geometry::Solid => 1.0,
            Geometry::Axisymmetric(_) => std::f64::consts::TAU * r,
        }
    }

    /// The measure of the strip x ∈ [lo, hi] (its width, or the area π(hi² − lo²) of the annulus it
    /// sweeps about the axis; in three dimensions the width, per metre along z): what a
    /// one-dimensional column's volume change is divided by to give its settlement.
    pub fn plan_area(&self, lo: f64, hi: f64) -> f64 {
        match self {
            Geometry::PlaneStrain | Geometry::Solid => hi - lo,
            Geometry::Axisymmetric(_) => std::f64::consts::PI * (hi * hi - lo * lo),
        }
    }

    /// Whether the analysis is axisymmetric.
    #[inline]
    pub fn axisymmetric(&self) -> bool {
        matches!(self, Geometry::Axisymmetric(_))
    }

    /// The particle's stencil with the hoop operator T_i of each node (zero in plane strain; see
    /// [`axisymmetric_stencil`]).
    pub fn stencil(&self, basis: Basis, grid: &Grid, x: [f64; 2], lp: [f64; 2]) -> (Stencil, [f64; MAX_STENCIL]) {
        match *self {
            Geometry::PlaneStrain | Geometry::Solid => (stencil(basis, grid, x, lp), [0.0; MAX_STENCIL]),
            Geometry::Axisymmetric(w) => axisymmetric_stencil(basis, w, grid, x, lp),
        }
    }
}

/// How an axisymmetric analysis (x ≡ r ≥ 0, y the axis) weights a GIMP particle in r
/// (`analysis.axisymmetric_weights`, docs/axisymmetry.md).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AxisymmetricWeights {
    /// Option A: the planar GIMP functions S_i, ∇S_i, and the hoop operator T_i = S_i / r_p.
    Planar,
    /// Option B: the particle's characteristic function integrated with the axisymmetric measure
    /// r dr: S^r_i = (1/2l r_p) ∫ N_i r dr, G^r_i = (1/2l r_p) ∫ N_i′ r dr over [r_p − l, r_p + l],
    /// T^r_i = S^{r,planar}_i / r_p; mass and volume then carry the 2πr weight consistently, which
    /// matters near the axis.
    RWeighted,
}

/// ∫_{−∞}^{s} t N(t) dt for the hat N of spacing h (zero outside (−h, h)).
#[inline]
fn hat_first_moment(s: f64, h: f64) -> f64 {
    if s <= -h || s >= h {
        0.0
    } else if s <= 0.0 {
        s * s / 2.0 + s * s * s / (3.0 * h) - h * h / 6.0
    } else {
        -h * h / 6.0 + s * s / 2.0 - s * s * s / (3.0 * h)
    }
}

/// The r-direction functions of Option B ([`AxisymmetricWeights::RWeighted`]) of the node at `ri` for
/// a particle at `rp` > 0 with half-width `lp` < `rp`: (S^r, G^r, T^r) with
/// S^r = (1/2l r_p) ∫ N_i r dr, G^r = (1/2l r_p) ∫ N_i′ r dr = (1/2l r_p)([N_i r] − ∫ N_i dr) and
/// T^r = (1/2l r_p) ∫ N_i dr over the domain. They satisfy Σ S^r = 1, Σ G^r = 0 and, for
/// u_r = α + βr, Σ G^r u_i = β and Σ T^r u_i = α/r_p + β.
pub fn axisymmetric_gimp_r(rp: f64, lp: f64, ri: f64, h: f64) -> (f64, f64, f64) {
    let (a, b) = (rp - lp - ri, rp + lp - ri);
    let scale = 1.0 / (2.0 * lp * rp);
    let plain = hat_integral(b, h) - hat_integral(a, h);
    let moment = hat_first_moment(b, h) - hat_first_moment(a, h) + ri * plain;
    let edges = hat(b, h) * (rp + lp) - hat(a, h) * (rp - lp);
    (scale * moment, scale * (edges - plain), scale * plain)
}

/// The stencil of a particle at `x` = (r, y) in an axisymmetric analysis, with the hoop operator
/// T_i of each node (ε_θθ = Σ T_i u_r,i): S_i = S^r_i S^y_i, ∇S_i = (G^r_i S^y_i, S^r_i G^y_i),
/// T_i = T^r_i S^y_i. The linear basis and [`AxisymmetricWeights::Planar`] keep the planar
/// functions with T_i = S_i / r_p; [`AxisymmetricWeights::RWeighted`] replaces the r-direction
/// GIMP functions by [`axisymmetric_gimp_r`]. The particle must lie off the axis, r_p > 0.
pub fn axisymmetric_stencil(
    basis: Basis,
    weights: AxisymmetricWeights,
    grid: &Grid,
    x: [f64; 2],
    lp: [f64; 2],
) -> (Stencil, [f64; MAX_STENCIL]) {
    let (wx, nx) = weights_1d(basis, x[0], lp[0], grid.origin[0], grid.h[0], grid.cells[0]);
    let (wy, ny) = weights_1d(basis, x[1], lp[1], grid.origin[1], grid.h[1], grid.cells[1]);
    let mut s = Stencil::default();
    let mut hoop = [0.0; MAX_STENCIL];
    for &(j, sy, gy) in &wy[..ny] {
        for &(i, sx, gx) in &wx[..nx] {
            let (sr, gr, tr) = match (basis, weights) {
                (Basis::Gimp, AxisymmetricWeights::RWeighted) => {
                    axisymmetric_gimp_r(x[0], lp[0], grid.origin[0] + i as f64 * grid.h[0], grid.h[0])
                }
                _ => (sx, gx, sx / x[0]),
            };
            let k = s.len;
            s.nodes[k] = [i, j];
            s.w[k] = sr * sy;
            s.dw[k] = [gr * sy, sr * gy];
            hoop[k] = tr * sy;
            s.len += 1;
        }
    }
    (s, hoop)
}

/// Up to four cells (their lower-left node) with the local GIMP weights of their four nodes.
pub type LocalGimp = [((u32, u32), [f64; 4]); 4];

/// The local GIMP weights of [001] §5.4 (double mapping with local GIMP functions, DM-G): for
/// each cell e the particle's domain overlaps, S*^e_ip = (1/V_p) ∫_{Ω_p ∩ Ω_e} N^e_i dx for the
/// cell's four nodes, in the order (i, j), (i + 1, j), (i, j + 1), (i + 1, j + 1) of the cell's
/// lower-left node (i, j). Separable closed form of the integral: per
/// direction the overlap [s, t] of the domain with the cell [a, a + h] gives the right node
/// I_R = ((t − a)² − (s − a)²)/2h and the left node I_L = (t − s) − I_R, over 2l. Summed over the
/// cells, the weights of a node are its planar GIMP weight. At most 2 × 2 cells (l ≤ h/2); cells
/// outside the grid are dropped. `assembly::stiffness` maps DM-G's stiffness with them.
pub fn local_gimp(grid: &Grid, x: [f64; 2], lp: [f64; 2]) -> (LocalGimp, usize) {
    let mut per_dir = [[(0u32, 0.0, 0.0); 2]; 2];
    let mut count = [0usize; 2];
    for d in 0..2 {
        let (o, h) = (grid.origin[d], grid.h[d]);
        let (lo, hi) = (x[d] - lp[d], x[d] + lp[d]);
        let first = (((lo - o) / h).floor() as i64).max(0);
        let last = (((hi - o) / h).floor() as i64).min(grid.cells[d] as i64 - 1);
        for c in first..=last {
            let a = o + c as f64 * h;
            let (s, t) = (lo.max(a), hi.min(a + h));
            if t - s > 1e-12 * h && count[d] < 2 {
                let right = ((t - a).powi(2) - (s - a).powi(2)) / (2.0 * h);
                let left = (t - s) - right;
                per_dir[d][count[d]] = (c as u32, left / (2.0 * lp[d]), right / (2.0 * lp[d]));
                count[d] += 1;
            }
        }
    }
    let mut out = [((0u32, 0u32), [0.0; 4]); 4];
    let mut n = 0;
    for &(cj, yl, yr) in &per_dir[1][..count[1]] {
        for &(ci, xl, xr) in &per_dir[0][..count[0]] {
            out[n] = ((ci, cj), [xl * yl, xr * yl, xl * yr, xr * yr]);
            n += 1;
        }
    }
    (out, n)
}

/// Weights for a force acting at `point` on the face of a particle: the bilinear hat functions
/// N_i(point) of the cell holding the point (points on the grid's edge belong to its last cell).
/// They are consistent with GIMP's internal force when the particle domain ends at the material's
/// surface (domains that follow the stretch, `ShapeFunctions::Gimp`): for a uniform stress σ,
/// ∫_Ω_p ∇N_i σ dV = N_i(x_face) σ A_face − N_i(x_opposite) σ A_face, so a surface traction equal to σ
/// is balanced node by node, and it moves continuously as the surface crosses grid lines.
/// B-splines take their own functions at the point: for a uniform stress, ∫_Ω ∇N_i σ dV =
/// ∮ N_i σ n dS, so the consistent weights of a surface force are the basis's values there.
pub fn face_weights(basis: Basis, grid: &Grid, point: [f64; 2]) -> Stencil {
    face_weights_in(basis, grid, point)
}

/// [`face_weights`] on a grid of any dimension (the multilinear functions of the cell holding the
/// point, or the B-splines at it).
pub fn face_weights_in<const D: usize, const M: usize>(basis: Basis, grid: &Grid<D>, point: [f64; D]) -> Stencil<D, M> {
    if basis.is_bspline() {
        return stencil_in(basis, grid, point, [0.0; D]);
    }
    let per = std::array::from_fn(|d| {
        let r = ((point[d] - grid.origin[d]) / grid.h[d]).clamp(0.0, grid.cells[d] as f64);
        let c = r.floor().min((grid.cells[d] - 1) as f64);
        let xi = r - c;
        let mut w = [(0u32, 0.0, 0.0); 4];
        w[0] = (c as u32, 1.0 - xi, 0.0);
        w[1] = (c as u32 + 1, xi, 0.0);
        (w, 2)
    });
    tensor_product(&per)
}

/// Volumetric gradients of B̄ for a particle ([000] Eqs. 13–16, with the support-domain portion per
/// cell of Coombs et al. 2018): ∇̄S_i = Σ_c f_c ∇N_i(x_{r(c)}), where f_c is the share of the
/// particle domain lying in cell c (renormalised over the cells inside the grid) and ∇N_i(x_r) the
/// gradient of node i's bilinear function at the centre of cell r(c), (±1/(2h_x), ±1/(2h_y)) for
/// the four nodes of r. The volumetric strain ∇̄·Δu is then the weighted average of cell-centre
/// volumetric strains. `root(c)` is the cell whose volumetric strain cell c takes: c itself, or for
/// a cell the material barely fills a well-filled neighbour (see `assembly::stencils::cell_roots`:
/// each sparse cut cell would otherwise add a volumetric constraint with almost no freedom behind
/// it, and nearly incompressible bodies showed alternating pressure spikes along curved free
/// surfaces). Standard MPM (`Linear`) uses the one cell holding the particle. Nodes of a root cell
/// that are not in `st` are appended to it with zero weight and gradient. Returns the gradients in
/// the order of `st.nodes` and, in axial symmetry (`hoop`), the volumetric hoop operator of
/// each node: the cell-centre values N_i(x_c)/r_c = 1/(4 r_c) of the same cells with the same
/// weights, so that B̄'s volumetric strain ∇̄·u + ū_r/r is the cell-centre one of the whole
/// divergence (zero without `hoop`).
pub fn volumetric_operators(
    basis: Basis,
    grid: &Grid,
    x: [f64; 2],
    lp: [f64; 2],
    st: &mut Stencil,
    root: &dyn Fn(usize, usize) -> (usize, usize),
    hoop: bool,
) -> ([[f64; 2]; MAX_STENCIL], [f64; MAX_STENCIL]) {
    volumetric_operators_in(basis, grid, x, lp, st, &|[i, j]| root(i, j).into(), hoop)
}

/// [`volumetric_operators`] on a grid of any dimension: the gradient of a corner node's multilinear
/// function at a cell's centre is ±1/(2^{D−1} h_d) in direction d, its value 1/2^D (the hoop
/// operator, axial symmetry only, is that value over the centre's radius).
pub fn volumetric_operators_in<const D: usize, const M: usize>(
    basis: Basis,
    grid: &Grid<D>,
    x: [f64; D],
    lp: [f64; D],
    st: &mut Stencil<D, M>,
    root: &dyn Fn([usize; D]) -> [usize; D],
    hoop: bool,
) -> ([[f64; D]; M], [f64; M]) {
    let mut gv = [[0.0; D]; M];
    let mut tv = [0.0; M];
    // Cells overlapped in each direction, with the length of the overlap.
    let overlaps = |d: usize| -> ([(usize, f64); 3], usize) {
        let mut out = [(0usize, 0.0); 3];
        let mut n = 0;
        let (o, h, nc) = (grid.origin[d], grid.h[d], grid.cells[d]);
        match basis {
            Basis::Linear => {
                let s = ((x[d] - o) / h).clamp(0.0, nc as f64);
                out[0] = ((s.floor() as usize).min(nc - 1), 1.0);
                n = 1;
            }
            // B-splines: the cells the particle domain overlaps, as GIMP (the domain is the
            // particle's share of the material in either case).
            Basis::Gimp | Basis::BSpline2 | Basis::BSpline3 => {
                let (a, b) = (x[d] - lp[d], x[d] + lp[d]);
                let first = ((a - o) / h).floor().max(0.0) as usize;
                let last = (((b - o) / h).floor().max(0.0) as usize).min(nc - 1);
                for c in first..=last {
                    let (lo, hi) = (o + c as f64 * h, o + (c + 1) as f64 * h);
                    let len = b.min(hi) - a.max(lo);
                    if len > 1e-12 * h && n < 3 {
                        out[n] = (c, len);
                        n += 1;
                    }
                }
            }
        }
        (out, n)
    };
    let per: [([(usize, f64); 3], usize); D] = std::array::from_fn(overlaps);
    let counts = per.map(|p| p.1);
    let total: f64 = per.iter().map(|(o, n)| o[..*n].iter().map(|a| a.1).sum::<f64>()).product();
    if total <= 0.0 || counts.contains(&0) {
        return (gv, tv);
    }
    let corner_scale = (1u32 << (D - 1)) as f64;
    let mut at = [0usize; D];
    loop {
        let cell: [usize; D] = std::array::from_fn(|d| per[d].0[at[d]].0);
        let f = (0..D).map(|d| per[d].0[at[d]].1).product::<f64>() / total;
        let r = root(cell);
        let centre_hoop = if hoop { 1.0 / (2.0 * corner_scale * grid.centre(r)[0]) } else { 0.0 };
        // The root cell's corners, the last direction fastest.
        for corner in 0..(1usize << D) {
            let bit = |d: usize| (corner >> (D - 1 - d)) & 1;
            let node: [u32; D] = std::array::from_fn(|d| (r[d] + bit(d)) as u32);
            let Some(k) = st.slot(node) else { continue };
            for (d, g) in gv[k].iter_mut().enumerate() {
                let sign = if bit(d) == 1 { 1.0 } else { -1.0 };
                *g += f * sign / (corner_scale * grid.h[d]);
            }
            tv[k] += f * centre_hoop;
        }
        if !next_combination(&mut at, counts) {
            return (gv, tv);
        }
    }
}

/// The grid's bilinear shape function of the node at `node` and its gradient at the point `x`, the
/// gradient taken on the side of grid lines through `x` where `side` lies (a point next to `x`):
/// N = Π_d max(0, 1 − |x_d − x_i,d|/h_d). A gradient component on a grid line itself with `side`
/// on it too is the mean of the two sides, 0.
pub fn bilinear(node: [f64; 2], x: [f64; 2], side: [f64; 2], h: [f64; 2]) -> (f64, [f64; 2]) {
    multilinear(node, x, side, h)
}

/// [`bilinear`] in any dimension: N = Π_d max(0, 1 − |x_d − x_i,d|/h_d) and its gradient.
pub fn multilinear<const D: usize>(node: [f64; D], x: [f64; D], side: [f64; D], h: [f64; D]) -> (f64, [f64; D]) {
    let n: [f64; D] = std::array::from_fn(|d| (1.0 - (x[d] - node[d]).abs() / h[d]).max(0.0));
    let dn: [f64; D] = std::array::from_fn(|d| {
        let r = side[d] - node[d];
        if r.abs() < h[d] && r != 0.0 {
            -r.signum() / h[d]
        } else {
            0.0
        }
    });
    product_rule(n, dn)
}

#[cfg(test)]
mod tests;
