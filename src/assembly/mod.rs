//! The global system: the only application module that talks to PETSc.
//!
//! A DMDA holds the background grid (dofs ux, uy, p, Ux, Uy interlaced, or ux, uy), so that the
//! distribution of nodes over ranks, ghost nodes and matrix preallocation come from PETSc. Every
//! step ([`GridSystem::prepare_step`]):
//! 1. each particle's stencil (nodes, S, ∇S) is computed once on the configuration x_n;
//! 2. masses, momenta, mass-weighted accelerations and porosities are mapped to the nodes ([003]
//!    Eq. 19) and summed over ranks; interpolated back, they give each particle its Newmark
//!    predictors and its porosity gradient;
//! 3. a node is active when the material fills more than [`MIN_FILLED_FRACTION`] of a cell in its
//!    support; dofs of inactive nodes and the components fixed by active boundaries are
//!    constrained (residual x − 0, identity row and zero column in the tangent);
//! 4. the external tractions at t_{n+1} are assembled; a fresh matrix is created when the
//!    particle–node connectivity or the constraints changed (its structure follows the particles),
//!    otherwise the previous one is reused, so PETSc keeps the symbolic factorisation and only
//!    refactorises numerically.
//!
//! [`GridSystem::solve`] then runs PETSc SNES with residual and Jacobian callbacks that loop over
//! particles, call the pure kernels of [`crate::kernels`] and scatter the small dense blocks with
//! local (ghosted) indices; PETSc sums contributions to nodes owned by other ranks.

mod bench;

use crate::case::Side;
use crate::kernels::{self, NodeBasis, NodeState, StepResult, MAX_LOCAL, MAX_NODES};
use crate::model::loads::LoadTarget;
use crate::model::shape::{self, Stencil};
use crate::model::{Active, Model};
use petsc::ksp::KspOps;
use petsc::mat::MatOps;
use petsc::snes::NonlinearProblem;
use petsc::{
    CallbackError, Comm, DmDa, GhostedRange, LogStage, Mat, MatRef, Options, Snes, StageGuard, VecOps, VecRef, Vector,
};
use std::time::Instant;

/// A node takes part in the solve when the material fills more than this fraction of a cell's area
/// in its support, φ_i = Σ_p S_ip V_p / (h_x h_y) (1 for a node inside the material, 1/4 at the
/// corner of a block on grid lines). Nodes that a particle domain barely reaches have a stiffness
/// ∝ ε and a mass ∝ ε² for an overlap ε: their dofs are ill-determined, and when such a node carried
/// a drained condition or a free pressure at a moving surface (slumping block, large-strain column)
/// the run blew up within a few steps. Leaving them out costs the particle the weight ε² of that node.
pub const MIN_FILLED_FRACTION: f64 = 1e-3;

/// Errors of the global system.
pub type Error = petsc::Error;

/// The stencils of all particles for one step, in this rank's ghosted node numbering, stored
/// flat: particle k uses entries `offsets[k]..offsets[k + 1]` of `nodes` and `basis`.
#[derive(Debug, Clone, Default)]
struct Stencils {
    offsets: Vec<usize>,
    nodes: Vec<u32>,
    basis: Vec<NodeBasis>,
}

impl Stencils {
    fn len(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    fn nodes(&self, k: usize) -> &[u32] {
        &self.nodes[self.offsets[k]..self.offsets[k + 1]]
    }

    fn get(&self, k: usize) -> (&[u32], &[NodeBasis]) {
        let r = self.offsets[k]..self.offsets[k + 1];
        (&self.nodes[r.clone()], &self.basis[r])
    }

    /// Whether every particle couples only nodes it coupled in `old`.
    fn within(&self, old: &Stencils) -> bool {
        self.len() == old.len() && (0..self.len()).all(|k| self.nodes(k).iter().all(|x| old.nodes(k).contains(x)))
    }
}

/// Per-step data shared by the callbacks.
#[derive(Debug, Default)]
struct StepData {
    nm: Option<kernels::Newmark>,
    /// Body acceleration at t_{n+1} per body.
    body_acc: Vec<[f64; 2]>,
    stencils: Stencils,
    /// External nodal forces at t_{n+1} (tractions) per ghosted dof.
    fext: Vec<f64>,
    /// Constrained flag per ghosted dof.
    constrained: Vec<bool>,
    /// Offsets of constrained dofs in the owned part of global vectors.
    owned_constrained: Vec<usize>,
    /// Global index of the first owned dof.
    global_start: usize,
    /// Δd at convergence, per ghosted dof.
    solution: Vec<f64>,
    /// Whether each ghosted node is active.
    active: Vec<bool>,
    /// Porosity gradient at each particle at t_n (two-phase).
    grad_n: Vec<[f64; 2]>,
    /// v_u, a_u, v_w, a_w at t_n at each particle, from the nodal projections.
    smooth: Vec<[[f64; 2]; 4]>,
    /// Pressure-projection blocks: the local p dofs of a cell's four nodes (−1 if constrained) and
    /// the 4 × 4 block S (see `kernels::pressure_projection`).
    projection: Vec<([i32; 4], [[f64; 4]; 4])>,
    /// Unknowns solved for (unconstrained dofs), summed over ranks.
    free_dofs: usize,
}

/// Outcome of one nonlinear step solve.
#[derive(Debug, Clone)]
pub struct StepSolve {
    /// Whether SNES converged.
    pub converged: bool,
    /// PETSc's reason (`CONVERGED_FNORM_RELATIVE`, `DIVERGED_LINE_SEARCH`, ...).
    pub reason: String,
    /// Newton iterations.
    pub newton_iterations: usize,
    /// Krylov iterations.
    pub linear_iterations: usize,
    /// Residual norms, initial and after each iteration.
    pub residual_history: Vec<f64>,
    /// A domain error raised by the callbacks.
    pub domain_error: Option<String>,
    /// Wall time spent in the residual and Jacobian callbacks [s].
    pub assembly_seconds: f64,
    /// Wall time of the whole SNES solve [s].
    pub solve_seconds: f64,
}

/// The PETSc log stages of a run (shown by `-log_view`).
struct Stages {
    run_setup: LogStage,
    setup: LogStage,
    solve: LogStage,
    assembly: LogStage,
    update: LogStage,
    output: LogStage,
}

/// The phases of a step, for log stages.
#[derive(Debug, Clone, Copy)]
pub enum Phase {
    /// Setting up the run: material points, verification, probes, output.
    Setup,
    /// Mapping to the grid, constraints, loads.
    StepSetup,
    /// The Newton solve (assembly and linear solves).
    NewtonSolve,
    /// Particle update.
    ParticleUpdate,
    /// Writing results.
    Output,
}

/// The DMDA grid, the solver and the per-step state of the global system.
pub struct GridSystem {
    comm: Comm,
    dm: DmDa,
    ndof: usize,
    two_phase: bool,
    ghost: GhostedRange,
    owned_start: [usize; 2],
    owned_count: [usize; 2],
    x: Vector,
    x_local: Vector,
    f_local: Vector,
    work_local: Vector,
    work_global: Vector,
    snes: Snes,
    jac: Option<Mat>,
    /// Stencil nodes of each particle and the free dofs when the matrix was created.
    pattern: Option<(Stencils, Vec<bool>)>,
    /// Steps that reused the previous matrix structure (and hence its symbolic factorisation).
    pub reused_patterns: usize,
    step: StepData,
    stages: Stages,
}

/// Ghost width in nodes: a GIMP particle of a cell reaches at most one cell beyond it, so the
/// nodes of a rank's cells plus two rows cover every node its particles touch.
const STENCIL_WIDTH: usize = 2;

impl GridSystem {
    /// Creates the DMDA for the grid and dof layout, and the SNES with porompm's defaults, then
    /// lets the PETSc options database override them. Defaults: Newton with full steps, relative
    /// residual tolerance 1e-6 as in [003] Algorithm 1; sparse LU by UMFPACK on one rank (the
    /// fastest of the measured strategies on the verification cases, see docs/solvers.md) up to
    /// [`UMFPACK_MAX_GRID_DOFS`], and by MUMPS beyond and on several ranks (UMFPACK is sequential).
    pub fn new(comm: Comm, grid: &crate::model::grid::Grid, two_phase: bool) -> Result<GridSystem, Error> {
        let dm = DmDa::new_2d(comm, grid.nodes(), STENCIL_WIDTH, crate::model::field_names(two_phase))?;
        let info = *dm.info();
        let x = dm.create_global_vector()?;
        let x_local = dm.create_local_vector()?;
        let f_local = dm.create_local_vector()?;
        let work_local = dm.create_local_vector()?;
        let work_global = dm.create_global_vector()?;
        let mut snes = Snes::new(comm)?;
        snes.set_dm(&dm)?;
        snes.set_type("newtonls")?;
        snes.set_line_search("basic")?;
        snes.set_tolerances(Some(1e-50), Some(1e-6), Some(1e-12), Some(30))?;
        {
            let mut ksp = snes.ksp()?;
            ksp.set_type("preonly")?;
            let mut pc = ksp.pc()?;
            pc.set_type("lu")?;
            let grid_dofs = grid.nodes()[0] * grid.nodes()[1] * crate::model::field_names(two_phase).len();
            pc.set_factor_solver_type(default_factor_package(comm, grid_dofs))?;
        }
        snes.set_from_options()?;
        let stages = Stages {
            run_setup: LogStage::register("porompm: setup")?,
            setup: LogStage::register("porompm: step setup")?,
            solve: LogStage::register("porompm: Newton solve")?,
            assembly: LogStage::register("porompm: assembly")?,
            update: LogStage::register("porompm: particle update")?,
            output: LogStage::register("porompm: output")?,
        };
        Ok(GridSystem {
            comm,
            dm,
            ndof: if two_phase { 5 } else { 2 },
            two_phase,
            ghost: info.ghosted,
            owned_start: info.owned_start,
            owned_count: info.owned_count,
            x,
            x_local,
            f_local,
            work_local,
            work_global,
            snes,
            jac: None,
            pattern: None,
            reused_patterns: 0,
            step: StepData::default(),
            stages,
        })
    }

    /// Whether this rank owns cell (i, j): the cell's lower-left node is owned.
    pub fn owns_cell(&self, i: usize, j: usize) -> bool {
        i >= self.owned_start[0]
            && i < self.owned_start[0] + self.owned_count[0]
            && j >= self.owned_start[1]
            && j < self.owned_start[1] + self.owned_count[1]
    }

    /// Enters a log stage until the guard is dropped.
    pub fn phase(&self, p: Phase) -> Result<StageGuard, Error> {
        match p {
            Phase::Setup => self.stages.run_setup.push(),
            Phase::StepSetup => self.stages.setup.push(),
            Phase::NewtonSolve => self.stages.solve.push(),
            Phase::ParticleUpdate => self.stages.update.push(),
            Phase::Output => self.stages.output.push(),
        }
    }

    /// Unknowns of the last prepared step (unconstrained dofs over all ranks).
    pub fn free_dofs(&self) -> usize {
        self.step.free_dofs
    }

    /// Total dofs of the grid (all nodes × dofs per node).
    pub fn total_dofs(&self) -> usize {
        let [nx, ny] = self.dm.info().nodes;
        nx * ny * self.ndof
    }

    /// The communicator.
    pub fn comm(&self) -> Comm {
        self.comm
    }

    /// Sums a ghosted per-dof array over ranks: afterwards every ghost holds the global total.
    fn sum_over_ranks(&mut self, data: &mut [f64]) -> Result<(), Error> {
        self.work_local.write()?.copy_from_slice(data);
        self.work_global.set_all(0.0)?;
        self.dm.local_to_global_add(&self.work_local, &mut self.work_global)?;
        self.dm.global_to_local(&self.work_global, &mut self.work_local)?;
        data.copy_from_slice(&self.work_local.read()?);
        Ok(())
    }

    fn local_node(&self, i: u32, j: u32) -> Option<u32> {
        self.ghost.node(i as usize, j as usize).map(|n| n as u32)
    }

    /// Prepares the step t_n → t_{n+1} = `t_new` of length `dt` with the stage's `active` loads and
    /// boundaries (see the module documentation).
    pub fn prepare_step(&mut self, model: &Model, active: &Active, t_new: f64, dt: f64) -> Result<(), String> {
        let nd = self.ndof;
        let ng = self.ghost.len() * nd;
        let ps = &model.particles;
        let nm = kernels::Newmark::new(model.beta, model.gamma, dt);

        // 1. Stencils on x_n.
        let mut stencils = Stencils { offsets: Vec::with_capacity(ps.len() + 1), ..Default::default() };
        stencils.offsets.push(0);
        for k in 0..ps.len() {
            let st: Stencil = shape::stencil(model.basis, &model.grid, ps.x[k], ps.lp[k]);
            if st.iter().all(|(_, w, _)| w == 0.0) {
                return Err(format!(
                    "material point {} at ({:.4}, {:.4}) m has left the grid",
                    ps.id[k], ps.x[k][0], ps.x[k][1]
                ));
            }
            for &(i, j) in &st.nodes[..st.len] {
                stencils.nodes.push(self.local_node(i, j).ok_or_else(|| {
                    format!(
                        "material point {} at ({:.4}, {:.4}) m reaches node ({i}, {j}) outside this rank's ghost region \
                         (particle migration between ranks is not implemented yet)",
                        ps.id[k], ps.x[k][0], ps.x[k][1]
                    )
                })?);
            }
            let first = stencils.basis.len();
            kernels::plain_basis(&st, &mut stencils.basis);
            if model.bbar {
                let gv = shape::volumetric_gradients(model.basis, &model.grid, ps.x[k], ps.lp[k], &st);
                for (b, g) in stencils.basis[first..].iter_mut().zip(gv) {
                    b.gv = g;
                }
            }
            stencils.offsets.push(stencils.nodes.len());
        }

        // 2. Nodal masses, momenta, mass-weighted accelerations ([003] Eq. 19) and filled fractions.
        let cell_area = model.grid.h[0] * model.grid.h[1];
        let (mut mass, mut mom, mut acc, mut weight) = (vec![0.0; ng], vec![0.0; ng], vec![0.0; ng], vec![0.0; ng]);
        for k in 0..stencils.len() {
            let (nodes, basis) = stencils.get(k);
            let mw = model.water_mass(k);
            for (&node, nb) in nodes.iter().zip(basis) {
                let b = node as usize * nd;
                let s = nb.s;
                weight[b] += s * ps.volume[k] / cell_area;
                for c in 0..2 {
                    mass[b + c] += s * ps.mass[k];
                    mom[b + c] += s * ps.mass[k] * ps.vel[k][c];
                    acc[b + c] += s * ps.mass[k] * ps.acc[k][c];
                    if self.two_phase {
                        mass[b + 3 + c] += s * mw;
                        mom[b + 3 + c] += s * mw * ps.vel_w[k][c];
                        acc[b + 3 + c] += s * mw * ps.acc_w[k][c];
                    }
                }
            }
        }
        // Mass-weighted nodal porosity, whose gradient at the particles enters the ∇n terms of the
        // two-phase equations (see crate::kernels).
        let mut porosity = vec![0.0; ng];
        if self.two_phase {
            for k in 0..stencils.len() {
                let (nodes, basis) = stencils.get(k);
                for (&node, nb) in nodes.iter().zip(basis) {
                    porosity[node as usize * nd] += nb.s * ps.mass[k] * ps.porosity[k];
                }
            }
        }
        for v in [&mut mass, &mut mom, &mut acc, &mut weight, &mut porosity] {
            self.sum_over_ranks(v).map_err(|e| e.to_string())?;
        }
        let grad_n: Vec<[f64; 2]> = if self.two_phase {
            (0..stencils.len())
                .map(|k| {
                    let (nodes, basis) = stencils.get(k);
                    let mut g = [0.0; 2];
                    for (&node, nb) in nodes.iter().zip(basis) {
                        let b = node as usize * nd;
                        if mass[b] > 0.0 {
                            let n = porosity[b] / mass[b];
                            g[0] += nb.g[0] * n;
                            g[1] += nb.g[1] * n;
                        }
                    }
                    g
                })
                .collect()
        } else {
            Vec::new()
        };

        // 3. Constraints: inactive nodes, components fixed by the active side and region boundaries,
        // and by moving surfaces (marked by the ranks owning the surface particles, summed over ranks).
        let mut surface = vec![0.0; ng];
        for ((i, j), comps) in model.surface_fixes(active) {
            if let Some(l) = self.local_node(i, j) {
                for c in (0..nd).filter(|&c| comps[c]) {
                    surface[l as usize * nd + c] = 1.0;
                }
            }
        }
        self.sum_over_ranks(&mut surface).map_err(|e| e.to_string())?;
        let mut constrained = vec![false; ng];
        for l in 0..self.ghost.len() {
            let (i, j) = self.ghost.ij(l);
            let inactive = weight[l * nd] <= MIN_FILLED_FRACTION;
            let fixed = model.fixed_components(active, i, j);
            for c in 0..nd {
                constrained[l * nd + c] = inactive || fixed[c] || surface[l * nd + c] > 0.0;
            }
        }
        let mut owned_constrained = Vec::new();
        let mut free = 0usize;
        for jj in 0..self.owned_count[1] {
            for ii in 0..self.owned_count[0] {
                let l = self
                    .ghost
                    .node(self.owned_start[0] + ii, self.owned_start[1] + jj)
                    .expect("owned nodes are ghosted");
                for c in 0..nd {
                    let o = (jj * self.owned_count[0] + ii) * nd + c;
                    if constrained[l * nd + c] {
                        owned_constrained.push(o);
                    } else {
                        free += 1;
                    }
                }
            }
        }
        let free_dofs = self.comm.sum_usize(free).map_err(|e| e.to_string())?;

        // Velocities and accelerations at t_n interpolated back from the nodal projections ([003]
        // Eq. 19b–c): the predictors of [003] Eq. 21 formed on the nodes and interpolated to a point
        // are the predictors of these values (they are linear in v and a). A constrained component
        // has zero velocity and acceleration.
        let smooth: Vec<[[f64; 2]; 4]> = (0..stencils.len())
            .map(|k| {
                let (nodes, basis) = stencils.get(k);
                let mut out = [[0.0; 2]; 4];
                for (&node, nb) in nodes.iter().zip(basis) {
                    let b = node as usize * nd;
                    // (dof, slot of its velocity in `out`, component): solid x, y, then water x, y.
                    for (c, slot, comp) in [(0, 0, 0), (1, 0, 1), (3, 2, 0), (4, 2, 1)] {
                        let q = b + c;
                        if c >= nd || constrained[q] || mass[q] <= 0.0 {
                            continue;
                        }
                        out[slot][comp] += nb.s * mom[q] / mass[q];
                        out[slot + 1][comp] += nb.s * acc[q] / mass[q];
                    }
                }
                out
            })
            .collect();

        // Pressure-projection blocks, cell by cell over this rank's particles (grouped by the cell
        // holding their centre).
        let mut projection = Vec::new();
        if let (true, Some(alpha)) = (self.two_phase, model.pressure_projection) {
            let g = &model.grid;
            let mut cells: std::collections::BTreeMap<(usize, usize), Vec<usize>> = Default::default();
            for k in 0..ps.len() {
                if let Some(c) = g.cell_of(ps.x[k]) {
                    cells.entry(c).or_default().push(k);
                }
            }
            for ((ci, cj), members) in cells {
                let mut idx = [-1i32; 4];
                let corners = [(ci, cj), (ci + 1, cj), (ci, cj + 1), (ci + 1, cj + 1)];
                for (slot, &(i, j)) in corners.iter().enumerate() {
                    if let Some(l) = self.local_node(i as u32, j as u32) {
                        let q = l as usize * nd + kernels::dof::P;
                        idx[slot] = if constrained[q] { -1 } else { q as i32 };
                    }
                }
                let o = g.node_position(ci, cj);
                let n: Vec<[f64; 4]> = members
                    .iter()
                    .map(|&k| {
                        let (x, y) = ((ps.x[k][0] - o[0]) / g.h[0], (ps.x[k][1] - o[1]) / g.h[1]);
                        [(1.0 - x) * (1.0 - y), x * (1.0 - y), (1.0 - x) * y, x * y]
                    })
                    .collect();
                let w: Vec<f64> = members
                    .iter()
                    .map(|&k| {
                        let shear = model.materials[ps.material[k] as usize].model.elastic().shear_modulus();
                        alpha / shear * ps.volume[k]
                    })
                    .collect();
                projection.push((idx, kernels::pressure_projection(&n, &w)));
            }
        }

        // 4. Tractions at t_{n+1}.
        let mut fext = vec![0.0; ng];
        for &li in &active.loads {
            let load = &model.loads[li];
            let f = load.time_fn.eval(t_new);
            match &load.target {
                LoadTarget::ParticleTraction { particles, face, traction } => {
                    // The traction acts at the centre of the particle's loaded face (force = traction ×
                    // current face length) with the bilinear weights there (see shape::face_weights).
                    for &k in particles {
                        let (x, lp) = (ps.x[k], ps.lp[k]);
                        let (point, length) = match face {
                            Side::XMin => ([x[0] - lp[0], x[1]], 2.0 * lp[1]),
                            Side::XMax => ([x[0] + lp[0], x[1]], 2.0 * lp[1]),
                            Side::YMin => ([x[0], x[1] - lp[1]], 2.0 * lp[0]),
                            Side::YMax => ([x[0], x[1] + lp[1]], 2.0 * lp[0]),
                        };
                        let w = shape::face_weights(&model.grid, point);
                        for ((i, j), s, _) in w.iter() {
                            let l =
                                self.local_node(i, j).ok_or("a traction point lies outside this rank's ghost region")?
                                    as usize;
                            for c in 0..2 {
                                fext[l * nd + c] += s * traction[c] * f * length;
                            }
                        }
                    }
                }
                LoadTarget::NodalTraction { nodes, traction } => {
                    for &(i, j, trib) in nodes {
                        let owned = (self.owned_start[0]..self.owned_start[0] + self.owned_count[0]).contains(&i)
                            && (self.owned_start[1]..self.owned_start[1] + self.owned_count[1]).contains(&j);
                        if owned {
                            let l = self.ghost.node(i, j).expect("owned") * nd;
                            for c in 0..2 {
                                fext[l + c] += traction[c] * f * trib;
                            }
                        }
                    }
                }
                LoadTarget::BodyForce { .. } => {}
            }
        }

        let global_start = self.x.ownership_range().map_err(|e| e.to_string())?.0;
        self.step = StepData {
            nm: Some(nm),
            body_acc: model.body_accelerations(active, t_new),
            stencils,
            fext,
            constrained,
            owned_constrained,
            global_start,
            solution: Vec::new(),
            active: (0..self.ghost.len()).map(|l| weight[l * nd] > MIN_FILLED_FRACTION).collect(),
            grad_n,
            smooth,
            projection,
            free_dofs,
        };
        // The matrix structure is the union of the particles' node couplings over the free dofs.
        // It can be kept while every particle couples a subset of the nodes it coupled when the
        // matrix was created and no constrained dof became free: PETSc then keeps the stored
        // pattern (unused entries stay zero) and refactorises numerically only.
        let reusable = match &self.pattern {
            Some((old, free)) => {
                self.step.stencils.within(old)
                    && free.iter().zip(&self.step.constrained).all(|(&was_free, &c)| was_free || c)
            }
            None => false,
        };
        if reusable && self.jac.is_some() {
            self.reused_patterns += 1;
        } else {
            self.jac = Some(self.dm.create_matrix().map_err(|e| e.to_string())?);
            let nodes_only = Stencils {
                offsets: self.step.stencils.offsets.clone(),
                nodes: self.step.stencils.nodes.clone(),
                basis: Vec::new(),
            };
            self.pattern = Some((nodes_only, self.step.constrained.iter().map(|c| !c).collect()));
        }
        Ok(())
    }

    /// Solves the prepared step by Newton's method from Δd = 0.
    pub fn solve(&mut self, model: &Model) -> Result<StepSolve, Error> {
        let _stage = self.stages.solve.push()?;
        self.x.set_all(0.0)?;
        let mut assembly_seconds = 0.0;
        let t0 = Instant::now();
        let out = {
            let (snes, x, jac, mut asm) = self.split(model, &mut assembly_seconds)?;
            snes.solve(x, jac, &mut asm)?
        };
        let solve_seconds = t0.elapsed().as_secs_f64();
        self.dm.global_to_local(&self.x, &mut self.x_local)?;
        self.step.solution = self.x_local.read()?.to_vec();
        Ok(StepSolve {
            converged: out.converged,
            reason: out.reason_text,
            newton_iterations: out.iterations,
            linear_iterations: out.linear_iterations,
            residual_history: out.residual_history,
            domain_error: out.domain_error,
            assembly_seconds,
            solve_seconds,
        })
    }

    /// Splits the system into the SNES, its solution vector and matrix, and the callbacks of the
    /// prepared step (which borrow the rest).
    fn split<'a>(
        &'a mut self,
        model: &'a Model,
        seconds: &'a mut f64,
    ) -> Result<(&'a mut Snes, &'a mut Vector, &'a mut Mat, Assembler<'a>), Error> {
        let GridSystem { dm, x, x_local, f_local, snes, jac, step, ndof, two_phase, stages, .. } = self;
        let jac = jac.as_mut().ok_or_else(|| petsc::Error::new("the step was not prepared"))?;
        let asm = Assembler {
            dm,
            model,
            step,
            x_local,
            f_local,
            nd: *ndof,
            two_phase: *two_phase,
            seconds,
            stage: &stages.assembly,
        };
        Ok((snes, x, jac, asm))
    }

    /// Pore-pressure increments of the converged step recovered at every particle by MLSA patches
    /// ([003] §3.3; see [`crate::model::patch`]); a particle without any active cell near it keeps the
    /// interpolated increment.
    pub fn recovered_pressure_increments(&self, model: &Model) -> Vec<f64> {
        let nd = self.ndof;
        let dp: Vec<f64> = (0..self.ghost.len()).map(|l| self.step.solution[l * nd + kernels::dof::P]).collect();
        let field = crate::model::patch::PatchField {
            grid: &model.grid,
            start: self.ghost.start,
            count: self.ghost.count,
            dp: &dp,
            active: &self.step.active,
        };
        (0..model.particles.len())
            .map(|k| field.recover(model.particles.x[k]).unwrap_or_else(|| self.step_result(model, k).kin.dp))
            .collect()
    }

    /// The nodes this rank owns after the last solve, as records of 7 values: global node index
    /// j·n_x + i, active flag (1 or 0), and the nodal increments Δd of the step (ux, uy, p, Ux, Uy;
    /// zeros beyond the dofs of one-phase runs). Empty before the first solve.
    pub fn owned_node_records(&self) -> Vec<f64> {
        let (nd, nx) = (self.ndof, self.dm.info().nodes[0]);
        let mut out = Vec::new();
        if self.step.solution.is_empty() {
            return out;
        }
        for j in self.owned_start[1]..self.owned_start[1] + self.owned_count[1] {
            for i in self.owned_start[0]..self.owned_start[0] + self.owned_count[0] {
                let Some(l) = self.ghost.node(i, j) else { continue };
                out.push((j * nx + i) as f64);
                out.push(if self.step.active.get(l).copied().unwrap_or(false) { 1.0 } else { 0.0 });
                for c in 0..5 {
                    out.push(if c < nd { self.step.solution[l * nd + c] } else { 0.0 });
                }
            }
        }
        out
    }

    /// The converged step at particle `k` (kinematics and volume ratio) for the particle update.
    pub fn step_result(&self, model: &Model, k: usize) -> StepResult {
        let (nodes, basis) = self.step.stencils.get(k);
        let states = node_states(nodes, &self.step.solution, &self.step, self.ndof);
        let pred = particle_input(model, &self.step, k).pred;
        kernels::step_result(basis, &states[..nodes.len()], &pred, self.two_phase)
    }
}

/// Nodal states of a particle's stencil from the increments `xl`.
#[inline]
fn node_states(nodes: &[u32], xl: &[f64], step: &StepData, nd: usize) -> [NodeState; MAX_NODES] {
    let nm = step.nm.expect("prepared");
    let mut out = [NodeState::default(); MAX_NODES];
    for (n, &node) in nodes.iter().enumerate() {
        let b = node as usize * nd;
        for c in 0..nd {
            let d = xl[b + c];
            out[n].d[c] = d;
            out[n].a[c] = nm.a0 * d;
            out[n].v[c] = nm.a1 * d;
        }
    }
    out
}

/// The residual and Jacobian callbacks of one step.
struct Assembler<'a> {
    dm: &'a DmDa,
    model: &'a Model,
    step: &'a StepData,
    x_local: &'a mut Vector,
    f_local: &'a mut Vector,
    nd: usize,
    two_phase: bool,
    seconds: &'a mut f64,
    stage: &'a LogStage,
}

fn fatal(e: petsc::Error) -> CallbackError {
    CallbackError::Fatal(e.to_string())
}

/// The kernel input of particle `k` for the prepared step.
fn particle_input(model: &Model, step: &StepData, k: usize) -> kernels::ParticleInput {
    let mut input = model.particle_input(k, &step.body_acc);
    if let Some(g) = step.grad_n.get(k) {
        input.grad_n = *g;
    }
    let nm = step.nm.as_ref().expect("prepared");
    let s = &step.smooth[k];
    input.pred = kernels::Predictors::new(nm, s[0], s[1], s[2], s[3]);
    input
}

impl Assembler<'_> {
    fn gather(&mut self, x: &VecRef) -> Result<Vec<f64>, CallbackError> {
        self.dm.global_to_local(x, self.x_local).map_err(fatal)?;
        Ok(self.x_local.read().map_err(fatal)?.to_vec())
    }
}

impl NonlinearProblem for Assembler<'_> {
    fn residual(&mut self, x: &VecRef, f: &mut VecRef) -> Result<(), CallbackError> {
        let _stage = self.stage.push().map_err(fatal)?;
        let t0 = Instant::now();
        let xl = self.gather(x)?;
        let nd = self.nd;
        {
            let mut fl = self.f_local.write().map_err(fatal)?;
            for (q, v) in fl.iter_mut().enumerate() {
                *v = -self.step.fext[q];
            }
            let mut buf = [0.0; MAX_LOCAL];
            for k in 0..self.step.stencils.len() {
                let (nodes, basis) = self.step.stencils.get(k);
                let states = node_states(nodes, &xl, self.step, nd);
                let input = particle_input(self.model, self.step, k);
                let mat = &self.model.materials[self.model.particles.material[k] as usize];
                let m = nodes.len() * nd;
                kernels::residual(basis, &states[..nodes.len()], &input, &mat.model, self.two_phase, &mut buf[..m]);
                for (n, &node) in nodes.iter().enumerate() {
                    let b = node as usize * nd;
                    for c in 0..nd {
                        fl[b + c] += buf[n * nd + c];
                    }
                }
            }
            // Pressure projection: −S Δp in the continuity rows.
            for (idx, s) in &self.step.projection {
                for (a, &ra) in idx.iter().enumerate() {
                    if ra < 0 {
                        continue;
                    }
                    let v: f64 =
                        idx.iter().enumerate().filter(|(_, &q)| q >= 0).map(|(b, &q)| s[a][b] * xl[q as usize]).sum();
                    fl[ra as usize] -= v;
                }
            }
        }
        f.set_all(0.0).map_err(fatal)?;
        self.dm.local_to_global_add(self.f_local, f).map_err(fatal)?;
        {
            // Constrained dofs: residual x − 0 (Dirichlet value zero).
            let xo = x.read().map_err(fatal)?;
            let mut fo = f.write().map_err(fatal)?;
            for &o in &self.step.owned_constrained {
                fo[o] = xo[o];
            }
        }
        *self.seconds += t0.elapsed().as_secs_f64();
        Ok(())
    }

    fn jacobian(&mut self, x: &VecRef, j: &mut MatRef) -> Result<(), CallbackError> {
        let _stage = self.stage.push().map_err(fatal)?;
        let t0 = Instant::now();
        let xl = self.gather(x)?;
        let nd = self.nd;
        let nm = self.step.nm.expect("prepared");
        j.zero_entries().map_err(fatal)?;
        let mut block = vec![0.0; MAX_LOCAL * MAX_LOCAL];
        let mut idx = [0i32; MAX_LOCAL];
        for k in 0..self.step.stencils.len() {
            let (nodes, basis) = self.step.stencils.get(k);
            let input = particle_input(self.model, self.step, k);
            let mat = &self.model.materials[self.model.particles.material[k] as usize];
            let m = nodes.len() * nd;
            // The soil tangent at the current iterate.
            let states = node_states(nodes, &xl, self.step, nd);
            let kin = kernels::interpolate(basis, &states[..nodes.len()], &input.pred, self.two_phase);
            let dsig = mat.model.update(&input.stress, input.eps_pd, &kin.deps).tangent;
            kernels::tangent(basis, &input, &dsig, nm, self.two_phase, &mut block[..m * m]);
            for (n, &node) in nodes.iter().enumerate() {
                let b = node as usize * nd;
                for c in 0..nd {
                    idx[n * nd + c] = if self.step.constrained[b + c] { -1 } else { (b + c) as i32 };
                }
            }
            j.set_values_local(&idx[..m], &idx[..m], &block[..m * m], true).map_err(fatal)?;
        }
        for (idx, s) in &self.step.projection {
            let neg: Vec<f64> = s.iter().flat_map(|r| r.iter().map(|v| -v)).collect();
            j.set_values_local(idx, idx, &neg, true).map_err(fatal)?;
        }
        for &o in &self.step.owned_constrained {
            let g = (self.step.global_start + o) as i32;
            j.set_values(&[g], &[g], &[1.0], true).map_err(fatal)?;
        }
        j.assemble().map_err(fatal)?;
        *self.seconds += t0.elapsed().as_secs_f64();
        Ok(())
    }
}

/// Grid dofs above which the default LU is MUMPS also on one rank: Debian's UMFPACK (32-bit
/// indices) failed in its numeric factorisation on the slumping block at 1.04e5 unknowns (grid
/// 216 × 162, 1.8e5 grid dofs), where MUMPS factorised it; at 2e4 unknowns both took the same time.
pub const UMFPACK_MAX_GRID_DOFS: usize = 50_000;

/// The factorisation package of the default solver: UMFPACK on one rank for grids up to
/// [`UMFPACK_MAX_GRID_DOFS`], MUMPS otherwise.
pub fn default_factor_package(comm: Comm, grid_dofs: usize) -> &'static str {
    if comm.size() == 1
        && grid_dofs <= UMFPACK_MAX_GRID_DOFS
        && petsc::PetscBuild::get().packages.contains(&"suitesparse")
    {
        "umfpack"
    } else {
        "mumps"
    }
}

/// PETSc options that were given but not used by any solver object so far.
pub fn unused_petsc_options() -> Result<Vec<String>, Error> {
    Ok(Options::global().unused()?.iter().map(|o| o.to_string()).collect())
}

/// Every option in PETSc's database, as `-name value` strings.
pub fn petsc_options() -> Result<Vec<String>, Error> {
    Ok(Options::global().all()?.iter().map(|o| o.to_string()).collect())
}

/// The solver configuration (KSP and PC types and the factorisation package), for the summary.
pub fn describe_solver(sys: &mut GridSystem) -> Result<String, Error> {
    let snes_type = sys.snes.type_name()?;
    let lag = sys.snes.lag_jacobian()?;
    let mut ksp = sys.snes.ksp()?;
    let ksp_type = ksp.type_name()?;
    let pc = ksp.pc()?;
    let pc_type = pc.type_name()?;
    let factor = if pc_type == "lu" || pc_type == "cholesky" {
        pc.factor_solver_type()?.map(|s| format!(" ({s})")).unwrap_or_default()
    } else {
        String::new()
    };
    let newton = if lag > 1 || lag == -1 || lag == -2 { "modified Newton (lagged Jacobian)" } else { "Newton" };
    Ok(format!("{snes_type} {newton}; KSP {ksp_type}; PC {pc_type}{factor}"))
}

/// Reductions over ranks for code outside this module (observers, probes, summaries).
#[derive(Clone, Copy)]
pub struct Collective {
    comm: Comm,
}

impl Collective {
    /// Over the run's communicator.
    pub fn new(comm: Comm) -> Collective {
        Collective { comm }
    }

    /// This rank.
    pub fn rank(&self) -> usize {
        self.comm.rank()
    }

    /// Number of ranks.
    pub fn size(&self) -> usize {
        self.comm.size()
    }

    /// Element-wise sum over ranks.
    pub fn sum(&self, v: &[f64]) -> Result<Vec<f64>, String> {
        let mut d = v.to_vec();
        self.comm.sum_f64(&mut d).map_err(|e| e.to_string())?;
        Ok(d)
    }

    /// Element-wise maximum over ranks.
    pub fn max(&self, v: &[f64]) -> Result<Vec<f64>, String> {
        let mut d = v.to_vec();
        self.comm.max_f64(&mut d).map_err(|e| e.to_string())?;
        Ok(d)
    }

    /// Every rank's values concatenated in rank order, on every rank.
    pub fn gather(&self, v: &[f64]) -> Result<Vec<f64>, String> {
        self.comm.all_gather_f64(v).map_err(|e| e.to_string())
    }

    /// Whether any rank reports `flag`.
    pub fn any(&self, flag: bool) -> Result<bool, String> {
        Ok(self.max(&[if flag { 1.0 } else { 0.0 }])?[0] > 0.5)
    }
}

/// Agreement of one field-pair block of the assembled tangent with finite differences.
#[derive(Debug, Clone, serde::Serialize)]
pub struct BlockCheck {
    /// Row field (`ux`, `uy`, `p`, `Ux`, `Uy`).
    pub row: &'static str,
    /// Column field.
    pub col: &'static str,
    /// max |J − J_fd| over the block.
    pub max_abs_error: f64,
    /// max |J| over the block.
    pub max_abs_entry: f64,
    /// max |J − J_fd| / max |J| of the block (of the block's rows if the block is zero).
    pub relative_error: f64,
}

impl GridSystem {
    /// Compares the assembled tangent of the prepared step with central finite differences of the
    /// assembled residual, block by block over the free dofs, at the iterate `fraction` × (the
    /// converged increment of this step). One rank only (it builds the dense FD Jacobian: small
    /// cases only).
    pub fn jacobian_check(&mut self, model: &Model, fraction: f64) -> Result<Vec<BlockCheck>, Error> {
        if self.comm.size() != 1 {
            return Err(petsc::Error::new("the finite-difference Jacobian check runs on one rank"));
        }
        let nd = self.ndof;
        let two_phase = self.two_phase;
        let names = crate::model::field_names(two_phase);
        // A realistic iterate: part of this step's converged increment.
        self.solve(model)?;
        let mut x = self.x.duplicate()?;
        self.x.copy_to(&mut x)?;
        x.scale(fraction)?;
        let n = x.local_size()?;
        let free: Vec<usize> = (0..n).filter(|o| !self.step.owned_constrained.contains(o)).collect();
        let mut seconds = 0.0;
        let (_, _, jac, mut asm) = self.split(model, &mut seconds)?;
        asm.jacobian(&x.as_ref(), &mut jac.as_ref()).map_err(|e| petsc::Error::new(format!("{e:?}")))?;
        let (_, dense) = jac.local_rows_dense()?;
        let xv = x.read()?.to_vec();
        // The finite-difference step of a dof follows the typical size of its kind of unknown:
        // displacements (ux, uy, Ux, Uy share one scale) or pore pressure, with floors of 1e-6 of a
        // cell (m) and 1 Pa when a kind is identically zero.
        let is_p = |o: usize| two_phase && o % nd == kernels::dof::P;
        let (mut typ_u, mut typ_p) = (0.0f64, 0.0f64);
        for &o in &free {
            if is_p(o) {
                typ_p = typ_p.max(xv[o].abs());
            } else {
                typ_u = typ_u.max(xv[o].abs());
            }
        }
        let h_cell = model.grid.h[0].min(model.grid.h[1]);
        let typical: Vec<f64> =
            (0..nd).map(|c| if is_p(c) { typ_p.max(1.0) } else { typ_u.max(1e-6 * h_cell) }).collect();
        let mut fd = vec![0.0; n * n];
        let (mut xp, mut fp, mut fm) = (x.duplicate()?, x.duplicate()?, x.duplicate()?);
        for &c in &free {
            let h = 1e-6 * (xv[c].abs() + typical[c % nd]);
            for (sign, out) in [(1.0, &mut fp), (-1.0, &mut fm)] {
                {
                    let mut w = xp.write()?;
                    w.copy_from_slice(&xv);
                    w[c] += sign * h;
                }
                asm.residual(&xp.as_ref(), &mut out.as_ref()).map_err(|e| petsc::Error::new(format!("{e:?}")))?;
            }
            let (a, b) = (fp.read()?, fm.read()?);
            for &r in &free {
                fd[r * n + c] = (a[r] - b[r]) / (2.0 * h);
            }
        }
        // A block is measured against the largest entry of its rows, so that blocks that are zero
        // (e.g. ux–Uy) are judged by their finite-difference noise relative to that scale.
        let row_scale: Vec<f64> = (0..nd)
            .map(|rf| {
                free.iter()
                    .filter(|&&r| r % nd == rf)
                    .flat_map(|&r| free.iter().map(move |&c| (r, c)))
                    .fold(0.0f64, |m, (r, c)| m.max(dense[r * n + c].abs()))
            })
            .collect();
        let mut out = Vec::new();
        for rf in 0..nd {
            for cf in 0..nd {
                let (mut err, mut big) = (0.0f64, 0.0f64);
                for &r in free.iter().filter(|&&r| r % nd == rf) {
                    for &c in free.iter().filter(|&&c| c % nd == cf) {
                        err = err.max((dense[r * n + c] - fd[r * n + c]).abs());
                        big = big.max(dense[r * n + c].abs());
                    }
                }
                out.push(BlockCheck {
                    row: names[rf],
                    col: names[cf],
                    max_abs_error: err,
                    max_abs_entry: big,
                    relative_error: err / big.max(row_scale[rf]).max(f64::MIN_POSITIVE),
                });
            }
        }
        Ok(out)
    }
}
