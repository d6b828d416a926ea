//! Isotropic linear elasticity, `type = "linear_elastic"`: σ_{n+1} = σ_n + D^e Δε, with D^e its
//! tangent ([`LinearElastic`], which the other models' estimates use as well).

use super::{Elasticity, LinearElastic, Region, SoilLaw, SoilParameters, Stress, StressUpdate, IDENTITY6};
use crate::check::Checked;
use serde::{Deserialize, Serialize};

// The parameters of `type = "linear_elastic"`: E and ν, the table of [`Elasticity`]. It has no doc
// comment on purpose: with one, schemars would describe the newtype by a reference to
// `Elasticity`'s schema, and the case reference would lose the table's keys.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(transparent)]
pub struct LinearElasticParameters(pub Elasticity);

impl SoilParameters for LinearElasticParameters {
    type Law = LinearElastic;

    fn law(&self) -> LinearElastic {
        self.0.law()
    }

    fn check(&self, key: &str) -> Checked {
        self.0.check(key)
    }

    fn describe(&self) -> String {
        format!("linear elastic, {}", self.0.describe())
    }
}

impl SoilLaw for LinearElastic {
    const ELASTIC: bool = true;

    #[inline]
    fn update(&self, stress: &Stress, eps_pd: f64, deps: &Stress) -> StressUpdate {
        StressUpdate {
            stress: self.trial(stress, deps),
            tangent: self.d,
            trial_tangent: IDENTITY6,
            eps_pd,
            region: Region::Elastic,
        }
    }

    fn elastic(&self) -> &LinearElastic {
        self
    }
}
