//! Materials: phase properties of the mixture, permeability laws and the skeleton's soil model
//! ([`crate::soils`]).

use crate::case::{self, Formulation};
use crate::soils::Constitutive;

/// A material as the solver uses it.
#[derive(Debug, Clone)]
pub struct Material {
    /// Name from the case.
    pub name: String,
    /// Initial porosity n₀ [-].
    pub porosity: f64,
    /// Grain density ρ_s [kg/m³].
    pub solid_density: f64,
    /// Water density ρ_w [kg/m³].
    pub water_density: f64,
    /// 1/Q = n/K_w + (1 − n)/K_s [1/Pa] at the initial porosity (two-phase; 0 otherwise).
    pub inv_q: f64,
    /// Water bulk modulus K_w [Pa] (two-phase; infinite otherwise).
    pub water_bulk_modulus: f64,
    /// Grain bulk modulus K_s [Pa].
    pub solid_bulk_modulus: f64,
    /// Hydraulic conductivity k₀ [m/s] at the initial porosity (two-phase; infinite otherwise).
    pub conductivity: f64,
    /// How the conductivity follows the void ratio.
    pub conductivity_law: case::ConductivityLaw,
    /// Skeleton model.
    pub model: Constitutive,
}

impl Material {
    /// Builds the solver's material from the case's.
    pub fn from_case(m: &case::Material, formulation: Formulation) -> Material {
        let model = m.model.law();
        let two = formulation == Formulation::TwoPhase;
        let kw = if two { m.water_bulk_modulus.unwrap_or(f64::INFINITY) } else { f64::INFINITY };
        let ks = m.solid_bulk_modulus.unwrap_or(f64::INFINITY);
        Material {
            name: m.name.clone(),
            porosity: m.porosity,
            solid_density: m.solid_density,
            water_density: m.water_density,
            inv_q: if two { inv_q(m.porosity, kw, ks) } else { 0.0 },
            water_bulk_modulus: kw,
            solid_bulk_modulus: ks,
            conductivity: if two { m.hydraulic_conductivity.unwrap_or(f64::INFINITY) } else { f64::INFINITY },
            conductivity_law: m.hydraulic_conductivity_law,
            model,
        }
    }

    /// Mixture density ρ = (1 − n)ρ_s + nρ_w at porosity `n` [kg/m³].
    pub fn mixture_density(&self, n: f64) -> f64 {
        (1.0 - n) * self.solid_density + n * self.water_density
    }

    /// Hydraulic conductivity at porosity `n` [m/s]: k₀, or k₀ ((1 + e)/(1 + e₀))² =
    /// k₀ ((1 − n₀)/(1 − n))² under the law of Xie & Leo (2004).
    pub fn conductivity_at(&self, n: f64) -> f64 {
        match self.conductivity_law {
            case::ConductivityLaw::Constant => self.conductivity,
            case::ConductivityLaw::XieLeo => self.conductivity * ((1.0 - self.porosity) / (1.0 - n)).powi(2),
        }
    }

    /// 1/Q at porosity `n`.
    pub fn inv_q_at(&self, n: f64) -> f64 {
        inv_q(n, self.water_bulk_modulus, self.solid_bulk_modulus)
    }
}

/// 1/Q = n/K_w + (1 − n)/K_s ([003] Eq. 5); infinite moduli contribute nothing.
pub fn inv_q(n: f64, kw: f64, ks: f64) -> f64 {
    let t = |k: f64| if k.is_infinite() { 0.0 } else { 1.0 / k };
    n * t(kw) + (1.0 - n) * t(ks)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_xie_leo_conductivity_follows_the_void_ratio_squared() {
        let mut m = Material::from_case(
            &crate::case::parse(crate::case::tests_support::MINIMAL, "t", &[]).unwrap().materials[0],
            case::Formulation::TwoPhase,
        );
        assert_eq!(m.conductivity_at(0.2), m.conductivity);
        m.conductivity_law = case::ConductivityLaw::XieLeo;
        // n₀ = 0.3 → e₀ = 3/7; n = 0.2 → e = 1/4: ((1 + e)/(1 + e₀))² = (1.25/1.428571)².
        let ratio = (1.25f64 / (10.0 / 7.0)).powi(2);
        assert!((m.conductivity_at(0.2) / m.conductivity - ratio).abs() < 1e-12);
    }

    #[test]
    fn storage_coefficient_ignores_infinite_moduli() {
        assert!((inv_q(0.4, 2e9, f64::INFINITY) - 0.4 / 2e9).abs() < 1e-25);
        assert_eq!(inv_q(0.4, f64::INFINITY, f64::INFINITY), 0.0);
        assert!((inv_q(0.3, 2.2e9, 1e10) - (0.3 / 2.2e9 + 0.7 / 1e10)).abs() < 1e-24);
    }
}
