//! The skeleton's material stiffness in the Newton matrix, as `stabilisation.stiffness` asks
//! ([001] §5, docs/stiffness.md): each material point's share of the
//! cells it maps to, prepared once per step on x_n.
//!
//! * `particle`: the exact tangent (share: none, material factor 1).
//! * `w_star`: particle integration with W*_p = W_p omp/cmp ([001] Eq. 15): the point's material
//!   tangent scaled by omp/cmp, omp the nominal number of points of a full cell (n² for n × n per
//!   cell, from the point's initial half-widths) and cmp the number of points whose centre is in
//!   its cell now.
//! * `gauss_mapping`, `double_mapping`: the point's moduli go to the four nodes of the cell holding
//!   its centre with the bilinear weights N_i(x_p) and the integration weight W_p = A_p/|J| (GM)
//!   or W*_p (DM), [001] Eqs. 16 and 19.
//! * `double_mapping_gimp`: to the nodes of every cell its domain overlaps, with the local GIMP
//!   weights S*^e_ip of `shape::local_gimp` and W_p, Eq. 20.
//!
//! K_e = Σ_g B_gᵀ (Σ_i N_i(x_g) Σ_p w_ip D_p) B_g |J| is linear in the points' shares, so each point
//! adds its own K_e^p into its own tangent block (`kernels::cell::mapped_stiffness` with
//! D_i = w_ip D_p), and extensions, bands and fixed dofs treat it like the rest of the block. A
//! point's cell is on its rank (points belong to the rank that owns the cell holding their
//! centre), so cmp needs no communication. A_p is the area in the (x, y) plane, so that in axial
//! symmetry r enters once, through the Gauss points' 2πr_g.
//!
//! D_p is the point's elastic matrix, as in [001] (Eq. 5, and its initial-stiffness iteration for
//! plasticity), which stays positive definite while points soften. (With either the elastic or
//! the consistent moduli mapped, Newton needed more than its default 30 iterations at the vertical
//! cut's first dynamic step; with the elastic ones and 300 (`super::newton_iterations`) it converges, about 200
//! iterations a step.) Every option but `particle` gives an approximate Jacobian: Newton
//! converges at a linear rate to the answer of the residual, which is unchanged;
//! `-snes_type ksponly` makes each step the single linear solve of [001].

use super::stencils::Stencils;
use crate::case::Stiffness;
use crate::kernels::cell::{mapped_force_operators, mapped_stiffness, q4, CellGeometry, Moduli};
use crate::kernels::NodeBasis;
use crate::model::{shape, Model};
use crate::soils;
use petsc::GhostedRange;

/// A cell (its lower-left node) and a point's weights w_i W_p of its four nodes.
type CellWeights = ((usize, usize), [f64; 4]);

/// One point's share of one cell.
#[derive(Debug, Clone, Copy)]
struct Share {
    /// The cell's four nodes as slots of the point's stencil, in `kernels::cell`'s order.
    slots: [u8; 4],
    /// The point's share K_e^p of the cell's stiffness (8 × 8 on the four nodes' u_x, u_y): the
    /// moduli are elastic and the weights fixed on x_n, so it is the same for every Newton
    /// iteration of the step and is computed once, here.
    ke: [[f64; 8]; 8],
}

/// The mapped-stiffness shares of a step's points.
#[derive(Debug, Default)]
pub struct MappedStiffness {
    /// The factor of each point's own material tangent (1, omp/cmp or 0).
    material: Vec<f64>,
    shares: Vec<Share>,
    /// Point k's shares are `shares[offsets[k]..offsets[k + 1]]`.
    offsets: Vec<usize>,
}

/// The cells each point maps to under a mapped stiffness, with their weights (shared by the
/// stiffness and the double-mapped forces, so that both map alike).
struct Mapping<'a> {
    model: &'a Model,
    ghost: &'a GhostedRange,
    /// cmp: the points whose centre is in each cell, keyed by the cell's lower-left node.
    count: Vec<u32>,
}

impl<'a> Mapping<'a> {
    fn new(model: &'a Model, ghost: &'a GhostedRange) -> Mapping<'a> {
        let mut m = Mapping { model, ghost, count: vec![0; ghost.len()] };
        for k in 0..model.particles.len() {
            if let Some(l) = m.cell_key(k) {
                m.count[l] += 1;
            }
        }
        m
    }

    /// The ghosted node of the lower-left corner of point `k`'s cell.
    fn cell_key(&self, k: usize) -> Option<usize> {
        let g = &self.model.grid;
        g.cell_of(self.model.particles.x[k]).and_then(|(i, j)| self.ghost.node(i, j))
    }

    /// W*_p / W_p = omp/cmp ([001] Eq. 15).
    fn w_star(&self, k: usize) -> f64 {
        let (g, ps) = (&self.model.grid, &self.model.particles);
        let omp = (g.h[0] * g.h[1] / (4.0 * ps.lp0[k][0] * ps.lp0[k][1])).round();
        self.cell_key(k).map_or(1.0, |l| omp / self.count[l].max(1) as f64)
    }

    /// The factor of point `k`'s own material tangent and the cells it maps to with its weights
    /// w_i W_p of their nodes.
    fn of(&self, k: usize) -> Result<(f64, Vec<CellWeights>), String> {
        let (model, g, ps) = (self.model, &self.model.grid, &self.model.particles);
        let w_p = model.area(k) / (g.h[0] * g.h[1] / 4.0);
        Ok(match model.stiffness {
            Stiffness::Particle => (1.0, Vec::new()),
            Stiffness::WStar => (self.w_star(k), Vec::new()),
            Stiffness::GaussMapping | Stiffness::DoubleMapping => {
                let (i, j) = g.cell_of(ps.x[k]).ok_or_else(|| outside(model, k))?;
                let xi = g.local_coordinates((i, j), ps.x[k]);
                let w = if model.stiffness == Stiffness::DoubleMapping { self.w_star(k) * w_p } else { w_p };
                (0.0, vec![((i, j), q4(xi, g.h).0.map(|n| n * w))])
            }
            Stiffness::DoubleMappingGimp => {
                let (list, n) = shape::local_gimp(g, ps.x[k], ps.lp[k]);
                let cells = list[..n].iter().map(|&((i, j), w)| ((i as usize, j as usize), w.map(|s| s * w_p)));
                (0.0, cells.collect())
            }
        })
    }

    /// The cell (`i`, `j`) as the cell kernels see it.
    fn geometry(&self, (i, j): (usize, usize)) -> CellGeometry {
        let g = &self.model.grid;
        CellGeometry {
            h: g.h,
            lo: g.node_position(i, j),
            bbar: self.model.bbar,
            axisymmetric: self.model.geometry.axisymmetric(),
        }
    }

    /// The slots in point `k`'s stencil `nodes` of the four nodes of cell (`i`, `j`), in
    /// `kernels::cell`'s order.
    fn slots(&self, k: usize, nodes: &[u32], (i, j): (usize, usize)) -> Result<[u8; 4], String> {
        let mut slots = [0u8; 4];
        for (s, (di, dj)) in slots.iter_mut().zip([(0, 0), (1, 0), (0, 1), (1, 1)]) {
            let l = self.ghost.node(i + di, j + dj).ok_or_else(|| outside(self.model, k))?;
            *s = nodes.iter().position(|&n| n as usize == l).ok_or_else(|| {
                format!(
                    "material point {}: node ({}, {}) of a cell it maps its stiffness or force to is not in its stencil",
                    self.model.particles.id[k],
                    i + di,
                    j + dj
                )
            })? as u8;
        }
        Ok(slots)
    }
}

impl MappedStiffness {
    /// The bytes the mapped stiffness holds on the heap.
    pub fn heap_bytes(&self) -> usize {
        use crate::algebra::heap::capacity as c;
        c(&self.material) + c(&self.shares) + c(&self.offsets)
    }

    /// The shares of this rank's points for the model's option (empty for `particle`).
    pub(super) fn prepare(model: &Model, ghost: &GhostedRange, st: &Stencils) -> Result<MappedStiffness, String> {
        let mut out = MappedStiffness::default();
        if model.stiffness == Stiffness::Particle {
            return Ok(out);
        }
        let mapping = Mapping::new(model, ghost);
        let ps = &model.particles;
        out.offsets.push(0);
        for k in 0..ps.len() {
            let (factor, cells) = mapping.of(k)?;
            out.material.push(factor);
            let (nodes, _) = st.get(k);
            let d: &Moduli = &soils::plane_block(&model.materials[ps.material[k] as usize].model.elastic().d);
            for (cell, weights) in cells {
                let slots = mapping.slots(k, nodes, cell)?;
                let d_nodes: [Moduli; 4] = std::array::from_fn(|n| d.map(|row| row.map(|v| v * weights[n])));
                out.shares.push(Share { slots, ke: mapped_stiffness(&mapping.geometry(cell), &d_nodes) });
            }
            out.offsets.push(out.shares.len());
        }
        Ok(out)
    }

    /// The factor of point `k`'s own material tangent (1 for the exact tangent).
    pub(super) fn material(&self, k: usize) -> f64 {
        self.material.get(k).copied().unwrap_or(1.0)
    }

    /// Adds point `k`'s mapped stiffness, times `weight` (the scheme's w_f), to the u–u entries of
    /// its tangent `block` (m × m, `nd` dofs per node).
    pub(super) fn add(&self, k: usize, weight: f64, block: &mut [f64], m: usize, nd: usize) {
        let Some(shares) = self.offsets.get(k + 1).map(|&hi| &self.shares[self.offsets[k]..hi]) else { return };
        for share in shares {
            let ke = &share.ke;
            for (a, &sa) in share.slots.iter().enumerate() {
                for (b, &sb) in share.slots.iter().enumerate() {
                    for c in 0..2 {
                        for e in 0..2 {
                            block[(sa as usize * nd + c) * m + sb as usize * nd + e] +=
                                weight * ke[2 * a + c][2 * b + e];
                        }
                    }
                }
            }
        }
    }
}

/// [001]'s double-mapped internal force (`stabilisation.internal_force = "mapped"`): each point's
/// force operators per raw stencil slot (`Stencils::forces`), Σ over the cells it maps to of
/// `kernels::cell::mapped_force_operators` with the weights of the mapped stiffness, per unit of
/// the point's volume V_n (what `kernels::Point::with_forces` takes). A point's stress then acts
/// on the nodes as the stiffness's share of it would (the same cells and weights); the residual's
/// terms and their exact tangent follow unchanged (`kernels::stress`).
pub(super) fn mapped_forces(model: &Model, ghost: &GhostedRange, st: &mut Stencils) -> Result<(), String> {
    let mapping = Mapping::new(model, ghost);
    let mut forces = vec![NodeBasis::default(); st.basis.len()];
    for k in 0..st.len() {
        let (_, cells) = mapping.of(k)?;
        let (nodes, _) = st.get(k);
        let first = st.offsets[k];
        let v = model.particles.volume[k];
        for (cell, weights) in cells {
            let slots = mapping.slots(k, nodes, cell)?;
            for (&slot, op) in slots.iter().zip(mapped_force_operators(&mapping.geometry(cell), weights)) {
                forces[first + slot as usize].add_scaled(&op, 1.0 / v);
            }
        }
    }
    st.forces = forces;
    Ok(())
}

/// The error of a point whose cell is not on this rank's grid.
fn outside(model: &Model, k: usize) -> String {
    let ps = &model.particles;
    format!(
        "material point {} at ({:.4}, {:.4}) m: its cell is outside this rank's ghost region",
        ps.id[k], ps.x[k][0], ps.x[k][1]
    )
}
