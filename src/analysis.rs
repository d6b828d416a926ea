//! Analysis types: what a stage solves. Each type is a choice of unknowns per node (a
//! [`Layout`]) and of a time treatment (an [`Integration`], which the kernels turn into the weights
//! of their terms, [`crate::kernels::Scheme`]); the driver, the assembly and the particle update are
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
//!
//! Each stage hands its particles (stress, pore pressure and its gradient, internal variables,
//! positions) to the next, whatever the types: e.g. a drained static gravity stage, a
//! quasi-static consolidation and a dynamic failure in one case.

use crate::case::{AnalysisType, Case, Drainage, Formulation, Stage};
use crate::kernels::{Integration, Layout};

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
        let two_phase = case.analysis.formulation == Formulation::TwoPhase;
        match stage.analysis {
            AnalysisType::Dynamic => StageAnalysis {
                layout: if two_phase { Layout::UPU } else { Layout::U },
                integration: stage.time_integration.as_ref().unwrap_or(&case.time_integration).integration(),
                dt_limit: None,
            },
            AnalysisType::QuasiStatic => StageAnalysis {
                layout: Layout::UP,
                integration: Integration::QuasiStatic { theta: stage.theta.unwrap_or(DEFAULT_THETA) },
                dt_limit: None,
            },
            AnalysisType::Static => StageAnalysis {
                layout: match (two_phase, stage.drainage) {
                    (true, Some(Drainage::Undrained)) => Layout::UP,
                    _ => Layout::U,
                },
                integration: Integration::Static,
                dt_limit: None,
            },
            AnalysisType::DynamicExplicit => {
                let e = stage.explicit.unwrap_or_default();
                StageAnalysis {
                    layout: Layout::U,
                    integration: Integration::Explicit {
                        flip: e.flip_blend,
                        damping: e.local_damping,
                        xpic: e.xpic_order.unwrap_or(0),
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
            _ => "u",
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
            Integration::Explicit { flip, damping, xpic } => format!(
                "explicit dynamic {unknowns} (update-stress-last, {}, local damping {damping}, Δt ≤ {:.3e} s)",
                if xpic > 0 { format!("XPIC({xpic}) transfer") } else { format!("FLIP share {flip}") },
                self.dt_limit.unwrap_or(f64::NAN)
            ),
        }
    }
}

/// The time a P-wave takes to cross the smallest cell, h_min / max c_p, with c_p = sqrt(E_c/ρ) of
/// each material at rest (E_c its constrained modulus, ρ its mixture density): the CFL limit of an
/// explicit step (the explicit stage takes C times it) [s].
pub fn wave_step(case: &Case) -> f64 {
    let h = case.cell_size();
    let c = case
        .materials
        .iter()
        .map(|m| {
            let mat = crate::model::material::Material::from_case(m, case.analysis.formulation);
            (mat.model.elastic().constrained_modulus() / mat.mixture_density(m.porosity)).sqrt()
        })
        .fold(0.0, f64::max);
    h[0].min(h[1]) / c
}

/// θ of a quasi-static stage that does not give one: backward Euler, which does not oscillate
/// however large c_v Δt / h² is (Crank–Nicolson, θ = 1/2, rings there; see docs/analysis.md).
pub const DEFAULT_THETA: f64 = 1.0;
