//! The forces of a converged step ([`StepForces`]): each boundary's reaction, the work of the
//! external forces, the first moment of the nodal forces for the equilibrium identity, the
//! magnitude of each field's equations, and the nodal diagnostics K_mag and F^int_mag of [001].

use super::points::Points;
use super::space::NodeSpace;
use super::step::{Solution, Step};
use super::System;
use crate::model::Model;
use crate::parallel::Collective;

/// The forces of a converged step, summed over ranks, for the equilibrium identity and the
/// boundaries' reactions.
#[derive(Debug, Clone)]
pub struct StepForces<const D: usize = 2> {
    /// Σ_i x'_i ⊗ (F_ext,i + R_i − F_inertia,i) over the nodes, with x' = x + Δu the nodes' positions
    /// at t_{n+1} relative to `origin` (rows a, columns b: x_a F_b).
    pub moment: [[f64; D]; D],
    /// The largest of the moments of the external forces, the reactions and the inertia forces
    /// (Frobenius norms), which scales the identity's error.
    pub scale: f64,
    /// The reference point of the moments [m].
    pub origin: [f64; D],
    /// The reaction of each boundary (index into `Model::boundaries`) on the material: the force
    /// the fixed dofs of both phases exert [N per m in two dimensions, N in three].
    pub reactions: Vec<[f64; D]>,
    /// The reactions per ghosted dof, for the work of the next step on the same node space.
    pub reactions_by_dof: Vec<f64>,
    /// The motion of each rigid body over the step (a boundary under a force; zero for the other
    /// boundaries): the displacement of its force's point along x, y, z [m] (zero in the
    /// directions it does not tie), then its rotation about x, y, z [rad] (zero unless it rotates;
    /// in the plane about z alone).
    pub rigid_motion: Vec<[f64; 6]>,
    /// The moment about the origin of each boundary's reactions at its grid nodes, Σ x_i × R_i at
    /// their grid positions [N m per m in the plane (about z), N m in three dimensions]: for a
    /// rigid body that rotates, the moment of its force about the origin when it is in balance
    /// (the shares of the held slots beyond a wall, which only walls have, are left out).
    pub reaction_moments: Vec<[f64; 3]>,
    /// The work of the external forces and the reactions over the step, Σ_i F̄_i · Δd_i over the
    /// displacement dofs of both phases, with F̄ the mean of the forces at t_n and t_{n+1}
    /// (trapezoidal; the reactions at t_n are the last step's, none after a new node space; at
    /// the first step of a Newmark stage the free dofs' force at t_n is the one its start is in
    /// balance with, f_n + r_n) [J per m].
    pub work: f64,
    /// The norm of each field's equation magnitudes at the converged state (Σ over particles of
    /// their absolute residual blocks plus the absolute loads, over the free dofs, in PETSc's
    /// scaling): with the magnitudes at the step's start, the scale of the field's final
    /// residual (a step that starts at rest has no continuity terms before it moves).
    pub field_scales: Vec<f64>,
    /// Whether the forces are those of the step's start (an explicit step: σ_n on x_n), so that
    /// ∫σ dV must be taken before the particle update; otherwise at the converged state.
    pub at_start: bool,
    /// K_mag and F^int_mag ([001] Eqs. 25–26) per owned node, when they were asked for.
    pub node_diagnostics: Vec<[f64; 2]>,
}

impl<const D: usize> Default for StepForces<D> {
    fn default() -> Self {
        StepForces {
            moment: [[0.0; D]; D],
            scale: 0.0,
            origin: [0.0; D],
            reactions: Vec::new(),
            reactions_by_dof: Vec::new(),
            rigid_motion: Vec::new(),
            reaction_moments: Vec::new(),
            work: 0.0,
            field_scales: Vec::new(),
            at_start: false,
            node_diagnostics: Vec::new(),
        }
    }
}

impl<const D: usize, const M: usize, const N: usize> System<D, M, N> {
    /// The forces of the converged `step` (collective): the moment of the external, reaction and
    /// inertia forces about the grid's centre for the equilibrium identity, and each boundary's
    /// reaction; with `diagnostics` also K_mag and F^int_mag per owned node. `last_reactions` are the
    /// reactions per ghosted dof of the last step on the same node space (empty after a new one).
    /// Under the generalized-α method the balance holds at t_{n+1−α_f}; the "inertia" is then
    /// everything in it but the internal and external forces at t_{n+1} (see
    /// [`Points::nodal_terms`]).
    pub fn forces(
        &mut self,
        step: &Step<D, M>,
        solution: &Solution,
        model: &Model<D>,
        coll: &Collective,
        diagnostics: bool,
        last_reactions: &[f64],
    ) -> Result<StepForces<D>, String> {
        let space = &mut self.space;
        let nd = space.layout.nd;
        let ng = space.ghost.len() * nd;
        // An explicit step's forces are those of its start (σ_n on x_n, [`super::explicit`]): its
        // balance is taken there, against the stress before the particle update
        // (`StepForces::at_start`).
        let at_start = model.integration.is_explicit();
        let xl = if at_start { vec![0.0; ng] } else { solution.increments.clone() };
        let (mut all, mut inertia, mut magnitude) = if at_start {
            let start = &step.start_terms;
            (start.all.clone(), start.inertia.clone(), start.magnitude.clone())
        } else {
            (vec![0.0; ng], vec![0.0; ng], vec![0.0; ng])
        };
        let points = Points::<D, M, N>::new(model, step);
        if !at_start {
            points.nodal_terms(&xl, &mut all, &mut inertia, &mut magnitude);
        }
        let node_diagnostics = if diagnostics { nodal_diagnostics(space, &points, &xl)? } else { Vec::new() };
        let walls = points.wall_shares(&xl, at_start);
        let mut fext = step.fext.clone();
        let mut fext_old = step.fext_old.clone();
        // A rigid body's force acts on the material through the body's reactions.
        super::ties::add_forces(&step.dofs, -1.0, &mut fext, &mut fext_old);
        for v in [&mut all, &mut inertia, &mut fext, &mut fext_old, &mut magnitude] {
            space.sum_over_ranks(v).map_err(|e| e.to_string())?;
        }
        // An explicit step's inertia is its lumped nodal update's (already summed over ranks).
        for (i, m) in inertia.iter_mut().zip(&solution.explicit_inertia) {
            *i += m;
        }
        let field_scales = space.field_norms(step, &magnitude, coll)?;
        let g = &model.grid;
        let origin = moments_origin(model);
        let nb = model.boundaries.len();
        // [total moment (D²), external (D²), reaction (D²), inertia (D²), work, reactions per
        // boundary (D nb), rigid motions per boundary (6 nb), reaction moments per boundary (3 nb)]
        let dd = D * D;
        let (motions_at, moments_at) = (4 * dd + 1 + D * nb, 4 * dd + 1 + (D + 6) * nb);
        let mut local = vec![0.0; 4 * dd + 1 + (D + 9) * nb];
        // Each rigid body's motion over the step, from its masters' increments.
        for (b, slots) in super::ties::motions(&step.dofs, &solution.increments) {
            local[motions_at + 6 * b..motions_at + 6 * b + 6].copy_from_slice(&slots);
        }
        let mut reactions = vec![0.0; ng];
        // (dof component, in-plane direction) of the solid and water motion.
        let motion: Vec<(usize, usize)> =
            space.motion().into_iter().map(|c| (c, if c < D { c } else { c - space.layout.w.unwrap_or(0) })).collect();
        for &a in &space.owned_nodes {
            let l = a as usize;
            let p = g.position(space.ghost.indices(l));
            let u = &xl[l * nd..l * nd + D];
            let xr: [f64; D] = std::array::from_fn(|d| p[d] + u[d] - origin[d]);
            for &(c, dir) in &motion {
                let q = l * nd + c;
                let b = step.dofs.boundary[q];
                let reaction = if (b as usize) < nb { all[q] - fext[q] } else { 0.0 };
                reactions[q] = reaction;
                let reaction_old = last_reactions.get(q).copied().unwrap_or(reaction);
                // The first step of a Newmark stage: the force its start is in balance with is
                // f_n + r_n (r_n = `start_imbalance`, zero where a boundary holds the dof).
                let start = if (b as usize) < nb { 0.0 } else { step.start_imbalance.get(q).copied().unwrap_or(0.0) };
                local[4 * dd] +=
                    0.5 * (fext_old[q] + start + fext[q] + reaction_old + reaction) * solution.increments[q];
                book_node_forces(&mut local, nb, b as usize, &xr, dir, [fext[q], reaction, inertia[q]]);
                if (b as usize) < nb {
                    let m = &mut local[moments_at + 3 * b as usize..moments_at + 3 * b as usize + 3];
                    add_moment(m, &p, dir, reaction);
                }
            }
        }
        book_walls(&mut local, nb, step, &walls, &motion, &origin);
        let s = coll.sum(&local)?;
        let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
        Ok(StepForces {
            moment: std::array::from_fn(|a| std::array::from_fn(|b| s[a * D + b])),
            scale: norm(&s[dd..2 * dd]).max(norm(&s[2 * dd..3 * dd])).max(norm(&s[3 * dd..4 * dd])),
            origin,
            reactions: (0..nb).map(|b| std::array::from_fn(|d| s[4 * dd + 1 + D * b + d])).collect(),
            rigid_motion: (0..nb).map(|b| std::array::from_fn(|d| s[motions_at + 6 * b + d])).collect(),
            reaction_moments: (0..nb).map(|b| std::array::from_fn(|d| s[moments_at + 3 * b + d])).collect(),
            reactions_by_dof: reactions,
            work: s[4 * dd],
            field_scales,
            at_start,
            node_diagnostics,
        })
    }
}

/// Books the shares of the held nodes beyond the grid that GIMP supports reach past a wall (this
/// rank's particles', `walls`, 2 nd per slot: all terms, then inertia): they do not move, and
/// their share of the particles' forces is the wall's reaction, booked on the boundary that holds
/// the wall node next to them (of `nb` boundaries), about `origin`.
fn book_walls<const D: usize, const M: usize>(
    local: &mut [f64],
    nb: usize,
    step: &Step<D, M>,
    walls: &[f64],
    motion: &[(usize, usize)],
    origin: &[f64; D],
) {
    let nd = step.dofs.nd;
    for (w, share) in step.stencils.beyond.iter().zip(walls.chunks_exact(2 * nd)) {
        let b = step.dofs.boundary[w.wall as usize * nd + w.normal as usize] as usize;
        let xr: [f64; D] = std::array::from_fn(|d| w.at[d] - origin[d]);
        for &(c, dir) in motion {
            book_node_forces(local, nb, b, &xr, dir, [0.0, share[c], share[c] - share[nd + c]]);
        }
    }
}

/// The point the equilibrium identity takes its moments about: the grid's centre; in axial
/// symmetry on the axis (the radial moment of the hoop stress is only defined there).
fn moments_origin<const D: usize>(model: &Model<D>) -> [f64; D] {
    let (g, hi) = (&model.grid, model.grid.extent_max());
    let mut origin: [f64; D] = std::array::from_fn(|d| 0.5 * (g.origin[d] + hi[d]));
    if model.geometry.axisymmetric() {
        origin[0] = 0.0;
    }
    origin
}

/// Adds the moment x × f of a force `f` along direction `dir` at `x` to `m` (about x, y, z).
fn add_moment<const D: usize>(m: &mut [f64], x: &[f64; D], dir: usize, f: f64) {
    let x = crate::algebra::pad3(*x);
    // x × (f e_dir): its component a is x_b f δ_{c,dir} − x_c f δ_{b,dir} with (a, b, c) cyclic.
    for (a, m) in m.iter_mut().enumerate().take(3) {
        let (b, c) = ((a + 1) % 3, (a + 2) % 3);
        if dir == c {
            *m += x[b] * f;
        } else if dir == b {
            *m -= x[c] * f;
        }
    }
}

/// K_mag and F^int_mag ([001] Eqs. 25–26) per owned node: the magnitudes of the nodal diagonal of
/// the skeleton's stiffness and of its internal force at the increments `xl`, summed over ranks.
fn nodal_diagnostics<const D: usize, const M: usize, const N: usize>(
    space: &mut NodeSpace<D>,
    points: &Points<D, M, N>,
    xl: &[f64],
) -> Result<Vec<[f64; 2]>, String> {
    let nd = space.layout.nd;
    let ng = space.ghost.len() * nd;
    let (mut stiffness, mut internal) = (vec![0.0; ng], vec![0.0; ng]);
    points.nodal_stiffness_and_force(xl, &mut stiffness, &mut internal);
    for v in [&mut stiffness, &mut internal] {
        space.sum_over_ranks(v).map_err(|e| e.to_string())?;
    }
    let mag = |v: &[f64], l: usize| v[l * nd..l * nd + D].iter().fold(0.0, |m: f64, x| m.hypot(*x));
    Ok(space.owned_nodes.iter().map(|&a| [mag(&stiffness, a as usize), mag(&internal, a as usize)]).collect())
}

/// Books one node's forces in direction `dir`, `[external, reaction, inertia]`, at `xr` (its position
/// about the moments' origin) into [`System::forces`]'s local sums: the first moments of the total
/// (external + reaction − inertia), external, reaction and inertia forces (D² each, in that order)
/// and, for a node held by boundary `boundary` < `nb`, that boundary's reaction (after the work).
fn book_node_forces<const D: usize>(
    local: &mut [f64],
    nb: usize,
    boundary: usize,
    xr: &[f64; D],
    dir: usize,
    [fext, reaction, inertia]: [f64; 3],
) {
    let dd = D * D;
    if boundary < nb {
        local[4 * dd + 1 + D * boundary + dir] += reaction;
    }
    for (row, x) in xr.iter().enumerate() {
        let k = row * D + dir;
        local[k] += x * (fext + reaction - inertia);
        local[dd + k] += x * fext;
        local[2 * dd + k] += x * reaction;
        local[3 * dd + k] += x * inertia;
    }
}
