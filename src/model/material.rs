//! Materials: phase properties of the mixture and the constitutive model of the skeleton.
//!
//! Stress and strain are 4-vectors [xx, yy, xy, zz] (plane strain; engineering shear strain
//! γ_xy = 2ε_xy; tension positive). A soil model maps a stress and a strain increment to the new
//! stress and the consistent tangent dσ/dε (4×4).

use crate::case::{self, Formulation, SoilModel};

/// A 4×4 matrix in the stress-vector basis.
pub type Mat4 = [[f64; 4]; 4];

/// Result of a stress update.
#[derive(Debug, Clone, Copy)]
pub struct StressUpdate {
    /// The updated stress [Pa].
    pub stress: [f64; 4],
    /// Consistent tangent dσ/dΔε [Pa].
    pub tangent: Mat4,
}

/// Isotropic linear elasticity in plane strain.
#[derive(Debug, Clone, Copy)]
pub struct LinearElastic {
    /// Young's modulus [Pa].
    pub young: f64,
    /// Poisson's ratio [-].
    pub poisson: f64,
    /// Elastic matrix D^e.
    pub d: Mat4,
}

impl LinearElastic {
    /// Elasticity with Young's modulus `e` [Pa] and Poisson's ratio `nu`.
    pub fn new(e: f64, nu: f64) -> Self {
        let lam = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
        let mu = e / (2.0 * (1.0 + nu));
        let a = lam + 2.0 * mu;
        let d = [[a, lam, 0.0, lam], [lam, a, 0.0, lam], [0.0, 0.0, mu, 0.0], [lam, lam, 0.0, a]];
        LinearElastic { young: e, poisson: nu, d }
    }

    /// Constrained (oedometric) modulus E_c = E(1 − ν)/((1 + ν)(1 − 2ν)) [Pa].
    pub fn constrained_modulus(&self) -> f64 {
        self.d[0][0]
    }

    /// Shear modulus [Pa].
    pub fn shear_modulus(&self) -> f64 {
        self.d[2][2]
    }
}

/// The constitutive model of the skeleton.
#[derive(Debug, Clone, Copy)]
pub enum Constitutive {
    /// Linear elasticity (never calls a return mapping).
    LinearElastic(LinearElastic),
}

impl Constitutive {
    /// New stress and consistent tangent for the strain increment `deps` from `stress`
    /// ([003] Eq. 24c: σ' ← σ' + D Δε for the elastic skeleton).
    #[inline]
    pub fn update(&self, stress: &[f64; 4], deps: &[f64; 4]) -> StressUpdate {
        match self {
            Constitutive::LinearElastic(el) => {
                let mut s = *stress;
                for (r, sr) in s.iter_mut().enumerate() {
                    *sr += (0..4).map(|c| el.d[r][c] * deps[c]).sum::<f64>();
                }
                StressUpdate { stress: s, tangent: el.d }
            }
        }
    }

    /// Elastic part (for the reference solutions and time-step estimates).
    pub fn elastic(&self) -> &LinearElastic {
        match self {
            Constitutive::LinearElastic(el) => el,
        }
    }

    /// Whether the model is linear (its tangent never changes).
    pub fn is_linear(&self) -> bool {
        matches!(self, Constitutive::LinearElastic(_))
    }
}

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
        let model = match m.model {
            SoilModel::LinearElastic { young_modulus, poisson_ratio } => {
                Constitutive::LinearElastic(LinearElastic::new(young_modulus, poisson_ratio))
            }
        };
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
    fn plane_strain_elasticity_gives_the_constrained_modulus_in_an_oedometer() {
        let el = LinearElastic::new(1e7, 0.3);
        let m = Constitutive::LinearElastic(el);
        let u = m.update(&[0.0; 4], &[0.0, -1e-3, 0.0, 0.0]);
        let ec = 1e7 * 0.7 / (1.3 * 0.4);
        assert!((u.stress[1] + ec * 1e-3).abs() < 1e-6 * ec);
        // Lateral stress ratio ν/(1 − ν) and σ_zz = σ_xx in an oedometer.
        assert!((u.stress[0] / u.stress[1] - 0.3 / 0.7).abs() < 1e-12);
        assert!((u.stress[3] - u.stress[0]).abs() < 1e-9);
        assert!((el.shear_modulus() - 1e7 / 2.6).abs() < 1e-6);
    }

    #[test]
    fn elastic_update_is_additive_and_the_tangent_is_d() {
        let m = Constitutive::LinearElastic(LinearElastic::new(2e7, 0.25));
        let s0 = [1.0, -2.0, 0.5, 3.0];
        let de = [1e-4, -2e-4, 3e-4, 0.0];
        let u = m.update(&s0, &de);
        // Finite-difference check of the tangent.
        for c in 0..4 {
            let mut dp = de;
            dp[c] += 1e-7;
            let up = m.update(&s0, &dp);
            for r in 0..4 {
                let fd = (up.stress[r] - u.stress[r]) / 1e-7;
                assert!((fd - u.tangent[r][c]).abs() < 1e-3 * u.tangent[0][0]);
            }
        }
    }

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
