//! Compressible neo-Hookean hyperelasticity, `type = "neo_hookean"` (Cook's membrane, [002] §4.1):
//! its parameters, E and ν, and its law, the stress of the point's total deformation gradient.

use super::finite_strain::{det, finite_update, left_tangent, normal, push, FiniteTangent, M3, UNIT};
use super::{Elasticity, LinearElastic, Region, SoilLaw, SoilParameters, Stress, StressUpdate};
use crate::check::Checked;
use serde::{Deserialize, Serialize};

// The parameters of `type = "neo_hookean"`: E and ν, the table of [`Elasticity`]. It has no doc
// comment on purpose: with one, schemars would describe the newtype by a reference to
// `Elasticity`'s schema, and the case reference would lose the table's keys.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(transparent)]
pub struct NeoHookeanParameters(pub Elasticity);

impl SoilParameters for NeoHookeanParameters {
    const FINITE_STRAIN: bool = true;
    const STRESS_FUNCTION_OF: Option<&'static str> = Some("its deformation");

    type Law = NeoHookeanLaw;

    fn law(&self) -> NeoHookeanLaw {
        NeoHookeanLaw::new(self.0.young_modulus, self.0.poisson_ratio)
    }

    fn check(&self, key: &str) -> Checked {
        self.0.check(key)
    }

    fn describe(&self) -> String {
        format!("neo-Hookean, {}", self.0.describe())
    }
}

/// Compressible neo-Hookean elasticity (Cook's membrane, [002] §4.1): Kirchhoff stress
/// τ = μ(b − 1) + λ ln J 1 with b = F Fᵀ, σ = τ/J (Bonet & Wood 2008, Eq. 6.28). Its small-strain
/// limit is linear elasticity with the same λ, μ.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NeoHookeanLaw {
    /// The elasticity of the same moduli, which serves the estimates.
    pub elastic: LinearElastic,
    /// Shear modulus μ [Pa].
    pub shear: f64,
    /// Lamé's λ [Pa].
    pub lame: f64,
}

impl NeoHookeanLaw {
    /// From Young's modulus [Pa] and Poisson's ratio.
    pub fn new(e: f64, nu: f64) -> NeoHookeanLaw {
        NeoHookeanLaw {
            elastic: LinearElastic::new(e, nu),
            shear: e / (2.0 * (1.0 + nu)),
            lame: e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)),
        }
    }

    /// The Cauchy stress of the deformation gradient `f`. `None` when J ≤ 0.
    pub fn stress(&self, f: M3) -> Option<Stress> {
        let j = det(f);
        if j <= 0.0 {
            return None;
        }
        let b = push(f, &UNIT);
        let vol = self.lame * j.ln();
        let (mu, inv) = (self.shear, 1.0 / j);
        Some(std::array::from_fn(|c| if normal(c) { (mu * (b[c] - 1.0) + vol) * inv } else { mu * b[c] * inv }))
    }
}

impl SoilLaw for NeoHookeanLaw {
    const ELASTIC: bool = true;

    /// The stress is a function of `f` alone.
    fn finite(&self, _df: &M3, f: &M3, _stress: &Stress, eps_pd: f64, _dt: f64) -> Option<StressUpdate> {
        Some(finite_update(&self.elastic, self.stress(*f), eps_pd, Region::Elastic))
    }

    /// δτ = μ δb + λ (δJ/J) 1 with b = F Fᵀ = ΔF (F_n F_nᵀ) ΔFᵀ ([`left_tangent`]).
    fn finite_tangent(&self, df: &M3, f: &M3, _stress: &Stress, _eps_pd: f64, _dt: f64) -> Option<FiniteTangent> {
        let sigma = self.stress(*f)?;
        let (mu, lame) = (self.shear, self.lame);
        let dtau = |db: &Stress, tr: f64| -> Stress {
            std::array::from_fn(|c| mu * db[c] + if normal(c) { lame * tr } else { 0.0 })
        };
        Some(left_tangent(df, &push(*f, &UNIT), &sigma, det(*f), dtau))
    }

    /// A hyperelastic model's stress comes from the total deformation ([`SoilLaw::finite`]); its
    /// increment here is the small-strain one of the same moduli, with their tangent (the
    /// kernels' tests use it; a case runs it through `finite` and `finite_tangent`).
    fn update(&self, stress: &Stress, eps_pd: f64, deps: &Stress) -> StressUpdate {
        self.elastic.update(stress, eps_pd, deps)
    }

    fn elastic(&self) -> &LinearElastic {
        &self.elastic
    }
}
