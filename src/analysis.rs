//! Analysis types: what a stage solves. Each type is a choice of unknowns per node (a
//! [`Layout`]) and of a time treatment (an [`Integration`], which the kernels turn into the weights
//! of their terms, [`crate::scheme::Scheme`]); the driver, the assembly and the particle update are
//! the same for all of them.
//!
//! | stage `analysis` | formulation | unknowns per node | time |
//! |---|---|---|---|
//! | `dynamic` (default) | two-phase | u, p, U (u–p–U, [003]) | Newmark or generalized-α |
//! | `dynamic` | one-phase | u | Newmark or generalized-α |
//! | `quasi_static` | two-phase | u, p (Biot's u–p with Darcy's law) | θ-method on the flux |
//! | `static`, `drainage = "undrained"` | two-phase | u, p (no flow) | none (load stepping) |
//! | `static`, `drainage = "drained"` | two-phase | u (p held) | none |
//! | `static` | one-phase | u | none |
//! | `dynamic_explicit` | one-phase | u | explicit ([002]: lumped mass, update-stress-last) |
//! | `dynamic_explicit` | two-phase | u, U (the pore pressure at the points) | explicit, the drag implicit at each node |
//!
//! With `stabilisation.fbar` an implicit u or u–p stage adds ϑ = J̄ − 1, [002]'s projected volume
//! ratio, to each node's unknowns (`kernels::fbar`, [`Layout::with_fbar`]).
//!
//! Each stage hands its particles (stress, pore pressure and its gradient, internal variables,
//! positions) to the next, whatever the types: e.g. a drained static gravity stage, a
//! quasi-static consolidation and a dynamic failure in one case.

use crate::case::{AnalysisType, Case, Formulation, Stage};
use crate::layout::Layout;
use crate::scheme::Integration;

/// What one stage solves.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StageAnalysis {
    /// Unknowns per node.
    pub layout: Layout,
    /// Time treatment.
    pub integration: Integration,
    /// The largest stable step of an explicit stage, C h_min / c_p [s] (`None` otherwise).
    pub dt_limit: Option<f64>,
}

impl StageAnalysis {
    /// The analysis of `stage` in `case` (validated: a quasi-static stage is two-phase, a static
    /// stage of a two-phase case says its drainage).
    pub fn of(case: &Case, stage: &Stage) -> StageAnalysis {
        let pore_water = case.analysis.formulation == Formulation::TwoPhase;
        // [002]'s F̄ in an implicit stage: the projected volume ratio joins the unknowns
        // (`kernels::fbar`) of the u and u–p systems; validation refuses F̄ in a stage whose
        // layout has no such form (u–p–U), which it finds by this function.
        let layout = stage.layout(pore_water, case.stabilisation.fbar);
        match stage.analysis {
            AnalysisType::Dynamic => StageAnalysis {
                layout,
                integration: stage.time_integration.as_ref().unwrap_or(&case.time_integration).integration(),
                dt_limit: None,
            },
            AnalysisType::QuasiStatic => StageAnalysis {
                layout,
                integration: Integration::QuasiStatic { theta: stage.theta.unwrap_or(DEFAULT_THETA) },
                dt_limit: None,
            },
            AnalysisType::Static => StageAnalysis { layout, integration: Integration::Static, dt_limit: None },
            AnalysisType::DynamicExplicit => {
                let e = stage.explicit.unwrap_or_default();
                StageAnalysis {
                    layout,
                    integration: Integration::Explicit {
                        flip: e.flip_blend,
                        damping: e.local_damping,
                        xpic: e.xpic_order.unwrap_or(0),
                        pointwise_pressure: e.pore_pressure != Some(crate::case::ExplicitPressure::Nodal),
                    },
                    dt_limit: Some(e.cfl * wave_step(case)),
                }
            }
        }
    }

    /// A short description for progress lines and `porompm check`.
    pub fn describe(&self) -> String {
        let unknowns = match (self.layout.p, self.layout.w) {
            (Some(_), Some(_)) => "u–p–U",
            (Some(_), None) => "u–p",
            (None, Some(_)) => "u–U",
            _ => "u",
        };
        let unknowns = match self.layout.jbar {
            Some(_) => format!("{unknowns} with F̄ (the projected J̄ at the nodes)"),
            None => unknowns.to_string(),
        };
        match self.integration {
            Integration::Dynamic { beta, gamma, alpha_m, alpha_f } if alpha_m == 0.0 && alpha_f == 0.0 => {
                format!("dynamic {unknowns}, Newmark β = {beta}, γ = {gamma}")
            }
            Integration::Dynamic { alpha_m, alpha_f, .. } => {
                format!("dynamic {unknowns}, generalized-α (α_m = {alpha_m:.4}, α_f = {alpha_f:.4})")
            }
            Integration::QuasiStatic { theta } => format!("quasi-static {unknowns} with Darcy flow, θ = {theta}"),
            Integration::Static if self.layout.p.is_some() => format!("static {unknowns}, undrained"),
            Integration::Static => format!("static {unknowns}"),
            Integration::Explicit { flip, damping, xpic, pointwise_pressure } => format!(
                "explicit dynamic {unknowns}{} (update-stress-last, {}, local damping {damping}, Δt ≤ {:.3e} s)",
                match (self.layout.w, pointwise_pressure) {
                    (None, _) => "",
                    (Some(_), false) =>
                        " with the pore pressure at the nodes (lumped continuity), drag implicit per node",
                    (Some(_), true) => " with the pore pressure point by point, drag implicit per node",
                },
                if xpic > 0 { format!("XPIC({xpic}) transfer") } else { format!("FLIP share {flip}") },
                self.dt_limit.unwrap_or(f64::NAN)
            ),
        }
    }
}

/// The time a P-wave takes to cross the smallest cell, h_min / max c_p, with c_p of each material
/// at rest: the CFL limit of an explicit step (the explicit stage takes C times it) [s]. One-phase,
/// c_p = sqrt(E_c/ρ) (E_c the constrained modulus, ρ the mixture density); two-phase, the faster
/// of the two P-waves of the u–U system without drag ([`coupled_wave_speed`]), which bounds the
/// undrained wave (the phases locked by a large drag) too.
pub fn wave_step(case: &Case) -> f64 {
    let h = case.cell_size();
    let pore_water = case.analysis.formulation == Formulation::TwoPhase;
    let c = case
        .materials
        .iter()
        .map(|m| {
            let mat = crate::model::material::Material::from_case(m, case.analysis.formulation);
            let e_c = mat.model.elastic().constrained_modulus();
            if pore_water {
                coupled_wave_speed(e_c, mat.inv_q_at(m.porosity), m.porosity, mat.solid_density, mat.water_density)
            } else {
                (e_c / mat.mixture_density(m.porosity)).sqrt()
            }
        })
        .fold(0.0, f64::max);
    h[0].min(h[1]) / c
}

/// The fast P-wave speed of the u–U system without drag [m/s]: per unit wave number the
/// stiffness K = [[E_c + (1 − n)²Q, n(1 − n)Q], [n(1 − n)Q, n²Q]] (the skeleton's constrained
/// modulus E_c and the pore pressure p = −Q((1 − n)∇·u + n∇·U) shared (1 − n) : n by the phases,
/// [003] Eqs. 23a–c) against the mass M = diag((1 − n)ρ_s, nρ_w); c² is the larger eigenvalue of
/// M⁻¹K. Any drag couples the phases towards the undrained wave, whose c² = (E_c + Q)/ρ is a
/// Rayleigh quotient of the same pair and so no larger.
pub fn coupled_wave_speed(e_c: f64, inv_q: f64, n: f64, rho_s: f64, rho_w: f64) -> f64 {
    let q = 1.0 / inv_q;
    let (ms, mw) = ((1.0 - n) * rho_s, n * rho_w);
    let (a, b, d) = ((e_c + (1.0 - n).powi(2) * q) / ms, n * (1.0 - n) * q / (ms * mw).sqrt(), n * n * q / mw);
    // The larger eigenvalue of the symmetric M^{-1/2} K M^{-1/2} = [[a, b], [b, d]].
    (0.5 * (a + d) + (0.25 * (a - d).powi(2) + b * b).sqrt()).sqrt()
}

/// θ of a quasi-static stage that does not give one: backward Euler, which does not oscillate
/// however large c_v Δt / h² is (Crank–Nicolson, θ = 1/2, rings there; see docs/analysis.md).
pub const DEFAULT_THETA: f64 = 1.0;

#[cfg(test)]
mod tests {
    use super::coupled_wave_speed;

    /// The fast wave of the u–U pair: without a water stiffness it is the skeleton's own wave in
    /// the grains' mass; without a skeleton, K = Q v vᵀ (v = (1 − n, n)) has the one eigenvalue
    /// Q vᵀM⁻¹v = Q ((1 − n)/ρ_s + n/ρ_w); and it is never slower than the undrained wave of the
    /// locked mixture, sqrt((E_c + Q)/ρ).
    #[test]
    fn the_coupled_wave_speed_has_its_limits() {
        let (n, rs, rw) = (0.3, 2650.0, 1000.0);
        let c = coupled_wave_speed(1e7, 1e6, n, rs, rw);
        assert!((c / (1e7 / ((1.0 - n) * rs)).sqrt() - 1.0).abs() < 1e-9, "{c}");
        let q = 2.2e9 / n;
        let c = coupled_wave_speed(0.0, 1.0 / q, n, rs, rw);
        assert!((c / (q * ((1.0 - n) / rs + n / rw)).sqrt() - 1.0).abs() < 1e-12, "{c}");
        for e_c in [1e5, 1e7, 1e9, 1e11] {
            let fast = coupled_wave_speed(e_c, 1.0 / q, n, rs, rw);
            let undrained = ((e_c + q) / ((1.0 - n) * rs + n * rw)).sqrt();
            assert!(fast >= undrained * (1.0 - 1e-12), "E_c = {e_c}: {fast} < {undrained}");
        }
    }
}
