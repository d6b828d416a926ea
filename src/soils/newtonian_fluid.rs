//! A weakly compressible Newtonian fluid, `type = "newtonian_fluid"` (the dam break, [002] §4.3):
//! its parameters ([`NewtonianFluid`]) and its stress of J and the step's rate of deformation
//! ([`NewtonianFluidLaw`]).

use super::finite_strain::{det, finite_update, normal, rate_of_deformation, M3};
use super::principal;
use super::{LinearElastic, Region, SoilLaw, SoilParameters, Stress, StressUpdate, NS};
use crate::check::{at, modulus, viscosity, Checked};
use serde::{Deserialize, Serialize};

/// The parameters of `type = "newtonian_fluid"`.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct NewtonianFluid {
    /// Bulk modulus K [Pa], in (0, 1e13] (water: 2.0e9 Pa; a smaller K is the usual weakly
    /// compressible substitute when the flow's Mach number v/√(K/ρ) stays below 0.1).
    pub bulk_modulus: f64,
    /// Dynamic viscosity μ_v [Pa s], in [0, 1e13] (water: 1.0e-3 Pa s).
    pub viscosity: f64,
    /// Bulk viscosity ζ [Pa s], in [0, 1e13] (default 0): σ gains ζ tr d 1. Water has none (Stokes);
    /// explicit codes add ζ = b₁ ρ c_p h (Abaqus/Explicit: b₁ = 0.06) to damp the volumetric
    /// ringing of a stiff fluid at the grid's scale.
    #[serde(default)]
    pub bulk_viscosity: f64,
}

impl SoilParameters for NewtonianFluid {
    const FINITE_STRAIN: bool = true;
    const IMPLICIT: bool = false;
    const STRESS_FUNCTION_OF: Option<&'static str> = Some("its deformation and its rate");

    type Law = NewtonianFluidLaw;

    fn law(&self) -> NewtonianFluidLaw {
        NewtonianFluidLaw::new(self.bulk_modulus, self.viscosity, self.bulk_viscosity)
    }

    fn check(&self, key: &str) -> Checked {
        modulus(&at(key, "bulk_modulus"), self.bulk_modulus)?;
        viscosity(&at(key, "viscosity"), self.viscosity)?;
        viscosity(&at(key, "bulk_viscosity"), self.bulk_viscosity)
    }

    fn describe(&self) -> String {
        format!(
            "Newtonian fluid (finite strain), K = {:.4e} Pa, μ_v = {:.4e} Pa s, ζ = {:.4e} Pa s",
            self.bulk_modulus, self.viscosity, self.bulk_viscosity
        )
    }
}

/// A weakly compressible Newtonian fluid (the dam break, [002] §4.3):
/// σ = −p 1 + 2μ_v dev d + ζ tr d 1 with the pressure of the equation of state
/// p = K max(1 − J, 0) (water takes no tension: a stretched point is separating, not pulling) and
/// the rate of deformation d = sym L ([002] does not state its equation of state; for the
/// |J − 1| ~ 1e-5 of water any one is the same).
/// The bulk viscosity ζ is the explicit codes' damping of volumetric ringing (Abaqus/Explicit's
/// linear bulk viscosity ζ = b₁ ρ c h, b₁ = 0.06 by default; Stokes' hypothesis gives water none).
/// With F̄, the pressure sees J̄ and the bulk viscosity the rate of J̄.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonianFluidLaw {
    /// The elasticity of its bulk modulus and no shear stiffness, which serves the estimates.
    pub elastic: LinearElastic,
    /// Bulk modulus K [Pa].
    pub bulk: f64,
    /// Dynamic viscosity μ_v [Pa s].
    pub viscosity: f64,
    /// Bulk viscosity ζ [Pa s].
    pub bulk_viscosity: f64,
}

impl NewtonianFluidLaw {
    /// The fluid of bulk modulus `bulk` [Pa], viscosity `viscosity` and bulk viscosity
    /// `bulk_viscosity` [Pa s].
    pub fn new(bulk: f64, viscosity: f64, bulk_viscosity: f64) -> NewtonianFluidLaw {
        NewtonianFluidLaw { elastic: LinearElastic::from_bulk_shear(bulk, 0.0), bulk, viscosity, bulk_viscosity }
    }

    /// The Cauchy stress at volume ratio `j` and velocity gradient `l` [1/s].
    pub fn stress(&self, j: f64, l: M3) -> Stress {
        let p = self.bulk * (1.0 - j).max(0.0);
        let d = principal::TENSOR_INDEX.map(|(a, b)| 0.5 * (l[a][b] + l[b][a]));
        let m = (d[0] + d[1] + d[3]) / 3.0;
        let mu2 = 2.0 * self.viscosity;
        std::array::from_fn(|c| if normal(c) { -p + mu2 * (d[c] - m) } else { mu2 * d[c] })
    }

    /// The fluid's pressure at volume ratio `j` [Pa].
    pub fn pressure(&self, j: f64) -> f64 {
        self.bulk * (1.0 - j)
    }

    /// The stress after a step of deformation gradient `df` over `dt` seconds that leaves the
    /// fluid at the total deformation `f`: the pressure of J = det f and the viscous
    /// stress of the step's rate of deformation ([`rate_of_deformation`]).
    pub fn stress_after(&self, df: M3, f: M3, dt: f64) -> Stress {
        let mut s = self.stress(det(f), rate_of_deformation(df, dt));
        // ζ tr d with tr d = ln(det ΔF)/Δt (with F̄, det ΔF̄ = J̄_{n+1}/J̄_n).
        let dj = det(df);
        if dt > 0.0 && dj > 0.0 && self.bulk_viscosity > 0.0 {
            let q = self.bulk_viscosity * dj.ln() / dt;
            for c in (0..NS).filter(|&c| normal(c)) {
                s[c] += q;
            }
        }
        s
    }
}

impl SoilLaw for NewtonianFluidLaw {
    const ELASTIC: bool = true;

    /// The pressure follows J = det `f` and the viscous stress the step's rate of deformation, ΔF
    /// over `dt` [s] ([`rate_of_deformation`]).
    fn finite(&self, df: &M3, f: &M3, _stress: &Stress, eps_pd: f64, dt: f64) -> Option<StressUpdate> {
        let admissible = det(*f) > 0.0;
        Some(finite_update(&self.elastic, admissible.then(|| self.stress_after(*df, *f, dt)), eps_pd, Region::Elastic))
    }

    /// The fluid's small-strain limit without viscosity: the pressure of its bulk modulus. A run
    /// never takes this path.
    fn update(&self, stress: &Stress, eps_pd: f64, deps: &Stress) -> StressUpdate {
        self.elastic.update(stress, eps_pd, deps)
    }

    /// A fluid remembers only its volume: its stress is a function of J and the rate alone, and
    /// the shear a flow piles into F would only make det F lose digits (Taichi's MPM fluids,
    /// [002]'s platform, keep √J 1 likewise). Its point keeps F = √J 1 and V = J V⁰ with J the
    /// volume ratio its pressure follows: det F_{n+1} (`f`), or with F̄ the projected J̄_{n+1}
    /// (`jbar`). So with F̄ a fluid point carries J̄ and the next step projects J̄_n ΔJ, [002]
    /// Algorithm 1 exactly: the points' own volume ratios, which nothing in a fluid holds in
    /// place, cannot drift apart beneath the projection.
    fn fluid_volume_ratio(&self, f: M3, jbar: Option<f64>) -> Option<f64> {
        Some(jbar.unwrap_or_else(|| det(f)))
    }

    fn elastic(&self) -> &LinearElastic {
        &self.elastic
    }
}
