//! Hencky elasticity with J2 (von Mises) plasticity and exponential softening,
//! `type = "hencky_j2"` (the strip footing and the landslide of [002] §4.2 and §4.4): its
//! parameters ([`HenckyJ2`]) and its multiplicative return in principal logarithmic strains
//! ([`HenckyJ2Law`]).

use super::elasticity::check_elastic;
use super::finite_strain::{det, finite_update, left_tangent, push, FiniteTangent, M3, UNIT};
use super::principal::Principal;
use super::{reduced_strength, LinearElastic, Region, SoilLaw, SoilParameters, Stress, StressUpdate, VonMisesLaw, NS};
use crate::check::{at, non_negative, strength, Checked};
use serde::{Deserialize, Serialize};

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

impl HenckyJ2 {
    /// The residual strength c_r [Pa] (c_p without softening).
    pub fn residual(&self) -> f64 {
        self.residual_cohesion.unwrap_or(self.cohesion)
    }
}

impl SoilParameters for HenckyJ2 {
    const FINITE_STRAIN: bool = true;

    type Law = HenckyJ2Law;

    fn law(&self) -> HenckyJ2Law {
        HenckyJ2Law::new(self.young_modulus, self.poisson_ratio, self.cohesion, self.residual(), self.softening_rate)
    }

    fn with_strength_reduced(&self, f: f64) -> HenckyJ2 {
        let (cohesion, residual_cohesion) = reduced_strength(self.cohesion, self.residual_cohesion, f);
        HenckyJ2 { cohesion, residual_cohesion, ..self.clone() }
    }

    /// Checks the parameters' ranges, and whether the softening keeps the return unique, which
    /// the law says; `key` is the model's table.
    fn check(&self, key: &str) -> Checked {
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
        non_negative(&k("softening_rate"), self.softening_rate)?;
        let law = self.law();
        if !law.well_posed() {
            return Err(format!(
                "key `{}`: the softening outpaces the elastic unloading (3μ ≤ √3 η (c_p − c_r)), so the return is \
                 not unique; it must be below {:.4e}",
                k("softening_rate"),
                3.0 * law.shear / (3f64.sqrt() * (self.cohesion - residual))
            ));
        }
        Ok(())
    }

    fn cohesion(&self) -> Option<f64> {
        Some(self.cohesion)
    }

    fn describe(&self) -> String {
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

/// The state of a Hencky–J2 point: the elastic left Cauchy–Green tensor b^e (a stress vector;
/// 1 at rest) and the accumulated equivalent plastic strain ε̄ = Σ √(2/3) |Δε^p|.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlasticState {
    /// b^e as [xx, yy, xy, zz, yz, zx].
    pub be: Stress,
    /// ε̄ [-].
    pub eps: f64,
}

impl Default for PlasticState {
    fn default() -> Self {
        PlasticState { be: UNIT, eps: 0.0 }
    }
}

/// Hencky elasticity with J2 (von Mises) plasticity and exponential softening (the footing and
/// the landslide of [002] §4.2, §4.4): multiplicative plasticity in principal logarithmic strains
/// (Simo 1992; de Souza Neto, Perić & Owen 2008, §14.5). Per step: b^e_trial = ΔF b^e_n ΔFᵀ,
/// ε^e = ½ ln b^e (principal), τ = K tr ε^e 1 + 2μ dev ε^e, radial return of dev τ onto
/// q = √3 c(ε̄) with c(ε̄) = c_r + (c_p − c_r) exp(−η ε̄) ([002] L357, κ read as the strength), then
/// b^e = exp(2ε^e) and σ = τ/J. c is the plane-strain shear strength (s_u: under plane strain and
/// incompressible flow q = √3 τ_max).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HenckyJ2Law {
    /// The elasticity of the same moduli, which serves the estimates.
    pub elastic: LinearElastic,
    /// Shear modulus μ [Pa].
    pub shear: f64,
    /// Bulk modulus K [Pa].
    pub bulk: f64,
    /// Peak shear strength c_p [Pa].
    pub cohesion: f64,
    /// Residual shear strength c_r [Pa] (c_p for no softening).
    pub residual_cohesion: f64,
    /// Softening rate η [-].
    pub softening_rate: f64,
}

/// The result of a Hencky–J2 update.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HenckyUpdate {
    /// Cauchy stress [Pa].
    pub stress: Stress,
    /// The state after the step.
    pub state: PlasticState,
    /// Whether the step flowed plastically.
    pub plastic: bool,
}

impl HenckyJ2Law {
    /// From Young's modulus, Poisson's ratio and the strengths.
    pub fn new(e: f64, nu: f64, cohesion: f64, residual_cohesion: f64, softening_rate: f64) -> HenckyJ2Law {
        let shear = e / (2.0 * (1.0 + nu));
        HenckyJ2Law {
            elastic: LinearElastic::new(e, nu),
            shear,
            bulk: e / (3.0 * (1.0 - 2.0 * nu)),
            cohesion,
            residual_cohesion,
            softening_rate,
        }
    }

    /// The shear strength at ε̄ and its slope dc/dε̄.
    pub fn cohesion_at(&self, eps: f64) -> (f64, f64) {
        let e = (-self.softening_rate * eps).exp();
        let drop = self.cohesion - self.residual_cohesion;
        (self.residual_cohesion + drop * e, -self.softening_rate * drop * e)
    }

    /// Whether the return is unique: the softening never outpaces the elastic unloading,
    /// 3μ > √3 η (c_p − c_r) (otherwise the return equation has several roots).
    pub fn well_posed(&self) -> bool {
        3.0 * self.shear > 3f64.sqrt() * self.softening_rate * (self.cohesion - self.residual_cohesion)
    }

    /// The elastic left Cauchy–Green tensor b^e of a point with Cauchy stress
    /// `stress` at volume ratio `j` (with F̄, J̄): τ = J σ determines the elastic logarithmic strain,
    /// ε^e = dev τ/(2μ) + tr τ/(9K) 1 (the inverse of Hencky's law, in τ's principal frame, which is
    /// b^e's), and b^e = exp(2ε^e). The inverse of [`HenckyJ2Law::step`]'s stress to round-off, so
    /// that a point's stress and J are its whole elastic state.
    pub fn elastic_left_cauchy_green(&self, stress: &Stress, j: f64) -> Stress {
        let frame = Principal::of(stress);
        let tau = frame.values.map(|v| v * j);
        let mean = (tau[0] + tau[1] + tau[2]) / 3.0;
        let (mu2, k3) = (2.0 * self.shear, 3.0 * self.bulk);
        frame.compose(&tau.map(|t| (2.0 * ((t - mean) / mu2 + mean / k3)).exp()))
    }

    /// One step: the increment `df` of the deformation gradient from `state`, with `j` the volume
    /// ratio det F of the point after the step (with F̄, J̄) by which the Kirchhoff stress is
    /// divided. `None` when b^e or J is not positive definite.
    pub fn step(&self, df: M3, state: &PlasticState, j: f64) -> Option<HenckyUpdate> {
        let r = self.returned(df, state, j)?;
        let e = r.dev.map(|d| r.factor * d + r.tr / 3.0);
        let be = r.frame.compose(&std::array::from_fn(|k| (2.0 * e[k]).exp()));
        let state = PlasticState { be, eps: state.eps + r.flow };
        Some(HenckyUpdate { stress: r.frame.compose(&r.tau.map(|t| t / j)), state, plastic: r.flow > 0.0 })
    }

    /// The return of one step ([`HenckyJ2Law::step`]): b^e_trial = ΔF b^e_n ΔFᵀ, its principal
    /// logarithmic strains, the radial return of the trial deviator and the principal Kirchhoff
    /// stresses. `None` when b^e or J is not positive definite.
    fn returned(&self, df: M3, state: &PlasticState, j: f64) -> Option<Return> {
        if j <= 0.0 {
            return None;
        }
        let trial = push(df, &state.be);
        // b^e's principal values and frame.
        let frame = Principal::of(&trial);
        let lam = frame.values;
        if lam.iter().any(|&l| l <= 0.0) {
            return None;
        }
        // Principal logarithmic elastic strains.
        let eps = [0.5 * lam[0].ln(), 0.5 * lam[1].ln(), 0.5 * lam[2].ln()];
        let tr = eps[0] + eps[1] + eps[2];
        let dev = [eps[0] - tr / 3.0, eps[1] - tr / 3.0, eps[2] - tr / 3.0];
        let mu2 = 2.0 * self.shear;
        let s_trial = [mu2 * dev[0], mu2 * dev[1], mu2 * dev[2]];
        let q_trial = (1.5 * (s_trial[0].powi(2) + s_trial[1].powi(2) + s_trial[2].powi(2))).sqrt();
        let r3 = 3f64.sqrt();
        let (c_n, _) = self.cohesion_at(state.eps);
        let (mut flow, mut factor) = (0.0, 1.0);
        if q_trial - r3 * c_n > 1e-12 * (q_trial + c_n) {
            // g(Δ) = q_trial − 3μΔ − √3 c(ε̄_n + Δ) = 0 on [0, q_trial/3μ], where g(0) > 0 and the
            // upper end gives −√3 c < 0: Newton kept inside the bracket, bisection otherwise.
            let g3 = 3.0 * self.shear;
            let g = |d: f64| {
                let (c, dc) = self.cohesion_at(state.eps + d);
                (q_trial - g3 * d - r3 * c, -g3 - r3 * dc)
            };
            let (mut lo, mut hi) = (0.0, q_trial / g3);
            let mut d = (q_trial - r3 * c_n) / g3;
            for _ in 0..100 {
                let (r, dr) = g(d);
                if r > 0.0 {
                    lo = d;
                } else {
                    hi = d;
                }
                if r.abs() <= 1e-14 * q_trial || hi - lo <= 1e-16 * q_trial / g3 {
                    break;
                }
                let next = d - r / dr;
                d = if dr < 0.0 && next > lo && next < hi { next } else { 0.5 * (lo + hi) };
            }
            factor = 1.0 - g3 * d / q_trial;
            flow = d;
        }
        // The returned deviator is the trial one scaled (radial return); the volume is elastic.
        let tau = std::array::from_fn(|k| self.bulk * tr + factor * s_trial[k]);
        Some(Return { trial, frame, tr, dev, s_trial, q_trial, factor, flow, eps_n: state.eps, tau })
    }

    /// ∂τ_i/∂λ_j of a return: the principal Kirchhoff stresses' derivatives with respect to the
    /// principal values λ_j of b^e_trial (ε_j = ½ ln λ_j). τ_i = K tr ε + f s_i with the trial
    /// deviator s_i = 2μ dev ε_i and the radial factor f = 1 − 3μΔ/q (1 when elastic), whose
    /// derivative follows from the return equation q − 3μΔ − √3 c(ε̄_n + Δ) = 0:
    /// dΔ/dq = 1/(3μ + √3 c'), ∂f/∂q = −3μ (q dΔ/dq − Δ)/q², ∂q/∂ε_k = 3μ s_k/q.
    fn principal_tangent(&self, r: &Return) -> [[f64; 3]; 3] {
        let mu2 = 2.0 * self.shear;
        let df_de: [f64; 3] = if r.flow > 0.0 {
            let g3 = 3.0 * self.shear;
            let (_, dc) = self.cohesion_at(r.eps_n + r.flow);
            let dd_dq = 1.0 / (g3 + 3f64.sqrt() * dc);
            let df_dq = -g3 * (r.q_trial * dd_dq - r.flow) / (r.q_trial * r.q_trial);
            r.s_trial.map(|s| df_dq * g3 * s / r.q_trial)
        } else {
            [0.0; 3]
        };
        let lam = r.frame.values;
        std::array::from_fn(|i| {
            std::array::from_fn(|k| {
                let dev = if i == k { 2.0 / 3.0 } else { -1.0 / 3.0 };
                (self.bulk + r.factor * mu2 * dev + r.s_trial[i] * df_de[k]) / (2.0 * lam[k])
            })
        })
    }
}

/// A Hencky–J2 step's return ([`HenckyJ2Law::returned`]).
struct Return {
    /// b^e_trial = ΔF b^e_n ΔFᵀ.
    trial: Stress,
    /// The principal frame and values of b^e_trial.
    frame: Principal,
    /// tr ε^e (elastic, so the trial's).
    tr: f64,
    /// The trial's principal deviatoric logarithmic strains.
    dev: [f64; 3],
    /// The trial's principal deviatoric Kirchhoff stresses 2μ dev ε.
    s_trial: [f64; 3],
    /// The trial's q.
    q_trial: f64,
    /// The radial return's factor of the deviator (1 when elastic).
    factor: f64,
    /// The step's plastic strain Δ (0 when elastic).
    flow: f64,
    /// ε̄ at the step's start.
    eps_n: f64,
    /// The principal Kirchhoff stresses after the return.
    tau: [f64; 3],
}

impl SoilLaw for HenckyJ2Law {
    /// Hencky–J2 needs b^e_n, which is not stored but recovered: the Kirchhoff stress
    /// τ_n = J_n σ_n, J_n = det f / det ΔF, determines the elastic logarithmic strain
    /// (ε^e = dev τ/2μ + tr τ/(9K) 1, in τ's principal frame), and b^e_n = exp(2ε^e). The stress
    /// is NaN when det F ≤ 0 or b^e is not positive (an inadmissible step).
    fn finite(&self, df: &M3, f: &M3, stress: &Stress, eps_pd: f64, _dt: f64) -> Option<StressUpdate> {
        let (j_new, dj) = (det(*f), det(*df));
        let state = PlasticState { be: self.elastic_left_cauchy_green(stress, j_new / dj), eps: eps_pd };
        Some(match self.step(*df, &state, j_new) {
            Some(u) => finite_update(
                &self.elastic,
                Some(u.stress),
                u.state.eps,
                if u.plastic { Region::Plane } else { Region::Elastic },
            ),
            None => finite_update(&self.elastic, None, eps_pd, Region::Elastic),
        })
    }

    /// ∂σ/∂ΔF at fixed b^e_n (recovered from σ_n as [`SoilLaw::finite`] does) and J_n: δτ is the
    /// isotropic map's derivative ([`Principal::derivative`] with [`HenckyJ2Law::principal_tangent`])
    /// in the direction δb^e_trial ([`left_tangent`]). `None` for an inadmissible step.
    fn finite_tangent(&self, df: &M3, f: &M3, stress: &Stress, eps_pd: f64, _dt: f64) -> Option<FiniteTangent> {
        let (j_new, dj) = (det(*f), det(*df));
        let state = PlasticState { be: self.elastic_left_cauchy_green(stress, j_new / dj), eps: eps_pd };
        let r = self.returned(*df, &state, j_new)?;
        let dtau_db = r.frame.derivative(&r.tau, &self.principal_tangent(&r));
        let sigma = r.frame.compose(&r.tau.map(|t| t / j_new));
        let dtau =
            |db: &Stress, _: f64| -> Stress { std::array::from_fn(|i| (0..NS).map(|c| dtau_db[i][c] * db[c]).sum()) };
        Some(left_tangent(df, &r.trial, &sigma, j_new, dtau))
    }

    /// Hencky–J2's small-strain limit, von Mises of the same strength with the exponential
    /// softening linearised at ε̄ = 0 (H = −η (c_p − c_r), floored at c_r). A run never takes this
    /// path: [`SoilLaw::finite`] answers for Hencky–J2 in every kernel.
    fn update(&self, stress: &Stress, eps_pd: f64, deps: &Stress) -> StressUpdate {
        let vm = VonMisesLaw {
            elastic: self.elastic,
            cohesion: self.cohesion,
            residual_cohesion: self.residual_cohesion,
            softening_modulus: -self.softening_rate * (self.cohesion - self.residual_cohesion),
        };
        vm.update(stress, eps_pd, deps)
    }

    fn elastic(&self) -> &LinearElastic {
        &self.elastic
    }
}
