//! `[[materials]]`: the phases of the mixture and the constitutive model of the skeleton, each
//! model's parameters in their own table with the checks of their ranges.

use crate::case::check::{
    at, in_closed_open, in_open, magnitude, modulus, non_negative, positive, strength, viscosity, Checked, MAX_DENSITY,
};
use serde::{Deserialize, Serialize};

/// A material: phase densities, porosity, the water and grain compressibility, the permeability,
/// and the constitutive model of the skeleton.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Material {
    /// The name bodies give to use it.
    pub name: String,
    /// Initial porosity n [-], in (0, 1) (in [0, 1) in a one-phase analysis, whose density is the
    /// mixture's (1 − n) ρ_s + n ρ_w).
    pub porosity: f64,
    /// Density of the solid grains ρ_s [kg/m³], in (0, 1e5].
    pub solid_density: f64,
    /// Density of the pore water ρ_w [kg/m³], in (0, 1e5].
    #[serde(default = "default_rho_w")]
    pub water_density: f64,
    /// Bulk modulus of the pore water K_w [Pa], in (0, 1e13]; required in a two-phase analysis.
    pub water_bulk_modulus: Option<f64>,
    /// Bulk modulus of the solid grains K_s [Pa], in (0, 1e13], or `inf` for incompressible
    /// grains; required in a two-phase analysis.
    pub solid_bulk_modulus: Option<f64>,
    /// Hydraulic conductivity k [m/s] at the initial porosity, in (0, 1]; required in a two-phase
    /// analysis.
    pub hydraulic_conductivity: Option<f64>,
    /// How the conductivity changes with the void ratio: `constant` (the default) or `xie_leo`.
    #[serde(default)]
    pub hydraulic_conductivity_law: ConductivityLaw,
    /// The constitutive model of the solid skeleton, chosen by its `type`.
    pub model: SoilModel,
}

/// Dependence of the hydraulic conductivity on the void ratio e.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum ConductivityLaw {
    /// k = k₀.
    #[default]
    Constant,
    /// k = k₀ ((1 + e)/(1 + e₀))², the law under which the large-strain consolidation of Xie & Leo
    /// (2004) has a closed form (with 1 + e = 1/(1 − n)).
    XieLeo,
}

fn default_rho_w() -> f64 {
    1000.0
}

impl Material {
    /// Checks the densities and the model's parameters; `key` is the material's table
    /// (`materials[0]`). The porosity's range and the two-phase keys depend on the formulation:
    /// validation checks them.
    pub fn check(&self, key: &str) -> Checked {
        for (f, v) in [("solid_density", self.solid_density), ("water_density", self.water_density)] {
            magnitude(&at(key, f), v, MAX_DENSITY, "kg/m³", "denser than any material")?;
        }
        self.model.check(&at(key, "model"))
    }
}

/// Constitutive model of the skeleton (effective stress in two-phase analyses, total stress in
/// one-phase analyses), chosen by the table's `type`.
#[derive(Debug, Clone, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum SoilModel {
    /// Isotropic linear elasticity.
    LinearElastic(Elasticity),
    /// Mohr–Coulomb, non-associated, with linear cohesion softening, a dilation angle decaying with
    /// plastic strain and an optional tension cut-off ([000] §4; Tresca with `friction_angle = 0`,
    /// the cohesion being the undrained strength).
    MohrCoulomb(MohrCoulomb),
    /// Von Mises with linear softening ([001] §3.2): q ≤ √3 c(ε̄), c = max(c_p + H_s ε̄, c_r).
    VonMises(VonMises),
    /// Compressible neo-Hookean hyperelasticity ([002] §4.1, Cook's membrane): Kirchhoff stress
    /// τ = μ(b − 1) + λ ln J 1 of the point's total deformation gradient, σ = τ/J. Only in
    /// `dynamic_explicit` stages (the implicit stages need its consistent tangent, which is not
    /// built), without an initial stress.
    NeoHookean(Elasticity),
    /// Hencky elasticity with J2 (von Mises) plasticity and exponential softening ([002] §4.2 and
    /// §4.4, the strip footing and the landslide): multiplicative plasticity in principal
    /// logarithmic strains, τ = K tr ε^e 1 + 2μ dev ε^e with ε^e = ½ ln b^e, radial return of
    /// dev τ onto q = √3 c(ε̄), c(ε̄) = c_r + (c_p − c_r) exp(−η ε̄), σ = τ/J (with F̄, J̄). c is
    /// the plane-strain shear strength (the undrained strength s_u). The point's b^e is not
    /// stored: it is recovered from its stress and J, which determine it (so an initial stress is
    /// an initial elastic strain). Only in `dynamic_explicit` stages (no consistent tangent for the
    /// implicit ones), in plane strain.
    HenckyJ2(HenckyJ2),
    /// A weakly compressible Newtonian fluid ([002] §4.3, the dam break): σ = −p 1 + 2μ_v dev d
    /// with the pressure of the equation of state p = K(1 − J) (with F̄, J̄) and d the step's rate
    /// of deformation. Its density is the material's (`porosity = 0`, `solid_density` = ρ). The
    /// stress is a function of J and the rate, so the body takes no initial stress: a hydrostatic
    /// state is reached by a settling stage. Only in `dynamic_explicit` stages, in plane strain.
    NewtonianFluid(NewtonianFluid),
}

/// Isotropic elastic constants (the models `linear_elastic` and `neo_hookean`).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Elasticity {
    /// Young's modulus E [Pa], in (0, 1e13].
    pub young_modulus: f64,
    /// Poisson's ratio ν [-], in (−1, 0.5).
    pub poisson_ratio: f64,
}

/// The parameters of `type = "mohr_coulomb"`.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MohrCoulomb {
    /// Young's modulus E [Pa], in (0, 1e13].
    pub young_modulus: f64,
    /// Poisson's ratio ν [-], in (−1, 0.5).
    pub poisson_ratio: f64,
    /// Friction angle φ [degrees], in [0, 90).
    pub friction_angle: f64,
    /// Peak cohesion c_p [Pa], in [0, 1e13] (> 0 when φ = 0).
    pub cohesion: f64,
    /// Residual cohesion c_r [Pa], in [0, 1e13] (default: c_p, no softening).
    pub residual_cohesion: Option<f64>,
    /// Accumulated deviatoric plastic strain ε_p^r at which c_r is reached [-], > 0; required when
    /// c_r differs from c_p.
    pub softening_strain: Option<f64>,
    /// Initial dilation angle ψ_ini [degrees], in (−90, φ] (default 0).
    #[serde(default)]
    pub dilation_angle: f64,
    /// Critical-state dilation angle ψ_crit [degrees], in (−90, φ] (default: ψ_ini, a constant
    /// dilation angle).
    pub critical_dilation_angle: Option<f64>,
    /// Decay rate η of ψ = ψ_crit + (ψ_ini − ψ_crit) exp(−η ε̄) [-], ≥ 0 (default 0).
    #[serde(default)]
    pub dilation_decay: f64,
    /// Tensile strength t of a cut-off σ_i ≤ t [Pa], ≥ 0 (default: no cut-off).
    pub tension_cutoff: Option<f64>,
}

/// The parameters of `type = "von_mises"`.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct VonMises {
    /// Young's modulus E [Pa], in (0, 1e13].
    pub young_modulus: f64,
    /// Poisson's ratio ν [-], in (−1, 0.5).
    pub poisson_ratio: f64,
    /// Peak shear strength c_p [Pa], in (0, 1e13].
    pub cohesion: f64,
    /// Residual shear strength c_r [Pa], in [0, 1e13] (default: c_p).
    pub residual_cohesion: Option<f64>,
    /// Softening modulus H_s = dc/dε̄ [Pa], in (−√3 G, 0] with G the shear modulus (default 0).
    #[serde(default)]
    pub softening_modulus: f64,
}

/// The parameters of `type = "hencky_j2"`.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct HenckyJ2 {
    /// Young's modulus E [Pa], in (0, 1e13].
    pub young_modulus: f64,
    /// Poisson's ratio ν [-], in (−1, 0.5).
    pub poisson_ratio: f64,
    /// Peak shear strength c_p [Pa], in (0, 1e13].
    pub cohesion: f64,
    /// Residual shear strength c_r [Pa], in [0, c_p] (default: c_p, no softening).
    pub residual_cohesion: Option<f64>,
    /// Softening rate η of c(ε̄) [-], ≥ 0 and below 3μ / (√3 (c_p − c_r)), where the return stops
    /// being unique (default 0).
    #[serde(default)]
    pub softening_rate: f64,
}

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

impl SoilModel {
    /// The `type` the case file names.
    pub fn kind(&self) -> &'static str {
        match self {
            SoilModel::LinearElastic(_) => "linear_elastic",
            SoilModel::MohrCoulomb(_) => "mohr_coulomb",
            SoilModel::VonMises(_) => "von_mises",
            SoilModel::NeoHookean(_) => "neo_hookean",
            SoilModel::HenckyJ2(_) => "hencky_j2",
            SoilModel::NewtonianFluid(_) => "newtonian_fluid",
        }
    }

    /// Whether the model follows the total deformation gradient (and its rate) rather than strain
    /// increments: the neo-Hookean solid, Hencky–J2 and the Newtonian fluid.
    pub fn is_finite_strain(&self) -> bool {
        matches!(self, SoilModel::NeoHookean(_) | SoilModel::HenckyJ2(_) | SoilModel::NewtonianFluid(_))
    }

    /// The peak cohesion c_p [Pa] of a model with a strength (none for the elastic models and the
    /// fluid).
    pub fn cohesion(&self) -> Option<f64> {
        match self {
            SoilModel::MohrCoulomb(m) => Some(m.cohesion),
            SoilModel::VonMises(m) => Some(m.cohesion),
            SoilModel::HenckyJ2(m) => Some(m.cohesion),
            SoilModel::LinearElastic(_) | SoilModel::NeoHookean(_) | SoilModel::NewtonianFluid(_) => None,
        }
    }

    /// Checks the ranges of the model's parameters; `key` is its table (`materials[0].model`).
    pub fn check(&self, key: &str) -> Checked {
        match self {
            SoilModel::LinearElastic(m) | SoilModel::NeoHookean(m) => m.check(key),
            SoilModel::MohrCoulomb(m) => m.check(key),
            SoilModel::VonMises(m) => m.check(key),
            SoilModel::HenckyJ2(m) => m.check(key),
            SoilModel::NewtonianFluid(m) => m.check(key),
        }
    }

    /// The model in words and numbers, for `porompm check`.
    pub fn describe(&self) -> String {
        match self {
            SoilModel::LinearElastic(m) => format!("linear elastic, {}", m.describe()),
            SoilModel::NeoHookean(m) => format!("neo-Hookean, {}", m.describe()),
            SoilModel::MohrCoulomb(m) => m.describe(),
            SoilModel::VonMises(m) => m.describe(),
            SoilModel::HenckyJ2(m) => m.describe(),
            SoilModel::NewtonianFluid(m) => m.describe(),
        }
    }

    /// The model with its peak strength divided by the strength reduction factor `f` (a stage's
    /// `strength_reduction`): c_p/f, φ' = atan(tan φ/f) with the dilation angles at most φ', the
    /// residual strength at most the reduced peak; the stiffness unchanged. Models without a
    /// strength (elastic, neo-Hookean, fluid) are returned as they are.
    pub fn with_strength_reduced(&self, f: f64) -> SoilModel {
        match self {
            SoilModel::MohrCoulomb(m) => SoilModel::MohrCoulomb(m.with_strength_reduced(f)),
            SoilModel::VonMises(m) => SoilModel::VonMises(VonMises {
                cohesion: m.cohesion / f,
                residual_cohesion: reduced_residual(m.residual_cohesion, m.cohesion / f),
                ..m.clone()
            }),
            SoilModel::HenckyJ2(m) => SoilModel::HenckyJ2(HenckyJ2 {
                cohesion: m.cohesion / f,
                residual_cohesion: reduced_residual(m.residual_cohesion, m.cohesion / f),
                ..m.clone()
            }),
            SoilModel::LinearElastic(_) | SoilModel::NeoHookean(_) | SoilModel::NewtonianFluid(_) => self.clone(),
        }
    }
}

/// A residual strength at most the reduced peak `peak`.
fn reduced_residual(residual: Option<f64>, peak: f64) -> Option<f64> {
    residual.map(|cr| cr.min(peak))
}

/// Young's modulus and Poisson's ratio of the tables at `key`.
fn check_elastic(key: &str, young_modulus: f64, poisson_ratio: f64) -> Checked {
    modulus(&at(key, "young_modulus"), young_modulus)?;
    in_open(&at(key, "poisson_ratio"), poisson_ratio, -1.0, 0.5)
}

impl Elasticity {
    /// Checks E and ν; `key` is the model's table.
    pub fn check(&self, key: &str) -> Checked {
        check_elastic(key, self.young_modulus, self.poisson_ratio)
    }

    /// E and ν in words.
    pub fn describe(&self) -> String {
        format!("E = {:.4e} Pa, ν = {}", self.young_modulus, self.poisson_ratio)
    }
}

impl MohrCoulomb {
    /// Checks the parameters' ranges and what they require of each other; `key` is the model's
    /// table.
    pub fn check(&self, key: &str) -> Checked {
        let k = |f: &str| at(key, f);
        check_elastic(key, self.young_modulus, self.poisson_ratio)?;
        in_closed_open(&k("friction_angle"), self.friction_angle, 0.0, 90.0)?;
        strength(&k("cohesion"), self.cohesion, true)?;
        let phi = self.friction_angle;
        for (f, v) in
            [("dilation_angle", Some(self.dilation_angle)), ("critical_dilation_angle", self.critical_dilation_angle)]
        {
            if let Some(v) = v.filter(|&v| !(v > -90.0 && v <= phi)) {
                return Err(format!("key `{}`: must be in (-90, friction_angle = {phi}], got {v}", k(f)));
            }
        }
        non_negative(&k("dilation_decay"), self.dilation_decay)?;
        if let Some(r) = self.residual_cohesion {
            strength(&k("residual_cohesion"), r, true)?;
            if r != self.cohesion && self.softening_strain.is_none() {
                return Err(format!(
                    "key `{}`: required when residual_cohesion differs from cohesion",
                    k("softening_strain")
                ));
            }
        }
        if let Some(e) = self.softening_strain {
            positive(&k("softening_strain"), e)?;
        }
        if let Some(t) = self.tension_cutoff {
            non_negative(&k("tension_cutoff"), t)?;
        }
        if phi == 0.0 && self.cohesion == 0.0 {
            return Err(format!(
                "key `{}`: a Tresca material (friction_angle = 0) needs a positive cohesion",
                k("cohesion")
            ));
        }
        Ok(())
    }

    /// The model in words and numbers.
    pub fn describe(&self) -> String {
        let mut t = format!(
            "{}, E = {:.4e} Pa, ν = {}, φ = {}°, c = {:.4e} Pa, ψ = {}°",
            if self.friction_angle == 0.0 { "Tresca (Mohr–Coulomb with φ = 0)" } else { "Mohr–Coulomb" },
            self.young_modulus,
            self.poisson_ratio,
            self.friction_angle,
            self.cohesion,
            self.dilation_angle
        );
        if let (Some(r), Some(e)) = (self.residual_cohesion, self.softening_strain) {
            t += &format!(", softening to c_r = {r:.4e} Pa at ε̄ = {e}");
        }
        if let Some(pc) = self.critical_dilation_angle {
            t += &format!(", ψ → {pc}° with η = {}", self.dilation_decay);
        }
        if let Some(tc) = self.tension_cutoff {
            t += &format!(", tension cut-off {tc:.4e} Pa");
        }
        t
    }

    /// The parameters with the peak strength divided by `f` (see
    /// [`SoilModel::with_strength_reduced`]).
    pub fn with_strength_reduced(&self, f: f64) -> MohrCoulomb {
        let cohesion = self.cohesion / f;
        let friction_angle = (self.friction_angle.to_radians().tan() / f).atan().to_degrees();
        MohrCoulomb {
            cohesion,
            friction_angle,
            dilation_angle: self.dilation_angle.min(friction_angle),
            critical_dilation_angle: self.critical_dilation_angle.map(|psi| psi.min(friction_angle)),
            residual_cohesion: reduced_residual(self.residual_cohesion, cohesion),
            ..self.clone()
        }
    }
}

impl VonMises {
    /// Checks the parameters' ranges; `key` is the model's table.
    pub fn check(&self, key: &str) -> Checked {
        let k = |f: &str| at(key, f);
        check_elastic(key, self.young_modulus, self.poisson_ratio)?;
        strength(&k("cohesion"), self.cohesion, false)?;
        if let Some(r) = self.residual_cohesion {
            strength(&k("residual_cohesion"), r, true)?;
        }
        // Softening steeper than the elastic shear stiffness has no unique return.
        let g = self.young_modulus / (2.0 * (1.0 + self.poisson_ratio));
        let limit = -3f64.sqrt() * g;
        let h = self.softening_modulus;
        if !(h <= 0.0 && h > limit) {
            return Err(format!("key `{}`: must be in (-√3 G, 0] = ({limit:.4e}, 0], got {h}", k("softening_modulus")));
        }
        Ok(())
    }

    /// The model in words and numbers.
    pub fn describe(&self) -> String {
        format!(
            "von Mises, E = {:.4e} Pa, ν = {}, c = {:.4e} Pa → c_r = {:.4e} Pa, H_s = {:.4e} Pa",
            self.young_modulus,
            self.poisson_ratio,
            self.cohesion,
            self.residual_cohesion.unwrap_or(self.cohesion),
            self.softening_modulus
        )
    }
}

impl HenckyJ2 {
    /// The residual strength c_r [Pa] (c_p without softening).
    pub fn residual(&self) -> f64 {
        self.residual_cohesion.unwrap_or(self.cohesion)
    }

    /// Checks the parameters' ranges; `key` is the model's table. Whether the softening keeps the
    /// return unique is the model's to say (validation asks it).
    pub fn check(&self, key: &str) -> Checked {
        let k = |f: &str| at(key, f);
        check_elastic(key, self.young_modulus, self.poisson_ratio)?;
        strength(&k("cohesion"), self.cohesion, false)?;
        let residual = self.residual();
        if !(0.0..=self.cohesion).contains(&residual) {
            return Err(format!(
                "key `{}`: must be in [0, cohesion = {}], got {residual}",
                k("residual_cohesion"),
                self.cohesion
            ));
        }
        non_negative(&k("softening_rate"), self.softening_rate)
    }

    /// The model in words and numbers.
    pub fn describe(&self) -> String {
        format!(
            "Hencky–J2 (finite strain), E = {:.4e} Pa, ν = {}, c = {:.4e} Pa → c_r = {:.4e} Pa, η = {}",
            self.young_modulus,
            self.poisson_ratio,
            self.cohesion,
            self.residual(),
            self.softening_rate
        )
    }
}

impl NewtonianFluid {
    /// Checks the parameters' ranges; `key` is the model's table.
    pub fn check(&self, key: &str) -> Checked {
        modulus(&at(key, "bulk_modulus"), self.bulk_modulus)?;
        viscosity(&at(key, "viscosity"), self.viscosity)?;
        viscosity(&at(key, "bulk_viscosity"), self.bulk_viscosity)
    }

    /// The model in words and numbers.
    pub fn describe(&self) -> String {
        format!(
            "Newtonian fluid (finite strain), K = {:.4e} Pa, μ_v = {:.4e} Pa s, ζ = {:.4e} Pa s",
            self.bulk_modulus, self.viscosity, self.bulk_viscosity
        )
    }
}
