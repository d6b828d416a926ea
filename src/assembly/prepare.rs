//! The preparation of a step ([`Step::prepare`]): one pass that builds the [`Step`] value, running
//! the same named steps whatever the analysis:
//! 1. `stencils_on_xn` ([`stencils::build_in`]): each particle's stencil (nodes, S, ∇S, ∇̄S) on
//!    x_n; a support reaching past the grid is an error;
//! 2. `project`: masses, momenta, mass-weighted accelerations, porosities and filled fractions
//!    mapped to the nodes ([003] Eq. 19) and summed over ranks;
//! 3. `dof_map` ([`dofs::build`]): the dof map — free dofs, dofs fixed by the active boundaries
//!    (with their prescribed increments) and the dofs of nodes the material barely fills; then the
//!    grid-edge check, the features of the dimension ([`StepDim`]: [001]'s CMPM patches and mapped
//!    forces) and [`stencils::extend`]: each particle's effective stencil;
//! 4. `data`: the threads' bands, the Newmark predictors and porosity gradients, the
//!    pressure-projection blocks and the external forces at t_{n+1} ([`loads`]), with the check that
//!    every applied force reaches a node that carries it, the generalized-α history, the force scale
//!    and the drained faces and nodes ([`pressure`]);
//! 5. `matrix_pattern` ([`pattern`]): the block pattern of the matrix, kept from the last step while it
//!    holds every pair the particles need.
//!
//! The analysis type enters only through the layout (which fields a node carries) and the
//! [`Scheme`] of the step.

use super::dim::StepDim;
use super::dofs::{self, DofMap};
use super::lowered::{self, PcMatrix};
use super::pattern::Pattern;
use super::points::{bands, Points};
use super::pressure;
use super::space::NodeSpace;
use super::splits::SchurNeeds;
use super::stencils::{self, Crossing, Stencils, WELL_FILLED_FRACTION};
use super::step::{StartTerms, Step};
use super::stiffness::MappedStiffness;
use super::{aggregates, loads, ties, Error};
use crate::layout::{Dim, Layout};
use crate::model::{Active, Model};
use crate::parallel::Collective;
use crate::scheme::Scheme;
use std::sync::Arc;

/// Nodal projections of a step.
pub(super) struct Nodal {
    /// Filled fraction per ghosted node.
    pub phi: Vec<f64>,
    /// Mass-weighted porosity per ghosted node.
    pub porosity: Vec<f64>,
    /// Per ghosted dof.
    pub mass: Vec<f64>,
    pub mom: Vec<f64>,
    pub acc: Vec<f64>,
}

/// What a step's preparation needs to know beyond the model: its interval, its stage's loads
/// and boundaries, and what the solver's preconditioner asks for.
pub(super) struct StepRequest<'a, const D: usize, const M: usize> {
    pub active: &'a Active,
    pub times: (f64, f64),
    /// The pattern of the solver's matrix, if it has one.
    pub kept: Option<Arc<Pattern<D>>>,
    /// The matrix the preconditioner is built from and the pattern of the solver's multilinear
    /// one, if it has one.
    pub pc_matrix: (PcMatrix, Option<Arc<Pattern<D>>>),
    pub schur: SchurNeeds,
    /// Whether the step is the first of its stage (the energy ledger's start, see
    /// [`Step::imbalance_at_start`]).
    pub stage_start: bool,
}

impl<const D: usize, const M: usize> Step<D, M> {
    /// Prepares the step of `request` (see the module documentation). Collective; every rank
    /// returns the same outcome.
    pub(super) fn prepare<const N: usize>(
        space: &mut NodeSpace<D>,
        model: &Model<D>,
        request: StepRequest<D, M>,
        coll: &Collective,
    ) -> Result<Step<D, M>, String>
    where
        Dim<D>: StepDim<D>,
    {
        let StepRequest { active, times, kept, pc_matrix, schur, stage_start } = request;
        let (t_old, t_new) = times;
        let dt = t_new - t_old;
        let (mut st, crossings) = stencils_on_xn::<D, M>(space, model, coll)?;
        let nodal = project(space, model, &st).map_err(|e| e.to_string())?;
        let weak = pressure::drains_weakly(space.layout, model, dt);
        let dofs = dof_map(space, model, active, times, &nodal, weak, coll)?;
        coll.agree(stencils::check_edges(model, &st, &crossings, &dofs, &space.ghost, t_old, &model.body_names))?;
        let boundary_fill = moving_boundary_fill(space, model, &dofs, &nodal.phi, coll)?;
        <Dim<D> as StepDim<D>>::recover_strain(&mut st, model, &space.ghost, &dofs, coll)?;
        stencils::extend(&mut st, model, &space.ghost, &dofs, &space.motion());
        let mut step = Step::data::<N>(space, model, active, times, st, dofs, &nodal, coll)?;
        step.boundary_fill = boundary_fill;
        // Newmark's step takes the forces of t_n only through the balance of a_n; a generalized-α
        // step carries them in its history, f_n itself (`Scheme::history`).
        let newmark =
            matches!(model.integration, crate::scheme::Integration::Dynamic { .. }) && step.scheme.history().is_none();
        if stage_start && newmark {
            step.start_imbalance =
                step.imbalance_at_start::<N>(space, model, active, t_old).map_err(|e| e.to_string())?;
        }
        step.stiffness = <Dim<D> as StepDim<D>>::mapped_stiffness(model, &space.ghost, &step.stencils, coll)?;
        step.fixed_stress = pressure::fixed_stress_diagonal(space, &step, model, &schur).map_err(|e| e.to_string())?;
        if schur.blocks {
            if let Some(p) = space.layout.p {
                let nodes = std::array::from_fn(|d| model.grid.cells[d] + 1);
                step.schur_groups = aggregates::surface_groups(
                    &space.ghost,
                    nodes,
                    &space.owned_nodes,
                    &step.dofs,
                    p,
                    schur.tuning.strip,
                );
            }
        }
        if weak {
            (step.face_owner, step.faces) = pressure::drained_faces(space, &step, model, active).into_iter().unzip();
        }
        if let crate::scheme::Integration::Explicit { pointwise_pressure: false, .. } = model.integration {
            if space.layout.w.is_some() {
                step.drained = pressure::drained_nodes(space, &step, model, active).map_err(|e| e.to_string())?;
            }
        }
        if model.integration.is_explicit() {
            // An explicit step solves nothing: no matrix.
            return Ok(step);
        }
        step.matrix_pattern(space, kept, coll)?;
        if pc_matrix.0 == PcMatrix::Multilinear {
            let tied = step.dofs.bodies.first().map(|b| b.boundary);
            let followed = step.dofs.follows.first().map(|&(q, _)| step.dofs.boundary[q as usize] as usize);
            // The rank that finds one tells every rank (its impermeable nodes may be on it alone).
            coll.agree(tied.or(followed).map_or(Ok(()), |b| {
                Err(format!(
                    "boundary `{}` ties rows (a rigid body or an impermeable surface) that the multilinear \
                     preconditioning matrix (-porompm_pc_matrix multilinear) does not carry; precondition with the \
                     Jacobian itself",
                    model.boundaries[b].name
                ))
            }))?;
            step.lowered = Some(lowered::prepare(&step, model, space, pc_matrix.1, coll)?);
        }
        Ok(step)
    }

    /// What the step's start is out of balance by, r_n per ghosted dof summed over ranks
    /// ([`Step::start_imbalance`]): the residual M a_n + f_int,n − f_n at Δd = 0 with the
    /// velocities and accelerations of t_n the points carry (projected as the predictors are) and
    /// the body forces and loads of t_n. The first step of a Newmark stage starts from
    /// accelerations that need not balance the stage's loads (a body at rest under a load on from
    /// t_n); Newmark's step sees the forces of t_n only through the balance of a_n, so it acts as
    /// if the force at t_n were f_n + r_n, and the energy ledger books that step's work with it
    /// ([`super::forces`]): the trapezoidal identity Δu·M(a_n + a_{n+1})/2 = ΔK then holds.
    /// Collective.
    fn imbalance_at_start<const N: usize>(
        &self,
        space: &mut NodeSpace<D>,
        model: &Model<D>,
        active: &Active,
        t_old: f64,
    ) -> Result<Vec<f64>, Error>
    where
        Dim<D>: StepDim<D>,
    {
        let body_acc_old = model.body_accelerations(active, t_old);
        let scheme = self.scheme.start_balance();
        let mut r = Points::<D, M, N>::new(model, self).terms_at_start(&scheme, &body_acc_old, &self.fext_old, true);
        space.sum_over_ranks(&mut r)?;
        Ok(r)
    }

    /// Step 4: the data the callbacks use, from the effective stencils `st` and the dof map: the
    /// threads' bands, the predictors, porosity gradients, pressure-projection blocks, external
    /// loads (checked against what the nodes carry), the generalized-α history and the force
    /// scale of the Newton floor.
    #[allow(clippy::too_many_arguments)]
    fn data<const N: usize>(
        space: &mut NodeSpace<D>,
        model: &Model<D>,
        active: &Active,
        (t_old, t_new): (f64, f64),
        st: Stencils<D>,
        dofs: DofMap,
        nodal: &Nodal,
        coll: &Collective,
    ) -> Result<Step<D, M>, String> {
        let layout = space.layout;
        let bands = bands(&st, space.ghost.count, coll.threads_for(st.len()));
        let (smooth, grad_n) = predictors(layout, model, &st, &dofs, nodal);
        let projection = pressure::projection_cells(space, model);
        let (fext, applied) = coll.agree(loads::external_forces::<D, M>(space, model, active, t_new, &dofs))?;
        let flow = layout.p.is_some() && layout.w.is_none();
        let scheme = Scheme::of(&model.integration, t_new - t_old, flow);
        let fext_old = coll.agree(loads::external_forces::<D, M>(space, model, active, t_old, &dofs))?.0;
        let mut step = Step {
            scheme,
            dt: t_new - t_old,
            layout,
            body_acc: model.body_accelerations(active, t_new),
            stencils: st,
            dofs,
            fext,
            fext_old: Vec::new(),
            history: Vec::new(),
            grad_n,
            smooth,
            force_scale: 0.0,
            projection,
            pattern: Arc::default(),
            bands,
            projection_blocks: Vec::new(),
            fixed_diagonals: Vec::new(),
            p_scale: pressure::scale(model),
            field_scales: Vec::new(),
            fixed_stress: Vec::new(),
            schur_groups: Vec::new(),
            faces: Vec::new(),
            face_owner: Vec::new(),
            stiffness: MappedStiffness::default(),
            start_terms: StartTerms::default(),
            start_imbalance: Vec::new(),
            drained: Vec::new(),
            boundary_fill: Vec::new(),
            lowered: None,
            tied_rows: Default::default(),
        };
        loads::check_loads(space, &step, &applied, t_new, coll)?;
        let mut fext_old = fext_old;
        ties::add_forces(&step.dofs, 1.0, &mut step.fext, &mut fext_old);
        if model.linear_increments {
            // A geometrically linear step solves for the increments alone ([001]'s K Δu = ΔF):
            // the residual of the step's start on x_n is taken off (validation keeps these stages
            // static or quasi-static, which have no generalized-α history).
            let body_acc_old = model.body_accelerations(active, t_old);
            step.history = Points::<D, M, N>::new(model, &step).start_out_of_balance(&body_acc_old, &fext_old);
        } else if let Some(hs) = scheme.history() {
            let body_acc_old = model.body_accelerations(active, t_old);
            step.history = Points::<D, M, N>::new(model, &step).history(&hs, &body_acc_old, &fext_old);
        }
        step.fext_old = fext_old;
        let mut mags = if model.integration.is_explicit() {
            // An explicit step's forces are those of its start: one pass gives them and their
            // magnitudes (the scale of each field's equation).
            let ng = step.fext.len();
            let mut terms = StartTerms { all: vec![0.0; ng], inertia: vec![0.0; ng], magnitude: vec![0.0; ng] };
            let xl = vec![0.0; ng];
            Points::<D, M, N>::new(model, &step).nodal_terms(
                &xl,
                &mut terms.all,
                &mut terms.inertia,
                &mut terms.magnitude,
            );
            let mags = terms.magnitude.clone();
            step.start_terms = terms;
            mags
        } else {
            Points::<D, M, N>::new(model, &step).force_magnitudes()
        };
        space.sum_over_ranks(&mut mags).map_err(|e| e.to_string())?;
        step.field_scales = space.field_norms(&step, &mags, coll)?;
        step.force_scale = step.field_scales.iter().map(|x| x * x).sum::<f64>().sqrt();
        Ok(step)
    }

    /// Step 5: the matrix pattern, kept (`old`) if every rank finds every pair in it, and where the
    /// pressure-projection cells and the fixed dofs' diagonals lie in it.
    fn matrix_pattern(
        &mut self,
        space: &NodeSpace<D>,
        old: Option<Arc<Pattern<D>>>,
        coll: &Collective,
    ) -> Result<(), String> {
        let nd = self.layout.nd;
        let ties = ties::pattern_ties(&self.dofs, space.ghost.len());
        let covers = old.as_ref().is_some_and(|p| !p.is_empty() && p.covers(&self.stencils, &ties));
        // Whether a matrix exists is the same on every rank: the reduction is collective.
        let keep = old.is_some() && !coll.any(!covers)?;
        let pattern = match old {
            Some(old) if keep => old,
            _ => {
                let groups: Vec<Vec<u32>> = self.projection.iter().map(|c| c.nodes.clone()).collect();
                let mut p = Pattern::build_in(&self.stencils, &space.owned_nodes, &groups, space.ghost.count);
                // Also on a rank without tied nodes (its virtual masters are in `ties`), so that
                // every rank finds the same ties in the pattern it keeps.
                if ties != Default::default() {
                    p.tie(ties);
                }
                Arc::new(p)
            }
        };
        // Only a rigid body's rows can miss a block (an impermeable surface's stay in their own
        // node's blocks); the bodies are the same on every rank, so only then is it agreed.
        let rows = ties::TiedRows::of(&self.dofs, &pattern);
        self.tied_rows = if self.dofs.bodies.is_empty() { rows? } else { coll.agree(rows)? };
        let projection_blocks: Option<Vec<Vec<u32>>> = self
            .projection
            .iter()
            .map(|cell| {
                let pattern = &pattern;
                cell.nodes.iter().flat_map(|&na| cell.nodes.iter().map(move |&nc| pattern.block(na, nc))).collect()
            })
            .collect();
        self.projection_blocks =
            projection_blocks.ok_or("a pressure-projection cell's nodes are not coupled by any particle")?;
        self.fixed_diagonals = pattern.fixed_diagonals(&self.dofs.owned_fixed, nd)?;
        self.pattern = pattern;
        Ok(())
    }
}

/// Step 1: the stencils on x_n (B̄'s cells first: which cells the material fills, summed over
/// ranks), and the particles whose support crosses a side of the grid.
fn stencils_on_xn<const D: usize, const M: usize>(
    space: &mut NodeSpace<D>,
    model: &Model<D>,
    coll: &Collective,
) -> Result<(Stencils<D>, Vec<Crossing>), String> {
    let nd = space.layout.nd;
    let roots = if model.bbar {
        let mut phi = vec![0.0; space.ghost.len() * nd];
        for (l, f) in stencils::cell_fractions(model, &space.ghost).into_iter().enumerate() {
            phi[l * nd] = f;
        }
        space.sum_over_ranks(&mut phi).map_err(|e| e.to_string())?;
        let per_cell: Vec<f64> = (0..space.ghost.len()).map(|l| phi[l * nd]).collect();
        stencils::CellRoots::new(&space.ghost, model.grid.cells, &per_cell)
    } else {
        stencils::CellRoots::identity()
    };
    coll.agree(stencils::build_in::<D, M>(model, &space.ghost, &roots))
}

/// Step 2: nodal masses, momenta and mass-weighted accelerations ([003] Eq. 19), mass-weighted
/// porosities and filled fractions, summed over ranks.
fn project<const D: usize>(space: &mut NodeSpace<D>, model: &Model<D>, st: &Stencils<D>) -> Result<Nodal, Error> {
    let nd = space.layout.nd;
    let w = space.layout.w;
    let ng = space.ghost.len() * nd;
    let ps = &model.particles;
    // A cell's area (its volume in three dimensions).
    let cell_area: f64 = model.grid.h.iter().product();
    let (mut mass, mut mom, mut acc) = (vec![0.0; ng], vec![0.0; ng], vec![0.0; ng]);
    let (mut phi, mut porosity) = (vec![0.0; ng], vec![0.0; ng]);
    for k in 0..st.len() {
        let (nodes, basis) = st.get(k);
        let mw = model.water_mass(k);
        for (&node, nb) in nodes.iter().zip(basis) {
            let b = node as usize * nd;
            let s = nb.s;
            phi[b] += s * model.area(k) / cell_area;
            porosity[b] += s * ps.mass[k] * ps.porosity[k];
            for c in 0..D {
                mass[b + c] += s * ps.mass[k];
                mom[b + c] += s * ps.mass[k] * ps.vel[k][c];
                acc[b + c] += s * ps.mass[k] * ps.acc[k][c];
                if let Some(w) = w {
                    mass[b + w + c] += s * mw;
                    mom[b + w + c] += s * mw * ps.vel_w[k][c];
                    acc[b + w + c] += s * mw * ps.acc_w[k][c];
                }
            }
        }
    }
    for v in [&mut mass, &mut mom, &mut acc, &mut phi, &mut porosity] {
        space.sum_over_ranks(v)?;
    }
    let n = space.ghost.len();
    Ok(Nodal {
        phi: (0..n).map(|l| phi[l * nd]).collect(),
        porosity: (0..n).map(|l| if mass[l * nd] > 0.0 { porosity[l * nd] / mass[l * nd] } else { 0.0 }).collect(),
        mass,
        mom,
        acc,
    })
}

/// Step 3: the dof map of the step `(t_n, t_{n+1})`. Moving surfaces: per surface boundary, the
/// dofs any rank's particles fix, summed over ranks; a dof takes the first such boundary in case
/// order. With `weak_drainage` the surfaces fix no pressure ([`pressure::drains_weakly`]).
fn dof_map<const D: usize>(
    space: &mut NodeSpace<D>,
    model: &Model<D>,
    active: &Active,
    times: (f64, f64),
    nodal: &Nodal,
    weak_drainage: bool,
    coll: &Collective,
) -> Result<DofMap, String> {
    let nd = space.layout.nd;
    let fixes = model.surface_fixes(active, weak_drainage);
    let mut surface = vec![0.0; space.ghost.len() * nd];
    for &bi in active.boundaries.iter().filter(|&&b| model.boundaries[b].surface.is_some()) {
        let mut marks = vec![0.0; space.ghost.len() * nd];
        for (n, _, comps) in fixes.iter().filter(|f| f.1 == bi) {
            if let Some(l) = space.ghost.local(n.map(|v| v as usize)) {
                for c in (0..nd).filter(|&c| space.layout.canonical(c).is_some_and(|k| comps[k])) {
                    marks[l * nd + c] = 1.0;
                }
            }
        }
        space.sum_over_ranks(&mut marks).map_err(|e| e.to_string())?;
        for (s, m) in surface.iter_mut().zip(&marks) {
            if *s == 0.0 && *m > 0.0 {
                *s = (bi + 1) as f64;
            }
        }
    }
    // Only a rigid body conflicts with another boundary, and the bodies are the same on every
    // rank: only then is the outcome agreed.
    let built = dofs::build(
        model,
        active,
        times,
        &space.ghost,
        space.owned_start,
        space.owned_count,
        nd,
        &nodal.phi,
        &surface,
        WELL_FILLED_FRACTION,
        space.layout,
    );
    let mut dofs = if model.boundaries.iter().any(|b| b.force.is_some()) { coll.agree(built)? } else { built? };
    dofs.free_dofs = coll.sum_count(dofs.free_dofs as u64) as usize;
    let position = |l: usize| crate::algebra::pad3(model.grid.position(space.ghost.indices(l)));
    ties::resolve(&mut dofs, &space.l2g, position, |b| model.boundaries[b].name.clone(), coll)?;
    Ok(dofs)
}

/// The mean filled fraction φ of the nodes of each boundary that prescribes a motion or ties a
/// rigid body (None for the others, and for a boundary without nodes): how much material the
/// nodes that carry the motion reach at the step's start (collective). A boundary on grid nodes
/// stays where the grid is, while the material it pushes moves on: once the material has moved by
/// about half a cell, the nodes reach only the points at the edge of their support, and the motion
/// no longer acts on the material as the boundary means it to (the driver warns).
fn moving_boundary_fill<const D: usize>(
    space: &NodeSpace<D>,
    model: &Model<D>,
    dofs: &DofMap,
    phi: &[f64],
    coll: &Collective,
) -> Result<Vec<Option<f64>>, String> {
    let nb = model.boundaries.len();
    let moving: Vec<bool> = model
        .boundaries
        .iter()
        .map(|b| {
            b.force.is_some()
                || b.motion.as_ref().is_some_and(|m| m.gradient.is_some() || m.vector.iter().any(|&v| v != 0.0))
        })
        .collect();
    if !moving.contains(&true) {
        // No boundary moves (every rank has the same boundaries): nothing to reduce.
        return Ok(vec![None; nb]);
    }
    let nd = space.layout.nd;
    let mut local = vec![0.0; 2 * nb];
    for &a in &space.owned_nodes {
        let l = a as usize;
        for c in 0..nd {
            let b = dofs.boundary[l * nd + c] as usize;
            // Each boundary once per node: at its first fixed component.
            let first = (0..c).all(|e| dofs.boundary[l * nd + e] as usize != b);
            if b < nb && moving[b] && first {
                local[2 * b] += phi[l];
                local[2 * b + 1] += 1.0;
            }
        }
    }
    let s = coll.sum(&local)?;
    Ok((0..nb).map(|b| (moving[b] && s[2 * b + 1] > 0.0).then(|| s[2 * b] / s[2 * b + 1])).collect())
}

/// Step 4: the Newmark predictors' velocities and accelerations at t_n interpolated to each
/// particle from the nodal projections ([003] Eq. 19b–c; the predictors of [003] Eq. 21 formed
/// on the nodes and interpolated are the predictors of these values, being linear in v and a),
/// and the porosity gradient at each particle (two-phase). A component held still by a boundary
/// has zero velocity and acceleration; an extended node takes its masters'.
fn predictors<const D: usize>(
    layout: Layout,
    model: &Model<D>,
    st: &Stencils<D>,
    dofs: &DofMap,
    nodal: &Nodal,
) -> (Vec<[[f64; D]; 4]>, Vec<[f64; D]>) {
    let value = |l: usize, c: usize, of: &[f64]| start_value(model, dofs, l * dofs.nd + c, &nodal.mass, of);
    // (dof, slot of its velocity in the output, component): the solid's, then the water's.
    let mut comps: Vec<(usize, usize, usize)> = (0..D).map(|c| (c, 0, c)).collect();
    if let Some(w) = layout.w {
        comps.extend((0..D).map(|c| (w + c, 2, c)));
    }
    let water_moves = layout.w.is_some();
    let mut smooth = Vec::with_capacity(st.len());
    let mut grad_n = Vec::with_capacity(if water_moves { st.len() } else { 0 });
    for k in 0..st.len() {
        let (nodes, basis) = st.get(k);
        let eff = st.effective(k);
        let ext = st.extensions(k);
        let mut out = [[0.0; D]; 4];
        let mut g = [0.0; D];
        for (slot, (&node, nb)) in nodes.iter().zip(basis).enumerate() {
            let e = ext.iter().find(|e| e.slot as usize == slot);
            // The masters' sum of `f` where the node is extended (zero where it is not, which
            // the callers never ask for).
            let of_masters = |f: &dyn Fn(usize) -> f64| -> f64 { e.map_or(0.0, |e| e.of_masters(eff, f)) };
            for &(c, s, comp) in &comps {
                let extended = e.is_some_and(|e| e.mask & (1 << c) != 0);
                let (v, a) = if extended {
                    (of_masters(&|l| value(l, c, &nodal.mom)), of_masters(&|l| value(l, c, &nodal.acc)))
                } else {
                    (value(node as usize, c, &nodal.mom), value(node as usize, c, &nodal.acc))
                };
                out[s][comp] += nb.s * v;
                out[s + 1][comp] += nb.s * a;
            }
            if water_moves {
                let n = if e.is_some() { of_masters(&|l| nodal.porosity[l]) } else { nodal.porosity[node as usize] };
                for (gd, nbd) in g.iter_mut().zip(nb.g) {
                    *gd += nbd * n;
                }
            }
        }
        smooth.push(out);
        if water_moves {
            grad_n.push(g);
        }
    }
    (smooth, grad_n)
}

/// A nodal value of a step's start at ghosted dof `q`, the lumped sum `of` over the lumped
/// `mass` (a velocity or an acceleration): zero where a boundary holds the component still (fixed
/// without a prescribed motion; a rigid body's tied dofs and an impermeable surface's water are
/// unknowns, not fixed) or where no point gives the node mass. The Newmark predictors and
/// an explicit step's FLIP update take their nodal values alike (each from its own lumping).
pub(super) fn start_value<const D: usize>(model: &Model<D>, dofs: &DofMap, q: usize, mass: &[f64], of: &[f64]) -> f64 {
    let (l, c) = (q / dofs.nd, q % dofs.nd);
    let still =
        dofs.fixed[q] && dofs.boundary_fixed(l, c) && model.boundaries[dofs.boundary[q] as usize].motion.is_none();
    if still || mass[q] <= 0.0 {
        0.0
    } else {
        of[q] / mass[q]
    }
}
