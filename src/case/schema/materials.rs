//! `[[materials]]`: the phases of the mixture and the constitutive model of the skeleton, whose
//! parameters, each model's in its own table with the checks of their ranges, are
//! [`crate::soils`]'.

use crate::check::{at, magnitude, Checked, MAX_DENSITY};
use serde::{Deserialize, Serialize};

pub use crate::soils::SoilModel;

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

serde_defaults! { default_rho_w: f64 = 1000.0 }

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
