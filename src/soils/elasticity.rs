//! Isotropic linear elasticity: the elastic matrix D^e every model's estimates use
//! ([`LinearElastic`]), and Young's modulus and Poisson's ratio as a case file gives them
//! ([`Elasticity`], the parameters of `linear_elastic` and `neo_hookean`, and [`check_elastic`],
//! the checks of the models that give them among others).

use super::stress::{Mat6, Stress, NS, NS_PLANE};
use crate::check::{at, in_open, modulus, Checked};
use serde::{Deserialize, Serialize};

/// Isotropic linear elasticity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearElastic {
    /// Young's modulus [Pa].
    pub young: f64,
    /// Poisson's ratio [-].
    pub poisson: f64,
    /// Elastic matrix D^e.
    pub d: Mat6,
}

impl LinearElastic {
    /// Elasticity with Young's modulus `e` [Pa] and Poisson's ratio `nu`.
    pub fn new(e: f64, nu: f64) -> Self {
        let lam = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
        let mu = e / (2.0 * (1.0 + nu));
        Self::of_lame(lam, mu, e, nu)
    }

    /// Elasticity with bulk modulus `k` and shear modulus `g` [Pa], which may be zero (a fluid's
    /// pressure–volume response: E = 0, ν = 1/2, D = K m mᵀ).
    pub fn from_bulk_shear(k: f64, g: f64) -> Self {
        let (e, nu) = (9.0 * k * g / (3.0 * k + g), (3.0 * k - 2.0 * g) / (2.0 * (3.0 * k + g)));
        Self::of_lame(k - 2.0 * g / 3.0, g, e, nu)
    }

    fn of_lame(lam: f64, mu: f64, e: f64, nu: f64) -> Self {
        let a = lam + 2.0 * mu;
        let d = [
            [a, lam, 0.0, lam, 0.0, 0.0],
            [lam, a, 0.0, lam, 0.0, 0.0],
            [0.0, 0.0, mu, 0.0, 0.0, 0.0],
            [lam, lam, 0.0, a, 0.0, 0.0],
            [0.0, 0.0, 0.0, 0.0, mu, 0.0],
            [0.0, 0.0, 0.0, 0.0, 0.0, mu],
        ];
        LinearElastic { young: e, poisson: nu, d }
    }

    /// Constrained (oedometric) modulus E_c = E(1 − ν)/((1 + ν)(1 − 2ν)) [Pa].
    pub fn constrained_modulus(&self) -> f64 {
        self.d[0][0]
    }

    /// Shear modulus G [Pa].
    pub fn shear_modulus(&self) -> f64 {
        self.d[2][2]
    }

    /// Lamé's λ [Pa].
    pub fn lame(&self) -> f64 {
        self.d[0][1]
    }

    /// Drained bulk modulus of the skeleton in plane strain, K_dr = λ + μ [Pa]: the in-plane mean
    /// stress (σ_xx + σ_yy)/2 per unit of the in-plane volumetric strain ε_xx + ε_yy.
    pub fn plane_bulk_modulus(&self) -> f64 {
        self.lame() + self.shear_modulus()
    }

    /// Bulk modulus K = λ + 2G/3 [Pa]: the mean stress over the volumetric strain in three
    /// dimensions.
    pub fn bulk_modulus(&self) -> f64 {
        self.lame() + 2.0 * self.shear_modulus() / 3.0
    }

    /// σ + D Δε.
    pub fn trial(&self, stress: &Stress, deps: &Stress) -> Stress {
        let mut s = *stress;
        // D^e couples [xx, yy, xy, zz] among themselves; yz and zx each only with itself.
        for (r, sr) in s.iter_mut().enumerate().take(NS_PLANE) {
            *sr += (0..NS_PLANE).map(|c| self.d[r][c] * deps[c]).sum::<f64>();
        }
        for r in NS_PLANE..NS {
            s[r] += self.d[r][r] * deps[r];
        }
        s
    }

    /// m D^e, with D^e's structure (see [`LinearElastic::trial`]): the consistent tangent of a
    /// return whose dσ/dσ_trial is `m`.
    pub fn right_multiply(&self, m: &Mat6) -> Mat6 {
        std::array::from_fn(|r| {
            std::array::from_fn(|c| {
                if c < NS_PLANE {
                    (0..NS_PLANE).map(|k| m[r][k] * self.d[k][c]).sum()
                } else {
                    m[r][c] * self.d[c][c]
                }
            })
        })
    }
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

impl Elasticity {
    /// Checks E and ν; `key` is the model's table.
    pub fn check(&self, key: &str) -> Checked {
        check_elastic(key, self.young_modulus, self.poisson_ratio)
    }

    /// E and ν in words.
    pub fn describe(&self) -> String {
        format!("E = {:.4e} Pa, ν = {}", self.young_modulus, self.poisson_ratio)
    }

    /// The elastic matrix of E and ν.
    pub fn law(&self) -> LinearElastic {
        LinearElastic::new(self.young_modulus, self.poisson_ratio)
    }
}

/// Young's modulus and Poisson's ratio of the tables at `key`.
pub fn check_elastic(key: &str, young_modulus: f64, poisson_ratio: f64) -> Checked {
    modulus(&at(key, "young_modulus"), young_modulus)?;
    in_open(&at(key, "poisson_ratio"), poisson_ratio, -1.0, 0.5)
}
