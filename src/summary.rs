//! `summary.json`: what a run did and found ([`Summary`]), kept up to date while it runs and
//! completed at its end.

use crate::diagnostics::{Warning, Worst};
use crate::verification::Metric;
use serde::Serialize;
use std::collections::BTreeMap;

/// How well one field's equations were solved over a run (see `Summary::field_residuals`).
#[derive(Debug, Clone, Serialize)]
pub struct FieldResidual {
    /// The field: `u` (solid displacement), `p` (pore pressure) or `U` (water displacement).
    pub field: String,
    /// The largest final Newton residual of the field's rows over a converged step, relative to
    /// the norm of the field's force magnitudes in that step (the sum of the absolute values of
    /// the terms of its equations: stress, pressure, inertia, drag, flow, loads). The Newton test
    /// of PETSc sees the fields through one norm; this shows each one.
    pub newton_final_max: f64,
    /// The largest relative residual of the field after a linear solve, ‖(b − A x)_f‖ over the
    /// larger of ‖b_f‖ and the largest block term ‖A_fg x_g‖ (null when not measured, under
    /// Eisenstat–Walker). A Krylov solve stopped at `-ksp_rtol` should leave it near that
    /// tolerance in every field; a direct solve leaves it at round-off.
    pub linear_max: Option<f64>,
}

/// Wall time per phase [s].
#[derive(Debug, Clone, Default, Serialize)]
pub struct Timings {
    /// Setting up (grid, particles, solver).
    pub setup_s: f64,
    /// Mapping to the grid, constraints, loads, matrix creation, every step.
    pub step_setup_s: f64,
    /// Residual and Jacobian assembly (inside the Newton solves).
    pub assembly_s: f64,
    /// The Jacobians' part of `assembly_s`: the tangent assemblies (rank 0), `jacobians` of them.
    pub jacobian_s: f64,
    /// The Jacobians assembled (the tangent matrices, one per Newton iteration unless PETSc is
    /// told to lag them).
    pub jacobians: usize,
    /// Linear solves and the rest of SNES (Newton solve time minus assembly).
    pub linear_solve_s: f64,
    /// Particle updates.
    pub particle_update_s: f64,
    /// Writing results.
    pub output_s: f64,
    /// The mean wall time of one mat-vec with the whole tangent (rank 0), timed after the linear
    /// solves where the field residuals are measured: the unit of a Krylov iteration's cost.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tangent_matvec_s: Option<f64>,
}

/// Where the memory goes [MiB]: what the program's structures hold on the heap, summed over ranks,
/// each the largest over the steps (not all at the same step), beside the resident peak.
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct MemoryUse {
    /// The material points' state.
    pub particles_mib: f64,
    /// A step's stencils (nodes, weights and gradients of every point's support).
    pub stencils_mib: f64,
    /// The rest of a step's data: dof map, loads, predictors, bands, pressure projection, drained
    /// faces, mapped stiffness.
    pub step_data_mib: f64,
    /// The matrix as PETSc stores it (values, column indices, row bookkeeping; `MatGetInfo`).
    pub matrix_mib: f64,
    /// The program's side of the matrix: its block pattern and the assembly's buffer of values.
    pub matrix_assembly_mib: f64,
    /// The converged step's per-point results and the points' state at the step's start, held
    /// during the particle update.
    pub step_results_mib: f64,
    /// How far rank 0's resident peak rose [MiB] by the end of the set-up (the program, MPI,
    /// PETSc, the model), and then while steps were set up, solved (matrix creation, assembly and
    /// the linear solver's set-up and work) and their points updated; the rest of the peak rose
    /// while writing results.
    pub peak_rise: PeakRise,
}

/// Rises of the resident peak by phase [MiB] (see [`MemoryUse::peak_rise`]).
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct PeakRise {
    pub setup_mib: f64,
    pub step_setup_mib: f64,
    pub solve_mib: f64,
    pub particle_update_mib: f64,
}

impl MemoryUse {
    /// The six amounts, in this order, from bytes.
    pub fn of_bytes(b: [f64; 6]) -> MemoryUse {
        let m = |x: f64| x / (1024.0 * 1024.0);
        MemoryUse {
            particles_mib: m(b[0]),
            stencils_mib: m(b[1]),
            step_data_mib: m(b[2]),
            matrix_mib: m(b[3]),
            matrix_assembly_mib: m(b[4]),
            step_results_mib: m(b[5]),
            peak_rise: PeakRise::default(),
        }
    }

    /// Each amount the larger of the two.
    pub fn max(self, o: MemoryUse) -> MemoryUse {
        MemoryUse {
            particles_mib: self.particles_mib.max(o.particles_mib),
            stencils_mib: self.stencils_mib.max(o.stencils_mib),
            step_data_mib: self.step_data_mib.max(o.step_data_mib),
            matrix_mib: self.matrix_mib.max(o.matrix_mib),
            matrix_assembly_mib: self.matrix_assembly_mib.max(o.matrix_assembly_mib),
            step_results_mib: self.step_results_mib.max(o.step_results_mib),
            peak_rise: self.peak_rise,
        }
    }
}

/// `summary.json`.
#[derive(Debug, Clone, Serialize)]
pub struct Summary {
    /// "running", "completed" or "failed".
    pub status: String,
    /// Why the run failed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// The case file.
    pub case: String,
    /// `--set` overrides.
    pub overrides: Vec<String>,
    /// porompm version and git revision.
    pub porompm_version: String,
    /// Wall time of the run [s].
    pub wall_time_s: f64,
    /// Simulated time reached [s].
    pub time_s: f64,
    /// Simulated time asked for [s].
    pub end_time_s: f64,
    /// Converged steps.
    pub steps: usize,
    /// Step cuts (retries with smaller Δt).
    pub step_cuts: usize,
    /// Steps whose full Newton steps failed and that were solved again with a line search
    /// (`assembly::LINE_SEARCH_RETRY`), converged or not.
    pub line_search_retries: usize,
    /// Material points that moved to another rank over the run (since the restart, if restarted).
    pub migrated_particles: usize,
    /// Repartitions of the grid over the ranks to balance the material points.
    pub repartitions: usize,
    /// The largest load imbalance at a history row (the busiest rank's points over the mean).
    pub load_imbalance_max: f64,
    /// porompm's own collective operations on rank 0 over the run (reductions, gathers, the
    /// migration and output exchanges; PETSc's own messages are in its `-log_view`).
    pub collectives: crate::parallel::Traffic,
    /// Newton iterations over the run.
    pub snes_iterations: usize,
    /// Krylov iterations over the run.
    pub ksp_iterations: usize,
    /// Steps whose matrix kept the previous step's nonzero structure (so the symbolic
    /// factorisation was reused).
    pub matrix_structure_reuses: usize,
    /// The residual of each field (u, p, U) relative to its own scale, the largest over the
    /// converged steps of the run (since the restart, if restarted).
    pub field_residuals: Vec<FieldResidual>,
    /// Unknowns of the last step (unconstrained dofs).
    pub dofs: usize,
    /// Dofs of the whole grid.
    pub grid_dofs: usize,
    /// Material points.
    pub particles: usize,
    /// MPI ranks.
    pub ranks: usize,
    /// The solver actually used.
    pub solver: String,
    /// PETSc's options database.
    pub petsc_options: Vec<String>,
    /// Wall time per phase.
    pub timings: Timings,
    /// Peak resident memory of the process (rank 0) at the end of the run [MiB]: `VmHWM` of
    /// `/proc/self/status`, absent where the system does not report it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub peak_memory_mib: Option<f64>,
    /// The sum of every rank's peak resident memory [MiB] (equal to `peak_memory_mib` on one rank).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub peak_memory_total_mib: Option<f64>,
    /// Where the memory goes, by structure (see [`MemoryUse`]).
    pub memory: MemoryUse,
    /// Largest checkerboard index of the pore pressures over the output steps (two-phase runs; see
    /// `verification::checkerboard`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub checkerboard_index_max: Option<f64>,
    /// Largest pressure oscillation index over the output steps (two-phase runs; see
    /// `diagnostics::Monitor::row`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pressure_oscillation_index_max: Option<f64>,
    /// Smallest and largest particle pore pressure over the output steps [Pa] (two-phase runs).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pore_pressure_range: Option<[f64; 2]>,
    /// The relative energy imbalance of the dynamic stages at the last history row (see
    /// `diagnostics::energy`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub energy_balance_error: Option<f64>,
    /// Warnings: parameter combinations known to lock or oscillate (before the run) and
    /// diagnostics past their thresholds (during it), each with what to change.
    pub warnings: Vec<Warning>,
    /// The worst relative error of the equilibrium identity ∫σ dV = Σ x ⊗ (F_ext + R − F_inertia)
    /// over the converged steps (see `recorders::equilibrium`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub equilibrium_error: Option<f64>,
    /// Why the run ended before the last stage's end although nothing failed (e.g. a footing
    /// that reached the settlement its check stops at).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stopped: Option<String>,
    /// Metrics against the case's analytical reference.
    pub verification: BTreeMap<String, Metric>,
    /// Quantities computed from the run without a reference to compare with: per probe the final
    /// displacement magnitude `<probe>.displacement` [m], in two-phase runs the excess pore pressure
    /// of largest magnitude (signed) `<probe>.excess_p_peak` and at the end `<probe>.excess_p_final`
    /// [Pa]; and the check's own (e.g. the bearing pressure at given settlements).
    pub results: BTreeMap<String, f64>,
    /// Whether every metric passed (absent without verification).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub verification_passed: Option<bool>,
    /// The checkpoint this run continued from.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub restarted_from: Option<crate::state::RestartInfo>,
}

impl Summary {
    /// The summary of a run that starts: `running`, with the case's label, its `--set` overrides,
    /// the simulated time it asks for, the ranks and PETSc's options database.
    pub fn new(
        case: String,
        overrides: Vec<String>,
        end_time_s: f64,
        ranks: usize,
        petsc_options: Vec<String>,
    ) -> Summary {
        Summary {
            status: "running".into(),
            error: None,
            case,
            overrides,
            porompm_version: crate::VERSION.into(),
            wall_time_s: 0.0,
            time_s: 0.0,
            end_time_s,
            steps: 0,
            step_cuts: 0,
            line_search_retries: 0,
            migrated_particles: 0,
            repartitions: 0,
            load_imbalance_max: 1.0,
            collectives: Default::default(),
            snes_iterations: 0,
            ksp_iterations: 0,
            matrix_structure_reuses: 0,
            field_residuals: Vec::new(),
            dofs: 0,
            grid_dofs: 0,
            particles: 0,
            ranks,
            solver: String::new(),
            petsc_options,
            timings: Timings::default(),
            peak_memory_mib: None,
            peak_memory_total_mib: None,
            memory: MemoryUse::default(),
            checkerboard_index_max: None,
            pressure_oscillation_index_max: None,
            pore_pressure_range: None,
            energy_balance_error: None,
            warnings: Vec::new(),
            equilibrium_error: None,
            stopped: None,
            verification: BTreeMap::new(),
            results: BTreeMap::new(),
            verification_passed: None,
            restarted_from: None,
        }
    }

    /// Ends the summary of a run: `completed`, or `failed` (`interrupted`) with the error; the
    /// metrics of a run that did not complete never count as a pass.
    pub fn settle(&mut self, error: Option<(&str, bool)>) {
        match error {
            None => self.status = "completed".into(),
            Some((message, interrupted)) => {
                self.status = if interrupted { "interrupted" } else { "failed" }.into();
                self.error = Some(message.to_string());
                if self.verification_passed.is_some() {
                    self.verification_passed = Some(false);
                }
            }
        }
    }

    /// Folds the worst values of the run's diagnostics into the summary.
    pub fn take_worst(&mut self, w: &Worst) {
        let some = |v: f64| (!v.is_nan()).then_some(v);
        self.checkerboard_index_max = some(w.checkerboard);
        self.pressure_oscillation_index_max = some(w.oscillation);
        self.pore_pressure_range = (!w.p_range[0].is_nan()).then_some(w.p_range);
        self.energy_balance_error = some(w.energy);
    }

    /// Folds the field residuals of a step just accepted into the run's maxima (by field name:
    /// a stage may change the system): the final Newton residual of each field of `fields` (norms
    /// `norms`) against the larger of its equation magnitudes at the step's start and at its
    /// converged state, and the linear solves' worst relative residuals `linear`.
    pub fn fold_field_residuals(
        &mut self,
        fields: &[(&'static str, Vec<usize>)],
        norms: &[f64],
        scales: (&[f64], &[f64]),
        linear: &[f64],
    ) {
        let (start_scales, end_scales) = scales;
        for (i, (name, _)) in fields.iter().enumerate() {
            let all = &mut self.field_residuals;
            let k = match all.iter().position(|r| r.field == *name) {
                Some(k) => k,
                None => {
                    all.push(FieldResidual { field: name.to_string(), newton_final_max: 0.0, linear_max: None });
                    all.len() - 1
                }
            };
            let r = &mut all[k];
            let scale = start_scales.get(i).copied().unwrap_or(0.0).max(end_scales.get(i).copied().unwrap_or(0.0));
            if let Some(&n) = norms.get(i) {
                if scale > 0.0 {
                    r.newton_final_max = r.newton_final_max.max(n / scale);
                }
            }
            if let Some(&l) = linear.get(i) {
                r.linear_max = Some(r.linear_max.unwrap_or(0.0).max(l));
            }
        }
    }
}
