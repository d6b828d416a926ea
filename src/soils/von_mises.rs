//! Von Mises with linear softening of the cohesion ([001] §3.2 after Wang et al.),
//! `type = "von_mises"`: its parameters ([`VonMises`]) and its law ([`VonMisesLaw`]), the radial
//! return in principal stresses and its consistent tangent.
//!
//! f = q − √3 c(ε̄) with q = sqrt(3/2 s:s) and c the shear strength (the plane-strain pure-shear
//! strength, as Tresca's c), c(ε̄) = max(c_p + H_s ε̄, c_r) with the softening modulus H_s ≤ 0. The
//! flow is associated, so Δε̄ = Δγ and the return is radial (de Souza Neto, Perić & Owen 2008, Box
//! 7.3): q = q_trial − 3GΔγ with Δγ = (q_trial − √3 c(ε̄_n))/(3G + √3 H) on the softening branch.

use super::elasticity::check_elastic;
use super::{
    isotropic_return, reduced_strength, LinearElastic, PrincipalReturn, Region, ReturnResult, SoilLaw, SoilParameters,
    Stress, StressUpdate,
};
use crate::check::{at, strength, Checked};
use serde::{Deserialize, Serialize};

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

impl SoilParameters for VonMises {
    type Law = VonMisesLaw;

    fn law(&self) -> VonMisesLaw {
        VonMisesLaw {
            elastic: LinearElastic::new(self.young_modulus, self.poisson_ratio),
            cohesion: self.cohesion,
            residual_cohesion: self.residual_cohesion.unwrap_or(self.cohesion),
            softening_modulus: self.softening_modulus,
        }
    }

    fn check(&self, key: &str) -> Checked {
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

    fn describe(&self) -> String {
        format!(
            "von Mises, E = {:.4e} Pa, ν = {}, c = {:.4e} Pa → c_r = {:.4e} Pa, H_s = {:.4e} Pa",
            self.young_modulus,
            self.poisson_ratio,
            self.cohesion,
            self.residual_cohesion.unwrap_or(self.cohesion),
            self.softening_modulus
        )
    }

    fn cohesion(&self) -> Option<f64> {
        Some(self.cohesion)
    }

    fn with_strength_reduced(&self, f: f64) -> VonMises {
        let (cohesion, residual_cohesion) = reduced_strength(self.cohesion, self.residual_cohesion, f);
        VonMises { cohesion, residual_cohesion, ..self.clone() }
    }
}

/// Von Mises as the solver runs it (Pa).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VonMisesLaw {
    /// The elasticity, D^e.
    pub elastic: LinearElastic,
    /// Peak shear strength c_p.
    pub cohesion: f64,
    /// Residual shear strength c_r.
    pub residual_cohesion: f64,
    /// Softening modulus H_s = dc/dε̄ (≤ 0).
    pub softening_modulus: f64,
}

impl VonMisesLaw {
    /// Shear strength at ε̄ and its slope.
    pub fn cohesion_at(&self, eps: f64) -> (f64, f64) {
        let c = self.cohesion + self.softening_modulus * eps;
        if c > self.residual_cohesion {
            (c, self.softening_modulus)
        } else {
            (self.residual_cohesion, 0.0)
        }
    }

    /// Returns the principal trial stresses `trial` (any order) from the state ε̄ = `eps`.
    pub fn return_principal(&self, trial: &[f64; 3], eps: f64) -> ReturnResult {
        let p = (trial[0] + trial[1] + trial[2]) / 3.0;
        let s = [trial[0] - p, trial[1] - p, trial[2] - p];
        let q = (1.5 * (s[0] * s[0] + s[1] * s[1] + s[2] * s[2])).sqrt();
        let (c_n, _) = self.cohesion_at(eps);
        let r3 = 3f64.sqrt();
        if q - r3 * c_n <= 1e-12 * (q + c_n) {
            return ReturnResult::elastic(*trial, eps);
        }
        let g3 = 3.0 * self.elastic.shear_modulus();
        // On the softening branch while ε̄ stays below the kink where c reaches c_r; beyond it,
        // perfectly plastic at c_r.
        let (mut h, mut dg) = (0.0, (q - r3 * c_n) / g3);
        if self.softening_modulus < 0.0 {
            let kink = (self.residual_cohesion - self.cohesion) / self.softening_modulus;
            if eps < kink {
                h = self.softening_modulus;
                dg = (q - r3 * c_n) / (g3 + r3 * h);
                if eps + dg > kink {
                    h = 0.0;
                    dg = (q - r3 * self.residual_cohesion) / g3;
                }
            }
        }
        let beta = 1.0 - g3 * dg / q;
        let stress = [p + beta * s[0], p + beta * s[1], p + beta * s[2]];
        // dσ_a/dλ_b = 1/3 + β(δ_ab − 1/3) + s_a dβ/dλ_b, with dq/dλ = (3/2) s/q,
        // dΔγ/dλ = dq/dλ / (3G + √3 H), dβ/dλ = −3G (dΔγ/dλ q − Δγ dq/dλ)/q².
        let mut tangent = [[0.0; 3]; 3];
        for (a, row) in tangent.iter_mut().enumerate() {
            for (b, v) in row.iter_mut().enumerate() {
                let dq = 1.5 * s[b] / q;
                let ddg = dq / (g3 + r3 * h);
                let dbeta = -g3 * (ddg * q - dg * dq) / (q * q);
                let kd = if a == b { 1.0 } else { 0.0 };
                *v = 1.0 / 3.0 + beta * (kd - 1.0 / 3.0) + s[a] * dbeta;
            }
        }
        ReturnResult { stress, tangent, eps: eps + dg, region: Region::Plane }
    }
}

impl SoilLaw for VonMisesLaw {
    const DISSIPATES: bool = true;

    #[inline]
    fn update(&self, stress: &Stress, eps_pd: f64, deps: &Stress) -> StressUpdate {
        isotropic_return(self, stress, eps_pd, deps)
    }

    fn elastic(&self) -> &LinearElastic {
        &self.elastic
    }
}

impl PrincipalReturn for VonMisesLaw {
    /// Whether [`Self::return_principal`] surely finds `trial` elastic: q = √(3/2) R from the
    /// trial's invariants ([`super::mean_and_deviator_norm`]) within half its tolerance of the
    /// yield surface, so that the principal values' round-off cannot tip it.
    fn surely_elastic(&self, trial: &Stress, eps: f64) -> bool {
        let q = (1.5f64).sqrt() * super::mean_and_deviator_norm(trial).1;
        let (c_n, _) = self.cohesion_at(eps);
        q - 3f64.sqrt() * c_n <= 0.5e-12 * (q + c_n)
    }

    fn map_principal(&self, values: &[f64; 3], eps: f64) -> ReturnResult {
        self.return_principal(values, eps)
    }
}
