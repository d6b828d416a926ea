//! Basis functions of the material point method: uGIMP ([003] Eqs. 13–15), standard linear MPM, and
//! quadratic and cubic B-splines ([002] §2.2.1; `../shared/seeds-001-002.md` Part C3).
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
/// ([002] §2.2.1; seeds-001-002.md Part C3):
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

/// The right stretch tensor U = sqrt(FᵀF) of an in-plane deformation gradient F (polar
/// decomposition F = RU), in closed form for 2 × 2: with C = FᵀF, s = sqrt(det C) and
/// t = sqrt(tr C + 2s), U = (C + s I)/t. Its diagonal scales the GIMP domains (iGIMP, Charlton et
/// al. 2017): a rigid rotation leaves them unchanged, a stretch along an axis scales that axis.
pub fn right_stretch(f: [[f64; 2]; 2]) -> [[f64; 2]; 2] {
    let c = [
        [f[0][0] * f[0][0] + f[1][0] * f[1][0], f[0][0] * f[0][1] + f[1][0] * f[1][1]],
        [f[0][1] * f[0][0] + f[1][1] * f[1][0], f[0][1] * f[0][1] + f[1][1] * f[1][1]],
    ];
    let s = (c[0][0] * c[1][1] - c[0][1] * c[1][0]).max(0.0).sqrt();
    let t = (c[0][0] + c[1][1] + 2.0 * s).sqrt();
    [[(c[0][0] + s) / t, c[0][1] / t], [c[1][0] / t, (c[1][1] + s) / t]]
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
    let pr = crate::model::soil::principal::Principal::of(&[c(0, 0), c(1, 1), c(0, 1), c(2, 2), c(1, 2), c(2, 0)]);
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
/// (`../shared/seeds-001-002.md` Part A2).
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
/// lower-left node (i, j). Separable closed form (`../shared/seeds-001-002.md` Part A6): per
/// direction the overlap [s, t] of the domain with the cell [a, a + h] gives the right node
/// I_R = ((t − a)² − (s − a)²)/2h and the left node I_L = (t − s) − I_R, over 2l. Summed over the
/// cells, the weights of a node are its planar GIMP weight. At most 2 × 2 cells (l ≤ h/2); cells
/// outside the grid are dropped. Not yet used by the kernels (issue «Seed [001]»).
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
/// the order of `st.nodes`.
pub fn volumetric_gradients(
    basis: Basis,
    grid: &Grid,
    x: [f64; 2],
    lp: [f64; 2],
    st: &mut Stencil,
    root: &dyn Fn(usize, usize) -> (usize, usize),
) -> [[f64; 2]; MAX_STENCIL] {
    volumetric_operators(basis, grid, x, lp, st, root, false).0
}

/// [`volumetric_gradients`] with, in axial symmetry (`hoop`), the volumetric hoop operator of
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
mod tests {
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
                    let fd = (uniform_bspline(degree, s - i as f64 + e).0
                        - uniform_bspline(degree, s - i as f64 - e).0)
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
        let (a, b) =
            (face_weights(Basis::Gimp, &g, [1.1, 0.75 - 1e-9]), face_weights(Basis::Gimp, &g, [1.1, 0.75 + 1e-9]));
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
            let (top, bottom) = (
                face_weights(Basis::Gimp, &g, [x[0], x[1] + lp[1]]),
                face_weights(Basis::Gimp, &g, [x[0], x[1] - lp[1]]),
            );
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
            let gv = volumetric_gradients(basis, &g, x, lp, &mut st, &|i, j| (i, j));
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
        let gv = volumetric_gradients(Basis::Gimp, &g, [1.25, 0.625], [0.125, 0.0625], &mut st, &|i, j| (i, j));
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

    /// Part E item 5 of `../shared/seeds-001-002.md`: for u_r = α + βr, u_y = γy the particle's
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

    /// Option B's r-functions against the closed forms of Part A2: Σ G^r = 0, the same hoop operator
    /// as Option A, and S^r = N_i(r_p) + n₁ l²/(3 r_p) for a domain inside one cell (n₁ = ±1/h the hat's
    /// slope there).
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

    /// Part E item 2 of `../shared/seeds-001-002.md`: the local GIMP weights of all cells sum to 1
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
        let inner =
            [[0.3, -0.4, 1.3], [0.125, -0.0625, 2.5], [1.375, -0.25, 1.1], [0.74, -0.26, 2.21], [1.2, -0.07, 1.79]];
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
                        let at = |s: &Stencil<3, MAX_STENCIL_3D>, n: [u32; 3]| {
                            s.iter().find(|o| o.0 == n).map_or(0.0, |o| o.1)
                        };
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
}
