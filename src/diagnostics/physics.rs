//! Checks of a case's physics before it runs: parameter combinations known to lock or to
//! oscillate are run, but with a warning that says what to change.
//!
//! - `locking`: a skeleton with ν ≥ [`LOCKING_NU`] without B̄. GIMP and linear MPM integrate the
//!   volumetric strain at every material point, too many constraints for a nearly incompressible
//!   skeleton (Terzaghi at ν = 0.4999 without B̄: settlement error 18 %).
//! - `equal_order_near_undrained`: equal-order pressures without pressure projection (or the MLSA
//!   patch recovery of [003], which smooths what the particles take from the nodes) when the
//!   water is much stiffer than the skeleton (Q ≥ [`STIFF_WATER`] M) and drains less than a tenth of
//!   a cell per step (c_v Δt / h² < [`UNDRAINED_RATIO`], or a static undrained stage): the
//!   discrete inf–sup condition fails and the pressure can alternate from node to node (Terzaghi at
//!   k = 1e-12 m/s: particle pressures up to 1.5 times the load). An explicit two-phase stage
//!   has the same failing with its nodal pore pressure (`explicit.pore_pressure = "nodal"`) when
//!   the water drains less than a cell over the whole stage (c_v T / h² < 1; Terzaghi at
//!   k = 1e-12 m/s: 0.61 and 1.41 times the undrained pressure at two points); its point-wise
//!   pressure (the default) is stable there and is not checked.
//! - `single_point_cells`: a two-phase body with one material point per cell in a dynamic stage.
//!   Each cell is then integrated at one point, and the u–p–U system has modes its stiffness does
//!   not see: the Terzaghi column at 1 × 1 per cell diverges within ten steps (Newton stalls, then
//!   the pressure becomes NaN), with or without pressure projection; quasi-static it passes.
//! - `unresolved_consolidation`: a dynamic two-phase stage whose step is more than
//!   [`CONSOLIDATION_SHARE`] of the consolidation time H²/c_v (H the grid's larger side, an upper
//!   bound of the drainage path): the step does not resolve the flow, and no dynamic scheme is
//!   monotone there (Terzaghi at Δt = 1 s: pore pressure down to −5.6 % of the load with the default
//!   generalized-α, −1.2 % with ρ∞ = 0; at ν = 0.4999, c_v = 520 m²/s, the shipped Δt is half the
//!   consolidation time and the settlement is 18 % off). A `quasi_static` stage (backward Euler,
//!   L-stable) keeps the pressure within the undrained one at any step.
//! - `patch_recovery_quasi_static`: MLSA patch recovery ([003] §3.3, made for the dynamic u–p–U
//!   system) in a quasi-static stage. It replaces each particle's pressure increment by a patch fit,
//!   while the gradient that drives the u–p system's Darcy flux keeps the interpolated one, and the
//!   quasi-static answers get worse: Terzaghi's settlement error 1.6e-3 against 5.6e-4 without it;
//!   the large-strain column 4.1 % against 0.57 % at 20 cells, Δt = 1e-3 s (docs/analysis.md).
//! - `undamped_large_step`: a dynamic stage whose step is longer than the time a compression wave
//!   takes to cross a cell (Courant number c Δt / h > [`COURANT_LIMIT`]) with a time integration
//!   that damps nothing (Newmark with γ = 1/2, generalized-α with ρ∞ = 1): the waves the grid cannot
//!   resolve keep ringing.

use super::Warning;
use crate::analysis::StageAnalysis;
use crate::case::{AnalysisType, Case, Drainage};
use crate::model::material::Material;
use crate::model::Model;
use crate::scheme::Integration;

/// Poisson's ratio from which a skeleton without B̄ locks.
pub const LOCKING_NU: f64 = 0.49;
/// Q / M from which the pore water makes the undrained mixture nearly incompressible.
pub const STIFF_WATER: f64 = 10.0;
/// c_v Δt / h² below which a step is nearly undrained.
pub const UNDRAINED_RATIO: f64 = 1e-2;
/// The share of the consolidation time H²/c_v above which a dynamic step does not resolve the flow.
/// Measured on Terzaghi (H²/c_v = 0.98 s): the smallest particle pressure is −1e-4 q at shares
/// 0.05 … 0.2, −5.5e-3 q at 0.5 and −5.6e-2 q at 1; the harmonic column of zone III runs at 0.12.
pub const CONSOLIDATION_SHARE: f64 = 0.25;
/// The Courant number beyond which a dynamic step does not resolve the compression wave.
pub const COURANT_LIMIT: f64 = 1.0;

/// The warnings of a case (its model built).
pub fn warnings<const D: usize>(case: &Case, model: &Model<D>) -> Vec<Warning> {
    let mut out = Vec::new();
    if !model.bbar && !model.fbar {
        locking(model, &mut out);
    }
    if model.pore_water && model.pressure_projection.is_none() && !model.patch_recovery {
        near_undrained(case, model, &mut out);
    }
    if model.patch_recovery {
        patch_recovery_quasi_static(case, &mut out);
    }
    if model.pore_water && case.stages.iter().any(|s| s.analysis == AnalysisType::Dynamic) {
        single_point_cells(case, &mut out);
    }
    if model.pore_water {
        unresolved_consolidation(case, model, &mut out);
    }
    undamped_large_steps(case, model, &mut out);
    out
}

/// A warning of `kind` with its message.
fn warn(out: &mut Vec<Warning>, kind: &str, message: String) {
    out.push(Warning { kind: kind.into(), message, time_s: None, value: None, threshold: None })
}

/// The consolidation coefficient c_v [m²/s] of material `m`.
fn consolidation_coefficient<const D: usize>(model: &Model<D>, m: &Material) -> f64 {
    m.conductivity
        / (m.water_density * model.g.abs().max(f64::MIN_POSITIVE))
        / (1.0 / m.model.elastic().constrained_modulus() + m.inv_q)
}

/// `locking`: a material with ν ≥ [`LOCKING_NU`] without B̄ or F̄.
fn locking<const D: usize>(model: &Model<D>, out: &mut Vec<Warning>) {
    for (i, m) in model.materials.iter().enumerate() {
        let nu = m.model.elastic().poisson;
        if nu >= LOCKING_NU {
            warn(
                out,
                "locking",
                format!(
                    "materials[{i}] (`{}`): ν = {nu} ≥ {LOCKING_NU} locks without B̄ or F̄ (the volumetric strain is constrained at every material point); set stabilisation.bbar = true (implicit stages) or stabilisation.fbar = true",
                    m.name
                ),
            );
        }
    }
}

/// `equal_order_near_undrained`: the first stage and material whose water is much stiffer than
/// the skeleton and drains too little for the equal-order pressure.
fn near_undrained<const D: usize>(case: &Case, model: &Model<D>, out: &mut Vec<Warning>) {
    let h = model.grid.h_min();
    for (s, stage) in case.stages.iter().enumerate() {
        let flow = match (stage.analysis, stage.drainage) {
            (AnalysisType::Static, Some(Drainage::Undrained)) => false,
            (AnalysisType::Static, _) => continue,
            _ => true,
        };
        let explicit = stage.analysis == AnalysisType::DynamicExplicit;
        if explicit && stage.explicit.unwrap_or_default().pore_pressure != Some(crate::case::ExplicitPressure::Nodal) {
            continue;
        }
        for (i, m) in model.materials.iter().enumerate() {
            let big_m = m.model.elastic().constrained_modulus();
            let q = 1.0 / m.inv_q;
            if q < STIFF_WATER * big_m {
                continue;
            }
            let cv = consolidation_coefficient(model, m);
            if explicit {
                let ratio = cv * stage.duration / (h * h);
                if ratio < 1.0 {
                    warn(
                        out,
                        "equal_order_near_undrained",
                        format!(
                            "stage `{}` (stages[{s}]) with materials[{i}] (`{}`): the water is {:.0} times stiffer than the skeleton and drains less than a cell over the \
                             whole explicit stage (c_v T / h² = {ratio:.1e} < 1); the nodal pore pressure (`explicit.pore_pressure = \"nodal\"`) then alternates from node to \
                             node: use the point-wise pressure (leave `pore_pressure` out)",
                            stage.name,
                            m.name,
                            q / big_m,
                        ),
                    );
                    return;
                }
                continue;
            }
            let ratio = if flow { cv * stage.dt() / (h * h) } else { 0.0 };
            if ratio < UNDRAINED_RATIO {
                warn(
                    out,
                    "equal_order_near_undrained",
                    format!(
                        "stage `{}` (stages[{s}]) with materials[{i}] (`{}`): the water is {:.0} times stiffer than the skeleton and drains {} (c_v Δt / h² = {ratio:.1e} < {UNDRAINED_RATIO}); \
                         equal-order pressures then alternate from node to node: set stabilisation.pressure_projection = 2.0",
                        stage.name,
                        m.name,
                        q / big_m,
                        if flow { "less than a tenth of a cell per step" } else { "not at all (undrained stage)" }
                    ),
                );
                return;
            }
        }
    }
}

/// `patch_recovery_quasi_static`: the first quasi-static stage with the MLSA patch recovery.
fn patch_recovery_quasi_static(case: &Case, out: &mut Vec<Warning>) {
    if let Some((s, stage)) = case.stages.iter().enumerate().find(|(_, s)| s.analysis == AnalysisType::QuasiStatic) {
        warn(
            out,
            "patch_recovery_quasi_static",
            format!(
                "stage `{}` (stages[{s}]) is quasi-static with stabilisation.patch_recovery = true: the MLSA recovery (made for the dynamic u–p–U system) replaces each point's \
                 pressure increment by a patch fit while the Darcy flux keeps the interpolated gradient, which makes the quasi-static answers worse (Terzaghi's settlement error \
                 three times larger); set stabilisation.patch_recovery = false, with stabilisation.pressure_projection near undrained conditions",
                stage.name
            ),
        );
    }
}

/// `single_point_cells`: every body with one material point per cell (in a two-phase case with a
/// dynamic stage).
fn single_point_cells(case: &Case, out: &mut Vec<Warning>) {
    for (i, b) in case.bodies.iter().enumerate().filter(|(_, b)| b.particles_per_cell == 1) {
        warn(
            out,
            "single_point_cells",
            format!(
                "bodies[{i}] (`{}`): one material point per cell integrates each cell at a single point, which leaves the u–p–U system of a dynamic stage modes its stiffness does not see \
                 (the Terzaghi column diverges within ten steps); use particles_per_cell ≥ 2, or quasi_static stages",
                b.name
            ),
        );
    }
}

/// `unresolved_consolidation`: every dynamic stage whose step is too long a share of the fastest
/// consolidation time H²/c_v of the materials (H the grid's larger side).
fn unresolved_consolidation<const D: usize>(case: &Case, model: &Model<D>, out: &mut Vec<Warning>) {
    let extent = (0..D).map(|d| model.grid.h[d] * model.grid.cells[d] as f64).fold(0.0, f64::max);
    let t_c = model
        .materials
        .iter()
        .map(|m| extent * extent / consolidation_coefficient(model, m))
        .fold(f64::INFINITY, f64::min);
    for (s, stage) in case.stages.iter().enumerate().filter(|(_, s)| s.analysis == AnalysisType::Dynamic) {
        let share = stage.dt() / t_c;
        if share > CONSOLIDATION_SHARE {
            warn(
                out,
                "unresolved_consolidation",
                format!(
                    "stage `{}` (stages[{s}]): Δt = {:.3e} s is {share:.2} of the consolidation time H²/c_v = {t_c:.3e} s (H = {extent} m, the grid's larger side): \
                     the dynamic step does not resolve the flow and the pore pressure can undershoot (below zero under a compressive load); \
                     take Δt ≤ {CONSOLIDATION_SHARE} H²/c_v, or for a slow process analysis = \"quasi_static\" (backward Euler, stable at any step)",
                    stage.name,
                    stage.dt()
                ),
            );
        }
    }
}

/// `undamped_large_step`: every dynamic stage whose time integration damps nothing and whose step
/// is longer than a compression wave takes to cross a cell.
fn undamped_large_steps<const D: usize>(case: &Case, model: &Model<D>, out: &mut Vec<Warning>) {
    let h = model.grid.h_min();
    for (s, stage) in case.stages.iter().enumerate() {
        let Integration::Dynamic { gamma, alpha_m, alpha_f, .. } = StageAnalysis::of(case, stage).integration else {
            continue;
        };
        if (gamma - 0.5).abs() > 1e-9 || (alpha_m - alpha_f).abs() > 1e-9 {
            continue;
        }
        let courant = model
            .materials
            .iter()
            .map(|m| {
                let stiff =
                    m.model.elastic().constrained_modulus() + if model.pore_water { 1.0 / m.inv_q } else { 0.0 };
                (stiff / m.mixture_density(m.porosity)).sqrt() * stage.dt() / h
            })
            .fold(0.0, f64::max);
        if courant > COURANT_LIMIT {
            warn(
                out,
                "undamped_large_step",
                format!(
                    "stage `{}` (stages[{s}]): Δt = {:.3e} s is {courant:.1} times the time a compression wave takes to cross a cell, and its time integration damps nothing: \
                     the waves the grid cannot resolve keep ringing; give it time_integration.rho_inf < 1 (e.g. 0.2), or for a slow process analysis = \"quasi_static\" (two-phase) or \"static\"",
                    stage.name,
                    stage.dt()
                ),
            );
        }
    }
}
