//! The particle–grid maps of a step: each particle's stencil (nodes, S, ∇S, ∇̄S on x_n), computed
//! once per step, and its map to the nodes that carry unknowns.
//!
//! # Nodes that the material barely reaches
//! A node is *well filled* when the material fills more than [`WELL_FILLED_FRACTION`] of a cell's
//! area in its support, φ_i = Σ_p S_ip V_p / (h_x h_y) (1 inside the material, 1/2 on a straight
//! edge, 1/4 at a convex corner of a body on grid lines). A node that a particle domain reaches by
//! a sliver δ has S ∝ δ² but ∇S ∝ δ (and, with B̄, ∇̄S ∝ δ): its mass and stiffness are tiny, so its
//! dofs are ill-determined, yet fixing them to zero makes it a support whose reaction is of order
//! δ σ — a nearly incompressible body loaded past a few percent of a cell lost half its load to such
//! supports. Instead, the motion of such a node (u and U components) is *extended* from well-filled
//! nodes by a linear extrapolation towards the particle that reaches it, which reproduces every
//! linear field exactly (so patch tests and the equilibrium identity hold), in this order:
//! 1. along the grid line of the axis on which the particle lies farther away:
//!    u_s = 2u_a − u_b with a, b the next two nodes towards the particle (both well filled);
//! 2. along the other axis;
//! 3. from the triangle of the cell corner towards the particle: u_s = u_a + u_b − u_c;
//! 4. with B-splines only: along the diagonal towards the particle, u_s = 2u_a − u_b.
//!
//! The choice depends only on the particle's position and on φ, so it is the same on every rank.
//! Without any of them (a node diagonal to a body's corner), the node stays fixed: with GIMP its
//! influence on the particle is of second order in the sliver. B-splines reach a cell and a half
//! (quadratic) or two (cubic) beyond a particle, so their weights at such nodes are not small, and
//! a traction near a body's corner put a share there (the tapered plate lost 5e-4 of its load). The pore pressure of a node that is
//! not well filled is fixed to zero (the material's free surface is drained), as before.
//! This is the extension of aggregated unfitted finite elements (Badia, Verdugo & Martín 2018)
//! with the particle's side as the aggregate.

use super::dofs::DofMap;
use crate::kernels::{self, NodeBasis};
use crate::model::shape::{self, Basis, MAX_STENCIL};
use crate::model::Model;
use petsc::GhostedRange;

/// Fraction of a cell's area that the material must fill in a node's support for the node to carry
/// unknowns of its own (see the module documentation).
pub const WELL_FILLED_FRACTION: f64 = 1e-2;

/// Largest number of master nodes of one extended node.
pub const MAX_MASTERS: usize = 3;

/// How a raw stencil slot's motion is extended: from up to three other nodes.
#[derive(Debug, Clone, Copy)]
pub struct Extension {
    /// The raw slot whose motion is extended.
    pub slot: u8,
    /// Effective slots of the masters and their coefficients.
    pub masters: [(u8, f64); MAX_MASTERS],
    /// Number of masters used.
    pub n: u8,
    /// The node's dof components that are extended (bit c: component c), its motion components
    /// that no boundary fixes.
    pub mask: u8,
}

impl Extension {
    /// Σ_m c_m f(n_m) over the masters: the extended value of a nodal field `f` of the ghosted
    /// node numbering, `eff` the particle's effective nodes ([`Stencils::effective`]).
    #[inline]
    pub fn of_masters(&self, eff: &[u32], f: impl Fn(usize) -> f64) -> f64 {
        (0..self.n as usize).map(|m| self.masters[m].1 * f(eff[self.masters[m].0 as usize] as usize)).sum()
    }
}

/// The stencils of all particles for one step, in this rank's ghosted node numbering, stored flat:
/// particle k uses entries `offsets[k]..offsets[k + 1]` of `nodes` and `basis` (the raw stencil),
/// `eff_offsets[k]..eff_offsets[k + 1]` of `eff_nodes` (its raw nodes, in the same order, then the
/// masters of its extended nodes that are not in the raw stencil; an empty range where there are
/// no such masters, the effective nodes then being the raw ones), and `ext_offsets[k]..` of `ext`.
#[derive(Debug, Clone, Default)]
pub struct Stencils<const D: usize = 2> {
    pub offsets: Vec<usize>,
    pub nodes: Vec<u32>,
    pub basis: Vec<NodeBasis<D>>,
    pub eff_offsets: Vec<usize>,
    pub eff_nodes: Vec<u32>,
    pub ext_offsets: Vec<usize>,
    pub ext: Vec<Extension>,
    /// The strain-recovery operators of each raw slot (`kernels::Point::with_recovery`), flat
    /// like `basis`; empty when the strain is recovered with the basis itself.
    pub strain: Vec<NodeBasis<D>>,
    /// The force operators of each raw slot (`kernels::Point::with_forces`, [001]'s double-mapped
    /// internal force), flat like `basis`; empty when the forces are integrated with the basis.
    pub forces: Vec<NodeBasis<D>>,
    /// The slots beyond the grid of the GIMP supports that reach past a held wall, by particle
    /// (see [`WallSlot`]).
    pub beyond: Vec<WallSlot<D>>,
}

/// A node beyond the grid's edge that a GIMP particle's support reaches past a wall ([`check_edges`]).
/// The stencil drops it, so the particle's basis there is lost; the node is the rigid wall's
/// material, held in every direction (a dropped node has no unknowns), and its share of the
/// particle's forces is the wall's reaction. The equilibrium identity counts it
/// (`System::forces`): without it the first moment of the nodal forces misses
/// Σ_p V_p σ_p ⊗ Σ_beyond x ∇S, which grows with the stretch of the domains at a fixed base.
#[derive(Debug, Clone, Copy)]
pub struct WallSlot<const D: usize = 2> {
    /// The particle.
    pub k: u32,
    /// Its basis at the node (on x_n). With B̄ the volumetric gradients are zero: the particle's
    /// cell-centre gradients ∇̄S, from the cells inside the grid only, already reproduce a linear
    /// field on their own.
    pub basis: NodeBasis<D>,
    /// The node's position (it does not move).
    pub at: [f64; D],
    /// The grid node on the wall next to it (ghosted numbering), whose boundary takes the share.
    pub wall: u32,
    /// The direction normal to the wall it lies beyond.
    pub normal: u8,
}

impl<const D: usize> Stencils<D> {
    /// The bytes the stencils hold on the heap.
    pub fn heap_bytes(&self) -> usize {
        use crate::algebra::heap::capacity as c;
        let offsets = [&self.offsets, &self.eff_offsets, &self.ext_offsets].map(c).iter().sum::<usize>();
        let nodes = c(&self.nodes) + c(&self.eff_nodes);
        let bases = [&self.basis, &self.strain, &self.forces].map(c).iter().sum::<usize>();
        offsets + nodes + bases + c(&self.ext) + c(&self.beyond)
    }

    /// Number of particles.
    pub fn len(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    /// Whether there are no particles.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Raw nodes and basis of particle `k`.
    pub fn get(&self, k: usize) -> (&[u32], &[NodeBasis<D>]) {
        let r = self.offsets[k]..self.offsets[k + 1];
        (&self.nodes[r.clone()], &self.basis[r])
    }

    /// The strain-recovery operators of particle `k`'s raw slots: its CMPM patch functions
    /// ([`cmpm_patches`]) or, by default, its basis.
    pub fn strain_of(&self, k: usize) -> &[NodeBasis<D>] {
        let r = self.offsets[k]..self.offsets[k + 1];
        if self.strain.is_empty() {
            &self.basis[r]
        } else {
            &self.strain[r]
        }
    }

    /// The force operators of particle `k`'s raw slots: its double-mapped ones, or none (an empty
    /// slice: its basis).
    pub fn forces_of(&self, k: usize) -> &[NodeBasis<D>] {
        if self.forces.is_empty() {
            &[]
        } else {
            &self.forces[self.offsets[k]..self.offsets[k + 1]]
        }
    }

    /// Effective nodes of particle `k` (its raw nodes first).
    pub fn effective(&self, k: usize) -> &[u32] {
        let (a, b) = (self.eff_offsets[k], self.eff_offsets[k + 1]);
        if a == b {
            &self.nodes[self.offsets[k]..self.offsets[k + 1]]
        } else {
            &self.eff_nodes[a..b]
        }
    }

    /// Extensions of particle `k`.
    pub fn extensions(&self, k: usize) -> &[Extension] {
        let r = self.ext_offsets.get(k).copied().unwrap_or(0)..self.ext_offsets.get(k + 1).copied().unwrap_or(0);
        &self.ext[r]
    }

    /// The slots beyond the grid of particle `k` ([`WallSlot`]; most particles have none).
    pub fn beyond_of(&self, k: usize) -> &[WallSlot<D>] {
        let first = self.beyond.partition_point(|w| (w.k as usize) < k);
        let last = first + self.beyond[first..].partition_point(|w| w.k as usize == k);
        &self.beyond[first..last]
    }
}

/// Fraction of a cell's area the material (the union of the particles' domains) must fill for the
/// cell's centre to give B̄ a volumetric strain of its own; a sparser cell takes that of a
/// well-filled neighbour (see `shape::volumetric_operators`).
pub const CELL_FILLED_FRACTION: f64 = 0.5;

/// For every cell of the ghosted box, the cell whose volumetric strain it takes in B̄.
#[derive(Debug, Clone)]
pub struct CellRoots<const D: usize = 2> {
    start: [usize; D],
    count: [usize; D],
    root: Vec<[u32; D]>,
}

impl<const D: usize> CellRoots<D> {
    /// Every cell its own root.
    pub fn identity() -> CellRoots<D> {
        CellRoots { start: [0; D], count: [0; D], root: Vec::new() }
    }

    /// The roots from the cells' filled fractions `phi` (per ghosted node for the cell whose
    /// lowest corner it is, summed over ranks): a cell filled below [`CELL_FILLED_FRACTION`] takes
    /// the most filled of its 3^D − 1 neighbours that is filled above it (ties: the first with x
    /// fastest), if any.
    pub fn new(ghost: &GhostedRange<D>, cells: [usize; D], phi: &[f64]) -> CellRoots<D> {
        let n = ghost.len();
        let at = |c: [i64; D]| -> Option<f64> {
            if (0..D).any(|d| c[d] < 0 || c[d] as usize >= cells[d]) {
                return None;
            }
            ghost.local(c.map(|v| v as usize)).map(|l| phi[l])
        };
        let root = (0..n)
            .map(|l| {
                let own_cell = ghost.indices(l);
                let here = own_cell.map(|v| v as i64);
                let own = at(here).unwrap_or(0.0);
                if own >= CELL_FILLED_FRACTION {
                    return own_cell.map(|v| v as u32);
                }
                let mut best: Option<([i64; D], f64)> = None;
                let mut offset = [0usize; D];
                loop {
                    let c: [i64; D] = std::array::from_fn(|d| here[d] + offset[d] as i64 - 1);
                    if let Some(f) = at(c).filter(|&f| f >= CELL_FILLED_FRACTION) {
                        if best.is_none_or(|b| f > b.1) {
                            best = Some((c, f));
                        }
                    }
                    if !crate::model::shape::next_combination(&mut offset, [3; D]) {
                        break;
                    }
                }
                best.map_or(own_cell.map(|v| v as u32), |(c, _)| c.map(|v| v as u32))
            })
            .collect();
        CellRoots { start: ghost.start, count: ghost.count, root }
    }

    /// The root of cell `c` (itself outside the ghosted box).
    pub fn root_of(&self, c: [usize; D]) -> [usize; D] {
        let inside = (0..D).all(|d| c[d] >= self.start[d] && c[d] < self.start[d] + self.count[d]);
        if !inside || self.root.is_empty() {
            return c;
        }
        let l = crate::model::grid::flat_number(self.count, std::array::from_fn(|d| c[d] - self.start[d]));
        self.root[l].map(|v| v as usize)
    }
}

impl CellRoots {
    /// The root of cell (i, j) (itself outside the ghosted box).
    pub fn root(&self, i: usize, j: usize) -> (usize, usize) {
        let [a, b] = self.root_of([i, j]);
        (a, b)
    }
}

/// The area (volume in three dimensions) of the particles' domains in every cell (their GIMP
/// domains, or their volumes for linear MPM) as a fraction of the cell, on this rank's particles,
/// per ghosted node for the cell whose lowest corner it is.
pub fn cell_fractions<const D: usize>(model: &Model<D>, ghost: &GhostedRange<D>) -> Vec<f64> {
    let g = &model.grid;
    let ps = &model.particles;
    let mut out = vec![0.0; ghost.len()];
    let area: f64 = g.h.iter().product();
    for k in 0..ps.len() {
        let (x, lp) = (ps.x[k], ps.lp[k]);
        if model.basis == Basis::Linear {
            if let Some(l) = g.cell_containing(x).and_then(|c| ghost.local(c)) {
                out[l] += model.area(k) / area;
            }
            continue;
        }
        let span = |d: usize| -> Vec<(usize, f64)> {
            let (o, h, nc) = (g.origin[d], g.h[d], g.cells[d]);
            let (a, b) = (x[d] - lp[d], x[d] + lp[d]);
            let first = ((a - o) / h).floor().max(0.0) as usize;
            let last = (((b - o) / h).floor().max(0.0) as usize).min(nc - 1);
            (first..=last)
                .filter_map(|c| {
                    let len = b.min(o + (c + 1) as f64 * h) - a.max(o + c as f64 * h);
                    (len > 0.0).then_some((c, len))
                })
                .collect()
        };
        // The domain's area is scaled to the particle's volume.
        let scale = model.area(k) / lp.iter().fold(1.0, |a, l| a * (2.0 * l));
        let spans: [Vec<(usize, f64)>; D] = std::array::from_fn(span);
        if spans.iter().any(|s| s.is_empty()) {
            continue;
        }
        let mut at = [0usize; D];
        loop {
            let cell: [usize; D] = std::array::from_fn(|d| spans[d][at[d]].0);
            if let Some(l) = ghost.local(cell) {
                let overlap = (1..D).fold(spans[0][at[0]].1, |a, d| a * spans[d][at[d]].1);
                out[l] += overlap * scale / area;
            }
            if !crate::model::shape::next_combination(&mut at, std::array::from_fn(|d| spans[d].len())) {
                break;
            }
        }
    }
    out
}

/// A particle whose support reaches past a side of the grid.
#[derive(Debug, Clone, Copy)]
pub struct Crossing {
    /// The particle.
    pub k: usize,
    /// The side (0: x_min, 1: x_max, 2: y_min, 3: y_max, 4: z_min, 5: z_max).
    pub side: usize,
}

/// The names of the grid's sides, in [`Crossing::side`] order.
pub const SIDES: [&str; 6] = ["x_min", "x_max", "y_min", "y_max", "z_min", "z_max"];

/// Builds the raw stencils on x_n (step 1 of a step), and lists the particles whose support
/// reaches past the grid (GIMP: their domain, beyond round-off; linear and B-splines, whose
/// functions stay a partition of unity up to the edge: their centre), for
/// [`check_edges`]. Fails, naming the particle, when a stencil node lies outside this rank's ghost
/// region or a position is not finite.
pub fn build(model: &Model, ghost: &GhostedRange, roots: &CellRoots) -> Result<(Stencils, Vec<Crossing>), String> {
    build_in::<2, { shape::MAX_STENCIL }>(model, ghost, roots)
}

/// [`build`] in any dimension, with stencils of at most `M` nodes (an axisymmetric model's
/// stencils are the plane ones with their hoop operators).
pub fn build_in<const D: usize, const M: usize>(
    model: &Model<D>,
    ghost: &GhostedRange<D>,
    roots: &CellRoots<D>,
) -> Result<(Stencils<D>, Vec<Crossing>), String> {
    let ps = &model.particles;
    let g = &model.grid;
    let mut out = Stencils { offsets: Vec::with_capacity(ps.len() + 1), ..Default::default() };
    let mut crossings = Vec::new();
    out.offsets.push(0);
    let hi = g.extent_max();
    let tol = 1e-9 * (1..D).fold(g.h[0], |m, d| m.min(g.h[d]));
    let axisymmetric = model.geometry.axisymmetric();
    let reached_only = only_reached_nodes(model);
    for k in 0..ps.len() {
        let (x, lp) = (ps.x[k], ps.lp[k]);
        if !x.iter().all(|v| v.is_finite()) {
            return Err(format!("material point {}: its position is not finite (NaN or Inf)", ps.id[k]));
        }
        let reach = if model.basis == Basis::Gimp { lp } else { [0.0; D] };
        let crossed_before = crossings.len();
        for d in 0..D {
            if x[d] - reach[d] < g.origin[d] - tol {
                crossings.push(Crossing { k, side: 2 * d });
            }
            if x[d] + reach[d] > hi[d] + tol {
                crossings.push(Crossing { k, side: 2 * d + 1 });
            }
        }
        let (mut st, hoop) = stencil_with_hoop::<D, M>(model, g, x, lp);
        let gv = model.bbar.then(|| {
            shape::volumetric_operators_in(model.basis, g, x, lp, &mut st, &|c| roots.root_of(c), axisymmetric)
        });
        if st.len == 0 {
            return Err(format!(
                "material point {} at {} m has left the grid",
                ps.id[k],
                crate::model::position_text(&x)
            ));
        }
        for n in &st.nodes[..st.len] {
            let node = n.map(|v| v as usize);
            let l = ghost.local(node).ok_or_else(|| {
                format!(
                    "material point {} at {} m reaches node {} outside this rank's ghost region \
                     (its support is wider than the ghost nodes around its cell allow)",
                    ps.id[k],
                    crate::model::position_text(&x),
                    crate::model::index_text(&node)
                )
            })?;
            out.nodes.push(l as u32);
        }
        let first = out.basis.len();
        kernels::plain_basis(&st, &hoop, &mut out.basis);
        if let Some((gv, tv)) = gv {
            for ((b, v), t) in out.basis[first..].iter_mut().zip(gv).zip(tv) {
                b.gv = v;
                b.tv = t;
            }
        }
        if reached_only {
            leave_out_touched_nodes(&mut out, first);
        }
        out.offsets.push(out.nodes.len());
        if crossings.len() > crossed_before && model.basis == Basis::Gimp {
            beyond_the_grid::<D, M>(model, ghost, k, &mut out.beyond)?;
        }
    }
    Ok((out, crossings))
}

/// Whether a point's stored stencil holds only the nodes its operators reach ([`build_in`]): every
/// point's operators are its basis's and its B̄ volumetric gradients. [001]'s CMPM strain patches
/// and its mapped forces and stiffnesses place operators of their own on a point's raw slots,
/// including nodes its domain only touches, so their stencils keep every node of the support.
pub fn only_reached_nodes<const D: usize>(model: &Model<D>) -> bool {
    use crate::case::{InternalForce, Stiffness, StressRecovery};
    model.stress_recovery == StressRecovery::Basis
        && model.internal_force == InternalForce::Particle
        && model.stiffness == Stiffness::Particle
}

/// Leaves out of the last point's raw stencil (its slots from `first` on) the nodes at which every
/// operator is zero: nodes its GIMP domain only touches (with two points per cell and direction, 5
/// of 9 nodes in the plane and 19 of 27 in three dimensions while no grid line is crossed). Their
/// terms in every sum over the stencil are exact zeros, so residuals and tangent entries are the
/// same to the bit; what changes is what is stored per point, the loops over it and the matrix's
/// pattern (a node couples to the nodes of the points it reaches, not of those it is touched by).
fn leave_out_touched_nodes<const D: usize>(out: &mut Stencils<D>, first: usize) {
    let mut kept = first;
    for slot in first..out.basis.len() {
        if !out.basis[slot].is_zero() {
            out.basis[kept] = out.basis[slot];
            out.nodes[kept] = out.nodes[slot];
            kept += 1;
        }
    }
    out.basis.truncate(kept);
    out.nodes.truncate(kept);
}

/// The stencil of a particle at `x` with half-widths `lp` on `grid` with the hoop operator of each
/// node: zero in plane strain and in three dimensions, the axisymmetric stencil's otherwise (two
/// dimensions only).
fn stencil_with_hoop<const D: usize, const M: usize>(
    model: &Model<D>,
    grid: &crate::model::grid::Grid<D>,
    x: [f64; D],
    lp: [f64; D],
) -> (shape::Stencil<D, M>, [f64; M]) {
    if !model.geometry.axisymmetric() {
        return (shape::stencil_in(model.basis, grid, x, lp), [0.0; M]);
    }
    let plane = crate::model::grid::Grid::new(
        [grid.origin[0], grid.origin[1]],
        [grid.h[0], grid.h[1]],
        [grid.cells[0], grid.cells[1]],
    );
    let (s2, h2) = model.geometry.stencil(model.basis, &plane, [x[0], x[1]], [lp[0], lp[1]]);
    let mut st = shape::Stencil::<D, M> { len: s2.len, ..Default::default() };
    for n in 0..s2.len {
        st.nodes[n] = std::array::from_fn(|d| s2.nodes[n][d]);
        st.w[n] = s2.w[n];
        st.dw[n] = std::array::from_fn(|d| s2.dw[n][d]);
    }
    (st, std::array::from_fn(|n| if n < s2.len { h2[n] } else { 0.0 }))
}

/// Appends the slots of particle `k`'s GIMP support beyond the grid ([`WallSlot`]): its stencil on
/// the grid grown by one cell on every side, the nodes outside the original grid. Inside the grid
/// the weights are those of the particle's stencil (GIMP's are local to each node).
fn beyond_the_grid<const D: usize, const M: usize>(
    model: &Model<D>,
    ghost: &GhostedRange<D>,
    k: usize,
    out: &mut Vec<WallSlot<D>>,
) -> Result<(), String> {
    let g = &model.grid;
    let (x, lp) = (model.particles.x[k], model.particles.lp[k]);
    let grown = crate::model::grid::Grid::<D>::new(
        std::array::from_fn(|d| g.origin[d] - g.h[d]),
        g.h,
        std::array::from_fn(|d| g.cells[d] + 2),
    );
    let (st, hoop) = stencil_with_hoop::<D, M>(model, &grown, x, lp);
    for (n, &t) in hoop.iter().enumerate().take(st.len) {
        let at = st.nodes[n].map(|v| v as usize);
        let Some(normal) = (0..D).find(|&d| at[d] == 0 || at[d] == grown.cells[d]) else { continue };
        let on_wall: [usize; D] = std::array::from_fn(|d| at[d].clamp(1, g.cells[d] + 1) - 1);
        let position = grown.position(at);
        let wall = ghost.local(on_wall).ok_or_else(|| {
            format!(
                "material point {} at {} m reaches past the grid to {} m, next to node {} outside this \
                 rank's ghost region",
                model.particles.id[k],
                crate::model::position_text(&x),
                crate::model::position_text(&position),
                crate::model::index_text(&on_wall)
            )
        })?;
        let (gv, tv) = if model.bbar { ([0.0; D], 0.0) } else { (st.dw[n], t) };
        out.push(WallSlot {
            k: k as u32,
            basis: NodeBasis { s: st.w[n], g: st.dw[n], gv, t, tv },
            at: position,
            wall: wall as u32,
            normal: normal as u8,
        });
    }
    Ok(())
}

/// The grid's edge. A support that reaches past a side of the grid loses the part of its basis
/// beyond it (the partition of unity, and with it part of the particle's internal force and load).
/// Where the particle's nodes on that side are held in the side's normal direction by a boundary
/// (a wall: rollers, a fixed base; not a rigid body's tied nodes, which move), the material beyond
/// is the rigid wall, which carries that part as its reaction (the held slots beyond the grid, [`WallSlot`]); on any other side the run must
/// stop, naming the particle, its body, the time and the side. (Linear MPM and B-splines: a centre
/// outside the grid always stops the run.)
pub fn check_edges<const D: usize>(
    model: &Model<D>,
    st: &Stencils<D>,
    crossings: &[Crossing],
    dofs: &DofMap,
    ghost: &GhostedRange<D>,
    t: f64,
    body_names: &[String],
) -> Result<(), String> {
    let ps = &model.particles;
    let g = &model.grid;
    for c in crossings {
        let (nodes, _) = st.get(c.k);
        let normal = c.side / 2;
        let edge = if c.side % 2 == 0 { 0 } else { g.cells[normal] };
        let on_side = |l: u32| ghost.indices(l as usize)[normal] == edge;
        let wall = model.basis == Basis::Gimp && {
            let side_nodes: Vec<u32> = nodes.iter().copied().filter(|&l| on_side(l)).collect();
            // Held still or moved by a boundary: a rigid body's tied nodes are unknowns, not a wall.
            let held = |l: u32| dofs.boundary_fixed(l as usize, normal) && dofs.fixed[l as usize * dofs.nd + normal];
            !side_nodes.is_empty() && side_nodes.iter().all(|&l| held(l))
        };
        if !wall {
            let body = body_names.get(ps.body[c.k] as usize).map_or("?", |s| s.as_str());
            return Err(format!(
                "at t = {t:.6e} s material point {} of body `{body}` at {} m reaches past the grid's {} \
                 edge, where no boundary holds it: its support would lose the part beyond the grid, and with it \
                 part of its load; enlarge the grid",
                ps.id[c.k],
                crate::model::position_text(&ps.x[c.k]),
                SIDES[c.side]
            ));
        }
    }
    Ok(())
}

/// Coefficients extending the node with indices `node` (at `pos`) from well-filled nodes towards
/// the point `toward` (see the module documentation), in any dimension: the masters' grid indices,
/// their coefficients and how many are used; `well(n)` says whether a node is well filled (false
/// outside the ghost region or the grid); `diagonal` allows the fourth rule (B-splines). The rules
/// of the module documentation, generalised: (1, 2) along the grid line of each axis, the axis on which the
/// particle lies farthest first; (3) from the triangle of two axes towards the particle,
/// u_s = u_a + u_b − u_c, the pairs of axes in their order; (4) with B-splines, along the diagonal
/// of the directions towards the particle. Each reproduces linear fields exactly.
pub fn extension_in<const D: usize>(
    node: [usize; D],
    pos: [f64; D],
    toward: [f64; D],
    well: &dyn Fn([i64; D]) -> bool,
    tiny: f64,
    diagonal: bool,
) -> Option<([[i64; D]; MAX_MASTERS], [f64; MAX_MASTERS], usize)> {
    let n = node.map(|v| v as i64);
    let d: [f64; D] = std::array::from_fn(|c| toward[c] - pos[c]);
    let dir: [i64; D] = d.map(|v| {
        if v > tiny {
            1i64
        } else if v < -tiny {
            -1
        } else {
            0
        }
    });
    let step = |s: [i64; D], k: i64| -> [i64; D] { std::array::from_fn(|c| n[c] + k * s[c]) };
    let unit = |a: usize| -> [i64; D] { std::array::from_fn(|c| if c == a { dir[a] } else { 0 }) };
    // The axes by decreasing distance to the particle (ties: the lower axis first).
    let mut axes: [usize; D] = std::array::from_fn(|a| a);
    axes.sort_by(|&a, &b| d[b].abs().total_cmp(&d[a].abs()));
    for &axis in axes.iter().filter(|&&a| dir[a] != 0) {
        let (a, b) = (step(unit(axis), 1), step(unit(axis), 2));
        if well(a) && well(b) {
            return Some(([a, b, n], [2.0, -1.0, 0.0], 2));
        }
    }
    for p in 0..D {
        for q in (p + 1..D).filter(|&q| dir[p] != 0 && dir[q] != 0) {
            let (a, b) = (step(unit(p), 1), step(unit(q), 1));
            let c: [i64; D] = std::array::from_fn(|k| a[k] + b[k] - n[k]);
            if well(a) && well(b) && well(c) {
                return Some(([a, b, c], [1.0, 1.0, -1.0], 3));
            }
        }
    }
    if diagonal && dir.iter().filter(|&&s| s != 0).count() >= 2 {
        let (a, b) = (step(dir, 1), step(dir, 2));
        if well(a) && well(b) {
            return Some(([a, b, n], [2.0, -1.0, 0.0], 2));
        }
    }
    None
}

/// [001]'s CMPM strain recovery (`stabilisation.stress_recovery = "cmpm"`, [001] Eqs. 21–24;
/// step 4 of a step, before the extensions): for each point,
/// the patch of its centre's cell in each direction is cubic when the node columns (rows) on both
/// sides of the cell are well filled, quadratic when one side is, linear otherwise (a neighbour
/// that is outside the grid or barely filled would pull the strain towards its extended or absent
/// motion); a corner of the tensor-product patch that is not well filled drops the y side of the
/// patch on its side first, then the x side. The patch's nodes join the point's raw stencil (with
/// zero basis: they carry no force or mass) and `strain` holds the patch functions' gradients
/// ∇N²_j(x_p) = (2/h) dN/dξ and, in axial symmetry, the hoop operators N²_j(x_p)/r_p.
pub fn cmpm_patches(st: &mut Stencils, model: &Model, ghost: &GhostedRange, dofs: &DofMap) -> Result<(), String> {
    use crate::model::cmpm::{functions, Patch1d};
    let (g, ps) = (&model.grid, &model.particles);
    let well = |i: i64, j: i64| -> bool {
        i >= 0 && j >= 0 && ghost.node(i as usize, j as usize).is_some_and(|l| dofs.well[l])
    };
    let mut out = Stencils { offsets: vec![0], ..Default::default() };
    for k in 0..st.len() {
        let x = ps.x[k];
        let (ci, cj) =
            g.cell_of(x).ok_or_else(|| format!("material point {}: its centre has left the grid", ps.id[k]))?;
        let (ci, cj) = (ci as i64, cj as i64);
        let col = |i: i64| well(i, cj) && well(i, cj + 1);
        let row = |j: i64| well(ci, j) && well(ci + 1, j);
        let (mut left, mut right, mut below, mut above) = (col(ci - 1), col(ci + 2), row(cj - 1), row(cj + 2));
        // Corners of the tensor product: each must be well filled too.
        for _ in 0..4 {
            let xs: Vec<i64> = [(left, ci - 1), (true, ci), (true, ci + 1), (right, ci + 2)]
                .iter()
                .filter_map(|&(on, i)| on.then_some(i))
                .collect();
            let ys: Vec<i64> = [(below, cj - 1), (true, cj), (true, cj + 1), (above, cj + 2)]
                .iter()
                .filter_map(|&(on, j)| on.then_some(j))
                .collect();
            let Some(&(bi, bj)) =
                xs.iter().flat_map(|&i| ys.iter().map(move |&j| (i, j))).find(|&(i, j)| !well(i, j)).as_ref()
            else {
                break;
            };
            if bj == cj - 1 && below {
                below = false;
            } else if bj == cj + 2 && above {
                above = false;
            } else if bi == ci - 1 {
                left = false;
            } else {
                right = false;
            }
        }
        let patch = |minus: bool, plus: bool| match (minus, plus) {
            (true, true) => Patch1d::Cubic,
            (false, true) => Patch1d::QuadraticPlus,
            (true, false) => Patch1d::QuadraticMinus,
            (false, false) => Patch1d::Linear,
        };
        let (px, py) = (patch(left, right), patch(below, above));
        let xi = g.local_coordinates((ci as usize, cj as usize), x);
        let ((nx, dx), (ny, dy)) = (functions(px, xi[0]), functions(py, xi[1]));
        // The patch's first node: one cell to the − side where the patch reaches there.
        let (ix0, jy0) = (ci - i64::from(left), cj - i64::from(below));
        let hoop = if model.geometry.axisymmetric() { 1.0 / x[0] } else { 0.0 };
        let (nodes, basis) = st.get(k);
        let mut nodes = nodes.to_vec();
        let mut basis = basis.to_vec();
        let mut strain = vec![NodeBasis::default(); nodes.len()];
        for b in 0..py.nodes().len() {
            for a in 0..px.nodes().len() {
                let (i, j) = (ix0 + a as i64, jy0 + b as i64);
                let l = ghost.node(i as usize, j as usize).ok_or_else(|| {
                    format!(
                        "material point {}: node ({i}, {j}) of its CMPM patch is outside this rank's ghost region",
                        ps.id[k]
                    )
                })? as u32;
                let slot = match nodes.iter().position(|&n| n == l) {
                    Some(s) => s,
                    None if nodes.len() < MAX_STENCIL => {
                        nodes.push(l);
                        basis.push(NodeBasis::default());
                        strain.push(NodeBasis::default());
                        nodes.len() - 1
                    }
                    None => {
                        return Err(format!(
                            "material point {}: its CMPM patch and stencil exceed {MAX_STENCIL} nodes",
                            ps.id[k]
                        ))
                    }
                };
                let e = [dx[a] * 2.0 / g.h[0] * ny[b], nx[a] * dy[b] * 2.0 / g.h[1]];
                let t = nx[a] * ny[b] * hoop;
                strain[slot] = NodeBasis { s: 0.0, g: e, gv: e, t, tv: t };
            }
        }
        out.nodes.extend(nodes);
        out.basis.extend(basis);
        out.strain.extend(strain);
        out.offsets.push(out.nodes.len());
    }
    *st = out;
    Ok(())
}

/// Adds the effective stencils and extensions (step 4 of a step) for the dof map `dofs` and the
/// motion components `motion` of the layout (u and U).
pub fn extend<const D: usize>(
    st: &mut Stencils<D>,
    model: &Model<D>,
    ghost: &GhostedRange<D>,
    dofs: &DofMap,
    motion: &[usize],
) {
    let ps = &model.particles;
    let g = &model.grid;
    let is_well = |n: [i64; D]| -> bool {
        if n.iter().any(|&v| v < 0) {
            return false;
        }
        ghost.local(n.map(|v| v as usize)).is_some_and(|l| dofs.well[l])
    };
    let tiny = 1e-9 * g.h.iter().copied().fold(f64::INFINITY, f64::min);
    st.eff_offsets.clear();
    st.eff_nodes.clear();
    st.ext_offsets.clear();
    st.ext.clear();
    st.eff_offsets.push(0);
    st.ext_offsets.push(0);
    for k in 0..st.len() {
        let raw = st.offsets[k]..st.offsets[k + 1];
        let start = st.eff_nodes.len();
        st.eff_nodes.extend_from_slice(&st.nodes[raw.clone()]);
        for (slot, idx) in raw.clone().enumerate() {
            let l = st.nodes[idx] as usize;
            let b = st.basis[idx];
            if dofs.well[l] || (b.s == 0.0 && b.g == [0.0; D] && b.gv == [0.0; D] && b.tv == 0.0) {
                continue;
            }
            let mask = motion.iter().filter(|&&c| !dofs.boundary_fixed(l, c)).fold(0u8, |m, &c| m | (1 << c));
            if mask == 0 {
                continue;
            }
            let n = ghost.indices(l);
            let Some((masters, coefs, count)) =
                extension_in(n, g.position(n), ps.x[k], &is_well, tiny, model.basis.is_bspline())
            else {
                continue;
            };
            let mut e = Extension { slot: slot as u8, masters: [(0, 0.0); MAX_MASTERS], n: count as u8, mask };
            for (m, (mn, &c)) in masters.iter().zip(&coefs).take(count).enumerate() {
                let ml = ghost.local(mn.map(|v| v as usize)).expect("well nodes are ghosted") as u32;
                let pos = match st.eff_nodes[start..].iter().position(|&x| x == ml) {
                    Some(p) => p,
                    None => {
                        st.eff_nodes.push(ml);
                        st.eff_nodes.len() - 1 - start
                    }
                };
                e.masters[m] = (pos as u8, c);
            }
            st.ext.push(e);
        }
        if st.eff_nodes.len() - start == raw.len() {
            // No master beyond the raw stencil: the effective nodes are the raw ones.
            st.eff_nodes.truncate(start);
        }
        st.eff_offsets.push(st.eff_nodes.len());
        st.ext_offsets.push(st.ext.len());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [`extension_in`] of plane node (i, j) with `well(i, j)`, the masters as (i, j) pairs.
    #[allow(clippy::type_complexity)]
    fn extension(
        node: (usize, usize),
        pos: [f64; 2],
        toward: [f64; 2],
        well: &dyn Fn(i64, i64) -> bool,
        tiny: f64,
        diagonal: bool,
    ) -> Option<([(i64, i64); MAX_MASTERS], [f64; MAX_MASTERS], usize)> {
        let (m, c, n) = extension_in([node.0, node.1], pos, toward, &|a: [i64; 2]| well(a[0], a[1]), tiny, diagonal)?;
        Some((m.map(|a| (a[0], a[1])), c, n))
    }

    #[test]
    fn an_extension_reproduces_linear_fields_and_reaches_towards_the_particle() {
        // Well filled: i ≤ 3 (a body to the left of x = 3), any j.
        let well = |i: i64, j: i64| (0..=3).contains(&i) && (0..10).contains(&j);
        let pos = |i: i64, j: i64| [i as f64, j as f64];
        // Node (4, 5) reached from a particle at (3.8, 5.2): x-line from (3, 5) and (2, 5).
        let (m, c, n) = extension((4, 5), [4.0, 5.0], [3.8, 5.2], &well, 1e-12, false).unwrap();
        assert_eq!(n, 2);
        assert_eq!(&m[..2], &[(3, 5), (2, 5)]);
        for f in [|x: [f64; 2]| 1.0 + 2.0 * x[0] - 3.0 * x[1], |x: [f64; 2]| x[1]] {
            let v: f64 = (0..n).map(|k| c[k] * f(pos(m[k].0, m[k].1))).sum();
            assert!((v - f([4.0, 5.0])).abs() < 1e-12);
        }
        // A node diagonal to a corner (well: i ≤ 3 and j ≤ 3): no line, no triangle.
        let corner = |i: i64, j: i64| (0..=3).contains(&i) && (0..=3).contains(&j);
        assert!(extension((4, 4), [4.0, 4.0], [3.8, 3.8], &corner, 1e-12, false).is_none());
        // With B-splines, along the diagonal from (3, 3) and (2, 2), exact for linear fields.
        let (m, c, n) = extension((4, 4), [4.0, 4.0], [3.8, 3.7], &corner, 1e-12, true).unwrap();
        assert_eq!((n, m[0], m[1]), (2, (3, 3), (2, 2)));
        let f = |x: [f64; 2]| 0.7 + 1.5 * x[0] - 2.5 * x[1];
        let v: f64 = (0..n).map(|k| c[k] * f(pos(m[k].0, m[k].1))).sum();
        assert!((v - f([4.0, 4.0])).abs() < 1e-12);
        // Node (4, 3) beside the corner, reached from (3.8, 2.9): x-line.
        let (m, _, n) = extension((4, 3), [4.0, 3.0], [3.8, 2.9], &corner, 1e-12, false).unwrap();
        assert_eq!((n, m[0], m[1]), (2, (3, 3), (2, 3)));
        // A triangle when neither line has two well nodes: only (1, 1), (1, 2), (2, 1) are well.
        let tri = |i: i64, j: i64| [(1, 1), (1, 2), (2, 1)].contains(&(i, j));
        let (m, c, n) = extension((2, 2), [2.0, 2.0], [1.9, 1.8], &tri, 1e-12, false).unwrap();
        assert_eq!(n, 3);
        let f = |x: [f64; 2]| 0.5 - x[0] + 4.0 * x[1];
        let v: f64 = (0..n).map(|k| c[k] * f(pos(m[k].0, m[k].1))).sum();
        assert!((v - f([2.0, 2.0])).abs() < 1e-12);
    }

    /// The extension rules in three dimensions: a line along the axis the particle lies farthest
    /// on, a triangle of two axes when no line has two well-filled nodes (any pair of axes), the
    /// diagonal with B-splines; each reproduces a linear field of x, y and z at the node.
    #[test]
    fn a_three_dimensional_extension_reproduces_linear_fields() {
        let f = |n: [i64; 3]| 0.3 + 1.1 * n[0] as f64 - 0.7 * n[1] as f64 + 2.3 * n[2] as f64;
        let check = |node: [usize; 3], toward: [f64; 3], well: &dyn Fn([i64; 3]) -> bool, diagonal: bool| {
            let pos = node.map(|v| v as f64);
            let (m, c, n) = extension_in(node, pos, toward, well, 1e-12, diagonal).expect("an extension");
            assert!(m[..n].iter().all(|&a| well(a)), "{m:?}");
            let v: f64 = (0..n).map(|k| c[k] * f(m[k])).sum();
            assert!((v - f(node.map(|x| x as i64))).abs() < 1e-12, "{v} at {node:?}");
            (m, n)
        };
        // A body below z = 2 (k ≤ 2): node (4, 5, 3) reached from (3.9, 5.1, 2.7) extends along z.
        let below = |a: [i64; 3]| a.iter().all(|&v| v >= 0) && a[2] <= 2;
        let (m, n) = check([4, 5, 3], [3.9, 5.1, 2.7], &below, false);
        assert_eq!((n, m[0], m[1]), (2, [4, 5, 2], [4, 5, 1]));
        // The farthest axis first: from (3.6, 5.1, 2.9), x (−0.4) before z (−0.1); only z is well.
        let (m, _) = check([4, 5, 3], [3.6, 5.1, 2.9], &below, false);
        assert_eq!(m[0], [4, 5, 2]);
        let x_side = |a: [i64; 3]| a.iter().all(|&v| v >= 0) && a[0] <= 3;
        let (m, _) = check([4, 5, 3], [3.6, 5.1, 2.9], &x_side, false);
        assert_eq!(m[..2], [[3, 5, 3], [2, 5, 3]]);
        // Triangles of the pairs (x, y) and (x, z).
        let xy = |a: [i64; 3]| [[1, 2, 1], [2, 1, 1], [1, 1, 1]].contains(&a);
        let (m, n) = check([2, 2, 1], [1.9, 1.8, 1.0], &xy, false);
        assert_eq!((n, m), (3, [[1, 2, 1], [2, 1, 1], [1, 1, 1]]));
        let xz = |a: [i64; 3]| [[1, 2, 2], [2, 2, 1], [1, 2, 1]].contains(&a);
        let (_, n) = check([2, 2, 2], [1.8, 1.9, 1.7], &xz, false);
        assert_eq!(n, 3);
        // Along the diagonal with B-splines only.
        let diagonal = |a: [i64; 3]| [[1, 1, 1], [0, 0, 0]].contains(&a);
        assert!(extension_in([2, 2, 2], [2.0; 3], [1.8, 1.7, 1.9], &diagonal, 1e-12, false).is_none());
        let (m, _) = check([2, 2, 2], [1.8, 1.7, 1.9], &diagonal, true);
        assert_eq!(m[..2], [[1, 1, 1], [0, 0, 0]]);
    }

    /// The stencils of a three-dimensional model (a body over two of the grid's three z layers,
    /// GIMP with B̄, every cell of the box filled, the partly filled cells of its sloping top
    /// taking the volumetric strain of a full neighbour): every point's functions are a partition
    /// of unity reproducing linear fields (Σ S = 1, Σ ∇S = 0, Σ x_i ⊗ ∇S_i = I and
    /// Σ x_i ⊗ ∇̄S_i = I), its nodes numbered in the ghosted block; the cell fractions add up to the
    /// points' volume; points whose domains reach past the grid's planes are listed with their
    /// sides.
    #[test]
    fn three_dimensional_stencils_reproduce_linear_fields() {
        let text = crate::case::tests_support::with_grid("[0.4, 1.0, 0.3]", "[4, 10, 3]")
            .replace(
                "shape = { rectangle = { min = [0.0, 0.0], max = [0.1, 1.0] } }",
                "shape = { polygon = { vertices = [[0.0, 0.0], [0.4, 0.0], [0.4, 0.75], [0.0, 1.0]] } }\n        z = [0.0, 0.2]",
            )
            .replace("[analysis]", "[stabilisation]\n        bbar = true\n        [analysis]");
        let c = crate::validation::load(&text, "t", &[]).unwrap();
        let model = Model::build_solid(&c, |_| true);
        let g = &model.grid;
        let ghost = GhostedRange { start: [0; 3], count: g.nodes(), dof: 1 };
        let phi = cell_fractions(&model, &ghost);
        let total: f64 = phi.iter().sum::<f64>() * g.h.iter().product::<f64>();
        let volume: f64 = model.particles.volume.iter().sum();
        assert!((total - volume).abs() < 1e-12 * volume, "{total} against {volume}");
        let roots = CellRoots::new(&ghost, g.cells, &phi);
        // An empty cell above the sloping top (x ∈ [0.3, 0.4], y ∈ [0.8, 0.9]) takes a well-filled
        // neighbour's strain; a full cell its own.
        assert_eq!(phi[ghost.local([3, 8, 0]).unwrap()], 0.0);
        let top = roots.root_of([3, 8, 0]);
        assert!(top != [3, 8, 0] && phi[ghost.local(top).unwrap()] >= CELL_FILLED_FRACTION, "{top:?}");
        assert_eq!(roots.root_of([1, 2, 1]), [1, 2, 1]);
        let (st, crossings) = build_in::<3, { shape::MAX_STENCIL_3D }>(&model, &ghost, &roots).unwrap();
        assert_eq!(st.len(), model.particles.len());
        for k in 0..st.len() {
            let (nodes, basis) = st.get(k);
            let pos: Vec<[f64; 3]> = nodes.iter().map(|&l| g.position(ghost.indices(l as usize))).collect();
            let sum: f64 = basis.iter().map(|b| b.s).sum();
            assert!((sum - 1.0).abs() < 1e-13, "point {k}: Σ S = {sum}");
            for a in 0..3 {
                let gs: f64 = basis.iter().map(|b| b.g[a]).sum();
                assert!(gs.abs() < 1e-10, "point {k}: Σ ∂S/∂x{a} = {gs}");
                for b in 0..3 {
                    let want = if a == b { 1.0 } else { 0.0 };
                    let xg: f64 = pos.iter().zip(basis).map(|(x, n)| x[a] * n.g[b]).sum();
                    let xgv: f64 = pos.iter().zip(basis).map(|(x, n)| x[a] * n.gv[b]).sum();
                    assert!((xg - want).abs() < 1e-10 && (xgv - want).abs() < 1e-10, "point {k}: {xg} {xgv} ({a}{b})");
                }
            }
        }
        // The domains end on grid planes, so their supports' nodes beyond those planes have zero
        // weight and gradients: the stored stencils leave them out and keep every other node.
        assert!(only_reached_nodes(&model));
        assert!(st.basis.iter().all(|b| !b.is_zero()));
        for k in 0..st.len() {
            let (x, lp) = (model.particles.x[k], model.particles.lp[k]);
            let raw: shape::Stencil<3, { shape::MAX_STENCIL_3D }> = shape::stencil_in(model.basis, g, x, lp);
            let (nodes, _) = st.get(k);
            for (n, w, d) in raw.iter().filter(|(_, w, d)| *w != 0.0 || d.iter().any(|&v| v != 0.0)) {
                let l = ghost.local(n.map(|v| v as usize)).unwrap() as u32;
                assert!(nodes.contains(&l), "point {k}: node {n:?} (S = {w}, ∇S = {d:?}) left out");
            }
        }
        assert!(2 * st.nodes.len() < 27 * st.len(), "{} slots for {} points", st.nodes.len(), st.len());
        // Domains end on the grid's planes: none is past them. Moved past x_min and z_max, two are.
        assert!(crossings.is_empty());
        let mut moved = model.clone();
        moved.particles.x[0][0] -= 0.02;
        let last = moved.particles.len() - 1;
        moved.particles.x[last][2] = 0.29;
        let (st, crossings) = build_in::<3, { shape::MAX_STENCIL_3D }>(&moved, &ghost, &roots).unwrap();
        let sides: Vec<(usize, &str)> = crossings.iter().map(|c| (c.k, SIDES[c.side])).collect();
        assert_eq!(sides, [(0, "x_min"), (last, "z_max")]);
        // Their slots beyond the grid complete the partition of unity and the reproduction of
        // linear fields (Σ x_i ⊗ ∇S_i = I over the raw and the held slots); the cell-centre
        // gradients ∇̄S need none (the slots' are zero); each slot's wall node is the nearest
        // node on the grid's edge.
        assert!(st.beyond.iter().all(|w| w.k == 0 || w.k as usize == last));
        for (k, side) in [(0, 0), (last, 5)] {
            let (nodes, basis) = st.get(k);
            let beyond = st.beyond_of(k);
            assert!(beyond.iter().any(|w| w.basis.s > 0.0), "point {k}: no weight beyond the grid");
            let mut ops: Vec<([f64; 3], NodeBasis<3>)> =
                nodes.iter().map(|&l| g.position(ghost.indices(l as usize))).zip(basis.iter().copied()).collect();
            let sum_in: f64 = ops.iter().map(|(_, b)| b.s).sum();
            assert!(sum_in < 1.0 - 1e-3, "point {k}: the grid keeps Σ S = {sum_in}");
            ops.extend(beyond.iter().map(|w| (w.at, w.basis)));
            let sum: f64 = ops.iter().map(|(_, b)| b.s).sum();
            assert!((sum - 1.0).abs() < 1e-13, "point {k}: Σ S = {sum} with the slots beyond");
            for a in 0..3 {
                for b in 0..3 {
                    let want = if a == b { 1.0 } else { 0.0 };
                    let xg: f64 = ops.iter().map(|(x, n)| x[a] * n.g[b]).sum();
                    let xgv: f64 = ops.iter().map(|(x, n)| x[a] * n.gv[b]).sum();
                    assert!((xg - want).abs() < 1e-10 && (xgv - want).abs() < 1e-10, "point {k}: {xg} {xgv} ({a}{b})");
                }
            }
            let hi = g.extent_max();
            let outside = |w: &WallSlot<3>, d: usize| w.at[d] < g.origin[d] || w.at[d] > hi[d];
            assert!(beyond.iter().any(|w| w.basis.s > 0.0 && w.normal as usize == side / 2));
            for w in beyond {
                let wall = g.position(ghost.indices(w.wall as usize));
                assert!(outside(w, w.normal as usize), "{:?} is not beyond the grid in {}", w.at, w.normal);
                let clamped: [f64; 3] = std::array::from_fn(|d| w.at[d].clamp(g.origin[d], hi[d]));
                assert!((0..3).all(|d| (wall[d] - clamped[d]).abs() < 1e-12), "{wall:?} next to {:?}", w.at);
            }
        }
    }
}
