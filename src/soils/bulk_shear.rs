//! Isotropic linear elasticity given by its bulk and shear moduli, `type = "elastic_bulk_shear"`:
//! the law of `linear_elastic` ([`LinearElastic`]) with λ = K − 2G/3 and μ = G, for the moduli a
//! laboratory's isotropic compression and shear tests (or a survey's wave speeds) give directly.
//! Any K > 0 and G > 0 make an admissible material: ν = (3K − 2G)/(2(3K + G)) lies in (−1, 0.5).

use super::{LinearElastic, SoilParameters};
use crate::check::{at, modulus, Checked};
use serde::{Deserialize, Serialize};

/// The parameters of `type = "elastic_bulk_shear"`.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BulkShear {
    /// Bulk modulus K [Pa], in (0, 1e13].
    pub bulk_modulus: f64,
    /// Shear modulus G [Pa], in (0, 1e13].
    pub shear_modulus: f64,
}

impl SoilParameters for BulkShear {
    type Law = LinearElastic;

    fn law(&self) -> LinearElastic {
        LinearElastic::from_bulk_shear(self.bulk_modulus, self.shear_modulus)
    }

    fn check(&self, key: &str) -> Checked {
        modulus(&at(key, "bulk_modulus"), self.bulk_modulus)?;
        modulus(&at(key, "shear_modulus"), self.shear_modulus)
    }

    fn describe(&self) -> String {
        let law = self.law();
        format!(
            "linear elastic, K = {:.4e} Pa, G = {:.4e} Pa (E = {:.4e} Pa, ν = {:.4})",
            self.bulk_modulus, self.shear_modulus, law.young, law.poisson
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::soils::{SoilModel, Stress};

    #[test]
    fn bulk_and_shear_moduli_give_the_elasticity_of_their_young_modulus_and_poisson_ratio() {
        // E = 9KG/(3K + G), ν = (3K − 2G)/(2(3K + G)).
        let (k, g) = (5.0e7, 1.2e7);
        let (e, nu) = (9.0 * k * g / (3.0 * k + g), (3.0 * k - 2.0 * g) / (2.0 * (3.0 * k + g)));
        let from_kg = BulkShear { bulk_modulus: k, shear_modulus: g }.law();
        let from_e_nu = LinearElastic::new(e, nu);
        for (a, b) in from_kg.d.iter().flatten().zip(from_e_nu.d.iter().flatten()) {
            assert!((a - b).abs() <= 1e-8 * k, "{a} against {b}");
        }
        assert!((from_kg.bulk_modulus() - k).abs() <= 1e-8 * k && (from_kg.shear_modulus() - g).abs() <= 1e-8 * g);
        // A volumetric strain ε_v gives the mean stress K ε_v.
        let deps: Stress = [1e-3, 1e-3, 0.0, 1e-3, 0.0, 0.0];
        let s = SoilModel::ElasticBulkShear(BulkShear { bulk_modulus: k, shear_modulus: g })
            .law()
            .update(&[0.0; 6], 0.0, &deps);
        let mean = (s.stress[0] + s.stress[1] + s.stress[3]) / 3.0;
        assert!((mean - k * 3e-3).abs() <= 1e-9 * k, "mean stress {mean}");
    }

    #[test]
    fn moduli_out_of_range_are_named() {
        let bad = BulkShear { bulk_modulus: 5.0e7, shear_modulus: 0.0 };
        let err = bad.check("materials[0].model").unwrap_err();
        assert!(err.contains("materials[0].model.shear_modulus"), "{err}");
        let bad = BulkShear { bulk_modulus: -1.0, shear_modulus: 1.0e6 };
        assert!(bad.check("m").unwrap_err().contains("m.bulk_modulus"));
    }
}
