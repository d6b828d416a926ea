//! One step t_n → t_{n+1} as a value ([`Step`]): built by one pass ([`super::prepare`]), handed
//! to the solver, read by the balance and the particle update, and dropped when the step ends; and
//! what its solve found ([`Solution`]).

use super::dofs::DofMap;
use super::pattern::Pattern;
use super::stencils::Stencils;
use super::stiffness::MappedStiffness;
use crate::kernels::{self, DrainedFace};
use crate::layout::Layout;
use crate::scheme::Scheme;
use std::sync::Arc;

/// A prepared step (points of dimension D with at most M stencil nodes).
#[derive(Debug)]
pub struct Step<const D: usize = 2, const M: usize = { kernels::MAX_NODES }> {
    /// The step's time scheme.
    pub(super) scheme: Scheme,
    /// The step's Δt [s].
    pub(super) dt: f64,
    /// The unknowns per node.
    pub(super) layout: Layout,
    /// Body acceleration at t_{n+1} per body.
    pub(super) body_acc: Vec<[f64; D]>,
    pub(super) stencils: Stencils<D>,
    pub(super) dofs: DofMap,
    /// External nodal forces at t_{n+1} (tractions) per ghosted dof, on the nodes that carry them.
    pub(super) fext: Vec<f64>,
    /// The same at t_n (for the generalized-α history and the work of the step).
    pub(super) fext_old: Vec<f64>,
    /// The generalized-α history per ghosted dof: α_m M a_n + α_f (forces at t_n) − α_f f_ext,n,
    /// or a geometrically linear step's out-of-balance of its start (empty otherwise).
    pub(super) history: Vec<f64>,
    /// Porosity gradient at each particle at t_n (two-phase).
    pub(super) grad_n: Vec<[f64; D]>,
    /// v_u, a_u, v_w, a_w at t_n at each particle, from the nodal projections.
    pub(super) smooth: Vec<[[f64; D]; 4]>,
    /// The norm of the step's force magnitudes over the free dofs, summed over ranks [N per m].
    pub(super) force_scale: f64,
    /// Pressure-projection cells.
    pub(super) projection: Vec<ProjectionCell>,
    /// The matrix pattern, shared with the solver's matrix while it covers the particles' pairs
    /// (a new one, which every rank agrees on, makes the solver build a new matrix).
    pub(super) pattern: Arc<Pattern<D>>,
    /// The bands of node rows the threads assemble.
    pub(super) bands: Vec<Band>,
    /// The pattern block of every corner pair (a, b) of each pressure-projection cell, C a + b for
    /// its C corners.
    pub(super) projection_blocks: Vec<Vec<u32>>,
    /// (diagonal block, component) of every owned fixed dof.
    pub(super) fixed_diagonals: Vec<(u32, usize)>,
    /// The multilinear preconditioning matrix's cells and pattern (`-porompm_pc_matrix
    /// multilinear`; `None`: the preconditioner is built from the Jacobian).
    pub(super) lowered: Option<Lowered<D>>,
    /// The pressure unknown's scale s [Pa/m] ([`pressure::scale`]): PETSc sees Δp / s, and the
    /// continuity rows multiplied by s.
    pub(super) p_scale: f64,
    /// The norm of the force magnitudes of each field (`Layout::fields`) over its free dofs, in
    /// PETSc's scaling: the scale of the field's residual.
    pub(super) field_scales: Vec<f64>,
    /// The diagonal the fixed-stress Schur preconditioner adds to A_pp, per owned pressure row
    /// (empty without that preconditioner).
    pub(super) fixed_stress: Vec<f64>,
    /// The free-surface aggregates of the u–p–U system's Schur preconditioner (empty without it).
    pub(super) schur_groups: Vec<Vec<usize>>,
    /// The drained faces imposed weakly and the particle of each, in increasing order.
    pub(super) faces: Vec<DrainedFace<D, M>>,
    pub(super) face_owner: Vec<usize>,
    /// The material stiffness of the Newton matrix (`stabilisation.stiffness`).
    pub(super) stiffness: MappedStiffness,
    /// An explicit step: the terms of its start (σ_n on x_n and the body force of t_{n+1}, without
    /// the loads), this rank's shares per ghosted dof; empty vectors otherwise.
    pub(super) start_terms: StartTerms,
    /// The first step of a Newmark stage: what its start is out of balance by per
    /// ghosted dof, summed over ranks (M a_n + f_int,n − f_n, [`Step::imbalance_at_start`]);
    /// empty otherwise.
    pub(super) start_imbalance: Vec<f64>,
    /// A two-phase explicit step with the nodal pore pressure: whether each ghosted node is
    /// drained; empty otherwise.
    pub(super) drained: Vec<bool>,
    /// The mean filled fraction of each moving boundary's nodes at the step's start (None for a
    /// boundary that prescribes no motion).
    pub boundary_fill: Vec<Option<f64>>,
    /// The Jacobian rows that rigid bodies' ties rewrite ([`super::ties`]).
    pub(super) tied_rows: super::ties::TiedRows,
}

/// The multilinear preconditioning matrix's side of a step: each point's cell corners (2^D
/// ghosted node numbers per point), which ghosted nodes are no point's corner on any rank (they
/// take the diagonal blocks of the points' own bases), the pattern, and the (diagonal block,
/// component) of every owned fixed dof in it.
#[derive(Debug, Clone)]
pub(super) struct Lowered<const D: usize> {
    pub corners: Vec<u32>,
    pub lone: Vec<bool>,
    pub pattern: Arc<Pattern<D>>,
    pub fixed_diagonals: Vec<(u32, usize)>,
}

impl<const D: usize> Lowered<D> {
    /// The corners of point `k`'s cell.
    pub fn corners_of(&self, k: usize) -> &[u32] {
        let c = 1 << D;
        &self.corners[k * c..(k + 1) * c]
    }
}

/// The nodal terms of an explicit step's start, this rank's shares per ghosted dof (see
/// [`Points::nodal_terms`] at Δd = 0): one pass over the points gives the force that accelerates
/// the nodes and the step's equilibrium identity.
#[derive(Debug, Clone, Default)]
pub(super) struct StartTerms {
    /// The residual without the external loads: f_int(σ_n) minus the body force.
    pub all: Vec<f64>,
    /// `all` minus the internal forces: the body force's share.
    pub inertia: Vec<f64>,
    /// Σ of the absolute values of the points' blocks plus the absolute external loads.
    pub magnitude: Vec<f64>,
}

/// What a step's solve found: the nodal increments and, for an explicit step, what its particle
/// update and its balance read.
#[derive(Debug, Clone, Default)]
pub struct Solution {
    /// Δd per ghosted dof in physical units (extended motion is not stored here).
    pub(super) increments: Vec<f64>,
    /// An explicit step: the lumped inertia m_i a_i of its nodal update plus the local damping
    /// force and, two-phase, the drag on the phase, per ghosted dof (summed over ranks); empty
    /// otherwise.
    pub(super) explicit_inertia: Vec<f64>,
    /// The F̄ projection of each particle's explicit step: the scale c_p of its increment, the scale
    /// s_p of its total deformation and its projected J̄_p^{n+1}; empty otherwise.
    pub(super) fbar_scale: Vec<[f64; 3]>,
    /// An explicit XPIC step: the nodal field w − v^n its points' velocities take, per ghosted dof.
    pub(super) xpic_correction: Vec<f64>,
    /// An explicit step: the nodal velocities v_i^n of its grid update, per ghosted dof.
    pub(super) start_velocity: Vec<f64>,
    /// A two-phase explicit step with the nodal pore pressure: each point's Δp, Σ_i S_ip Δp_i.
    pub(super) pressure_increment: Vec<f64>,
}

/// A cell of the pressure projection: its 2^D corner nodes (ghosted numbers, x fastest) and the
/// C × C block S of `kernels::pressure_projection`, row by row.
#[derive(Debug, Clone, Default)]
pub(super) struct ProjectionCell {
    pub nodes: Vec<u32>,
    pub s: Vec<f64>,
}

/// A range `lo..hi` of ghosted nodes (whole layers of the ghosted grid along its last direction:
/// rows in two dimensions, planes of constant z in three; so one range of the ghosted numbering)
/// whose rows of the residual and of the matrix one thread assembles (see [`super::points`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Band {
    pub lo: u32,
    pub hi: u32,
}

impl Band {
    /// Whether ghosted node `a` lies in the band.
    pub fn holds(&self, a: u32) -> bool {
        a >= self.lo && a < self.hi
    }
}

impl<const D: usize, const M: usize> Step<D, M> {
    /// The bytes the step's data hold on the heap, `(stencils, the rest)`: the stencils, and the
    /// dof map, loads, predictors, bands, projection, faces, mapped stiffness, start terms and the
    /// multilinear preconditioning matrix's corners (the matrix patterns, shared with the system's
    /// matrices, are the matrices').
    pub fn heap_bytes(&self) -> (usize, usize) {
        use crate::algebra::heap::{capacity as c, nested};
        let projection = c(&self.projection) + self.projection.iter().map(|p| c(&p.nodes) + c(&p.s)).sum::<usize>();
        let t = &self.start_terms;
        let per_dof = [&self.fext, &self.fext_old, &self.history, &self.field_scales, &self.fixed_stress]
            .into_iter()
            .chain([&t.all, &t.inertia, &t.magnitude, &self.start_imbalance])
            .map(c)
            .sum::<usize>();
        let per_point = c(&self.grad_n) + c(&self.smooth) + c(&self.body_acc);
        let groups = nested(&self.projection_blocks) + nested(&self.schur_groups);
        let faces = c(&self.faces) + c(&self.face_owner) + c(&self.drained) + c(&self.boundary_fill);
        let rest = per_dof
            + per_point
            + projection
            + groups
            + faces
            + self.dofs.heap_bytes()
            + c(&self.bands)
            + c(&self.fixed_diagonals)
            + self.lowered.as_ref().map_or(0, |l| c(&l.corners) + c(&l.lone) + c(&l.fixed_diagonals))
            + self.stiffness.heap_bytes();
        (self.stencils.heap_bytes(), rest)
    }

    /// Unknowns of the step (free dofs over all ranks).
    pub fn free_dofs(&self) -> usize {
        self.dofs.free_dofs
    }

    /// The drained faces of particle `k` (usually none).
    pub(super) fn faces_of(&self, k: usize) -> &[DrainedFace<D, M>] {
        let lo = self.face_owner.partition_point(|&o| o < k);
        let hi = lo + self.face_owner[lo..].partition_point(|&o| o == k);
        &self.faces[lo..hi]
    }

    /// The physical increment of ghosted dof `q` per unit of its PETSc unknown: s for a pressure
    /// dof, 1 for the others.
    pub(super) fn unit(&self, q: usize) -> f64 {
        match self.layout.p {
            Some(p) if q % self.dofs.nd == p => self.p_scale,
            _ => 1.0,
        }
    }
}
