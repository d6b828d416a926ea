//! One step of the run: its preparation, its solve (with what the first solve tells about the
//! solver), and the particle update of a converged step with the energy of a dynamic one.

use super::{failed, Dimension, RunError, Simulation};
use crate::assembly::{Phase, Solution, Step, StepSolve};
use crate::diagnostics::{energy, Warning};
use crate::kernels::{ParticleInput, StepResult};
use crate::layout::Dim;
use crate::model::Active;
use crate::recorders::Converged;
use crate::scheme::Integration;
use std::time::Instant;

/// What a particle update leaves for the record of the step.
pub(super) struct Updated {
    /// The energy of a dynamic step: the work of the external forces and the reactions, and the
    /// points' terms ([`crate::recorders::Moment::energy`]).
    pub energy: Option<(f64, [f64; 5])>,
    /// The norm of each field's equation magnitudes at the converged state.
    pub field_scales: Vec<f64>,
}

/// How far this process's resident peak has risen since it was `before` [MiB] (0 where the system
/// does not report it).
fn rise_since(before: Option<f64>) -> f64 {
    match (before, crate::io::peak_memory_mib()) {
        (Some(b), Some(a)) => a - b,
        _ => 0.0,
    }
}

/// Fraction of its first filled fraction below which a moving boundary's nodes have lost their grip
/// on the material (see [`Simulation::check_boundary_grip`]).
const GRIP_FRACTION: f64 = 0.5;

impl<const D: usize, const M: usize, const N: usize> Simulation<'_, D, M, N>
where
    Dim<D>: Dimension<D>,
{
    /// The step t → t + dt prepared ([`crate::assembly::System::prepare`]), and the warning of a
    /// moving boundary whose nodes the material left.
    pub(super) fn prepare(&mut self, active: &Active, dt: f64) -> Result<Step<D, M>, RunError> {
        let t0 = Instant::now();
        let peak = crate::io::peak_memory_mib();
        let step = {
            let _stage = self.system.phase(Phase::StepSetup).map_err(failed)?;
            let times = (self.t + dt, dt);
            self.system.prepare(&self.model, active, times, self.stage_start, self.coll).map_err(RunError::Failed)?
        };
        let summary = &mut *self.journal.summary;
        summary.timings.step_setup_s += t0.elapsed().as_secs_f64();
        summary.memory.peak_rise.step_setup_mib += rise_since(peak);
        summary.dofs = step.free_dofs();
        self.check_boundary_grip(&step.boundary_fill);
        Ok(step)
    }

    /// The nonlinear solve of `step`, its timings and iterations in the summary; after the first
    /// solve with PETSc's solver, its description, the warning of a Krylov solver on an
    /// unstabilised equal-order system, and the refusal of PETSc options no solver object used.
    pub(super) fn solve(&mut self, step: &Step<D, M>) -> Result<(StepSolve, Solution), RunError> {
        let peak = crate::io::peak_memory_mib();
        let (solved, solution) = self
            .system
            .solve(step, &self.model, self.coll)
            .map_err(|e| RunError::Failed(format!("Newton solve at t = {:.6e} s: {e}", self.t)))?;
        let summary = &mut *self.journal.summary;
        summary.memory.peak_rise.solve_mib += rise_since(peak);
        summary.matrix_structure_reuses = self.system.reused_patterns;
        summary.timings.assembly_s += solved.assembly.seconds;
        summary.timings.jacobian_s += solved.assembly.jacobian_seconds;
        summary.timings.jacobians += solved.assembly.jacobians;
        summary.timings.linear_solve_s += solved.solve_seconds - solved.assembly.seconds;
        let (count, seconds) = self.system.timed_matvecs();
        if count > 0 {
            summary.timings.tangent_matvec_s = Some(seconds / count as f64);
        }
        summary.snes_iterations += solved.newton_iterations;
        summary.ksp_iterations += solved.linear_iterations;
        summary.line_search_retries += usize::from(solved.line_search_retry);
        if solved.solver_used && summary.solver.is_empty() {
            self.first_solve()?;
        }
        if let Some(why) = &solved.workspace_retry {
            self.journal.progress(&format!("  step from t = {:.6e} s: {why}", self.t));
        }
        if solved.converged && solved.line_search_retry {
            self.journal.progress(&format!(
                "  step from t = {:.6e} s: full Newton steps failed, solved with a line search ({})",
                self.t,
                crate::assembly::LINE_SEARCH_RETRY
            ));
        }
        Ok((solved, solution))
    }

    /// What the first solve tells: the solver's description in the summary, the warning of a
    /// Krylov solver on an equal-order two-phase case without pressure projection, and the error
    /// naming PETSc options that no solver object used.
    fn first_solve(&mut self) -> Result<(), RunError> {
        let (solver, iterative) = self.system.solver().map_err(failed)?;
        self.journal.summary.solver = solver;
        if iterative && self.system.layout().p.is_some() && self.model.pressure_projection.is_none() {
            self.journal.warn(vec![Warning {
                kind: "iterative_unstabilised".into(),
                message: format!(
                    "the Krylov solver ({}) runs an equal-order two-phase case without pressure projection: its \
                     checkerboard pressure modes are nearly singular for the pressure block's preconditioner, whose \
                     iterations may then grow with the grid (docs/solvers.md, \"Which strategy for which case\"); \
                     set stabilisation.pressure_projection = 1.0 or use a direct strategy",
                    self.journal.summary.solver
                ),
                time_s: None,
                value: None,
                threshold: None,
            }]);
        }
        let unused = crate::assembly::unused_petsc_options().map_err(failed)?;
        if !unused.is_empty() {
            return Err(RunError::Input(format!(
                "PETSc option(s) not used by any solver object: {} (misspelt, or not applicable to this solver)",
                unused.join(", ")
            )));
        }
        Ok(())
    }

    /// Why a solve did not converge: PETSc's reason, a domain error, and the first material point
    /// whose residual was not finite (the lowest rank's, agreed by all ranks).
    pub(super) fn why_not(&mut self, solved: StepSolve) -> Result<String, RunError> {
        let mut why = match solved.domain_error {
            Some(d) => format!("{} ({d})", solved.reason),
            None => solved.reason,
        };
        if let Err(where_) = self.coll.agree(solved.nonfinite.map_or(Ok(()), Err)) {
            why = format!("{why}; {where_}");
        }
        Ok(why)
    }

    /// The particle update of a converged step ([`crate::update`]) after the step's forces and
    /// the recorders' look at it: `Ok(Err(..))` if a particle would become inadmissible (the step
    /// is then cut), in which case no particle is changed; otherwise what the update leaves for
    /// the record ([`Updated`]). The nodal diagnostics are computed when a recorder needs the
    /// nodes of this step (`stage_end`: it ends its stage).
    pub(super) fn update_particles(
        &mut self,
        step: &Step<D, M>,
        solution: &Solution,
        active: &Active,
        (dt, stage_end): (f64, bool),
    ) -> Result<Result<Updated, String>, RunError> {
        let peak = crate::io::peak_memory_mib();
        let diagnostics = self.recorders.iter().any(|r| r.needs_nodes(self.step + 1, stage_end));
        let forces = self
            .system
            .forces(step, solution, &self.model, self.coll, diagnostics, &self.last_reactions)
            .map_err(RunError::Failed)?;
        self.last_reactions = forces.reactions_by_dof.clone();
        let t0 = Instant::now();
        let _stage = self.system.phase(Phase::ParticleUpdate).map_err(failed)?;
        self.nodes = self.system.node_block(step, solution, &forces.node_diagnostics);
        let n = self.model.particles.len();
        let results: Vec<StepResult<D>> = (0..n).map(|k| step.result::<N>(&self.model, solution, k)).collect();
        let converged = Converged {
            model: &self.model,
            forces: &forces,
            results: &results,
            nodes: diagnostics.then_some(&self.nodes),
            coll: self.coll,
        };
        for r in self.recorders.iter_mut() {
            r.converged(&converged).map_err(RunError::Failed)?;
        }
        let bad = results.iter().enumerate().find_map(|(k, r)| crate::update::check_step(&self.model, k, r).err());
        if self.coll.any(bad.is_some()).map_err(RunError::Failed)? {
            return Ok(Err(bad
                .map(|e| e.0)
                .unwrap_or_else(|| "a material point on another rank became inadmissible".into())));
        }
        let pressure = self.system.pressure_increments(step, solution, &self.model).map_err(failed)?;
        let dynamic = matches!(self.model.integration, Integration::Dynamic { .. });
        let body_after = if dynamic { self.model.body_accelerations(active, self.t + dt) } else { Vec::new() };
        let before: Vec<_> = if dynamic {
            let body_before = self.model.body_accelerations(active, self.t);
            let ps = &self.model.particles;
            (0..n).map(|k| (ParticleInput::of(&self.model, k, &body_before), ps.vel[k], ps.vel_w[k])).collect()
        } else {
            Vec::new()
        };
        let mut terms = [0.0; 5];
        for (k, r) in results.iter().enumerate() {
            let dp = pressure.as_ref().map_or(r.interp.dp, |v| v[k]);
            crate::update::update_particle(&mut self.model, k, r, dp, dt).map_err(|e| RunError::Failed(e.0))?;
            if let Some((input, v, vw)) = before.get(k) {
                let ps = &self.model.particles;
                let b = body_after[ps.body[k] as usize];
                let e = energy::particle_step(input, r, dp, (ps.volume[k], b));
                let k_old = energy::kinetic(input.mass, input.water_mass, *v, *vw);
                let k_new = energy::kinetic(ps.mass[k], self.model.water_mass(k), ps.vel[k], ps.vel_w[k]);
                let d = if input.water_mass > 0.0 { energy::darcy(input.drag, dt, r) } else { 0.0 };
                terms[0] += e.body;
                terms[1] += e.internal;
                terms[2] += k_new - k_old;
                terms[3] += d;
                terms[4] += k_new;
            }
        }
        self.journal.summary.timings.particle_update_s += t0.elapsed().as_secs_f64();
        let held = crate::algebra::heap::capacity(&results) + crate::algebra::heap::capacity(&before);
        self.observe_memory(step, held)?;
        self.journal.summary.memory.peak_rise.particle_update_mib += rise_since(peak);
        Ok(Ok(Updated { energy: dynamic.then_some((forces.work, terms)), field_scales: forces.field_scales }))
    }

    /// Folds this step's memory by structure into the summary's largest (collective): the points'
    /// state, the step's stencils and other data, the matrix and `held`, the bytes of the per-point
    /// results and start states the particle update holds.
    fn observe_memory(&mut self, step: &Step<D, M>, held: usize) -> Result<(), RunError> {
        let (stencils, data) = step.heap_bytes();
        let (matrix, assembly) = self.system.matrix_memory().map_err(failed)?;
        let ours = |b: usize| b as f64;
        let local =
            [ours(self.model.particles.heap_bytes()), ours(stencils), ours(data), matrix, ours(assembly), ours(held)];
        let s = self.coll.sum(&local).map_err(RunError::Failed)?;
        let now = crate::summary::MemoryUse::of_bytes(std::array::from_fn(|i| s[i]));
        let m = &mut self.journal.summary.memory;
        *m = m.max(now);
        Ok(())
    }

    /// Warns (once per boundary) when the material has moved away from the grid nodes that carry a
    /// boundary's prescribed motion: their mean filled fraction at the step's start (`fill`, per
    /// boundary) has fallen below half of what it was when the boundary was first seen. A boundary
    /// on grid nodes stays where the grid is; past that point its motion reaches only the points at
    /// the edge of the nodes' support (a footing pushed into the ground by more than about half a
    /// cell loses its grip on the soil beneath it, and the load it carries is no longer the
    /// footing's).
    fn check_boundary_grip(&mut self, fill: &[Option<f64>]) {
        let grip = &mut self.grip;
        grip.resize(fill.len(), (None, false));
        let mut warnings = Vec::new();
        for (b, f) in fill.iter().enumerate() {
            let Some(f) = *f else { continue };
            let (first, warned) = &mut grip[b];
            let start = *first.get_or_insert(f);
            if !*warned && start > 0.0 && f < GRIP_FRACTION * start {
                *warned = true;
                warnings.push(Warning {
                    kind: "boundary_detached".into(),
                    message: format!(
                        "boundary `{}` moves grid nodes (a prescribed motion or a rigid body) that the material has \
                         moved away from: their mean filled fraction is {f:.3}, {:.0} % of the {start:.3} it was at \
                         first; the motion now reaches the material only through the points at the edge of the \
                         nodes' support, and the reactions past this time are not those of the boundary the case \
                         means (move it by less than half a cell, or model the pushing body with material points)",
                        self.model.boundaries[b].name,
                        100.0 * f / start
                    ),
                    time_s: Some(self.t),
                    value: Some(f / start),
                    threshold: Some(GRIP_FRACTION),
                });
            }
        }
        self.journal.warn(warnings);
    }
}
